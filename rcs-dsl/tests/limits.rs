//! `too_large` through the whole front end: a plan of 65,536 rows, from
//! text, is refused with no other finding. (Statuses and states, whose
//! names the front end looks up one by one, are taken past their limits on
//! the IR by the unit tests of `checks::limits`.) The inputs are generated:
//! a golden file would be megabytes.

use rcs_dsl::{check, Options, PlanSet};

fn codes(text: &str) -> Vec<String> {
    let set = PlanSet::from_texts("limits", [("big.rcs", text)], None);
    let mut codes: Vec<String> = check(&set, &Options::default())
        .diagnostics
        .iter()
        .map(|d| d.code.name().to_string())
        .collect();
    codes.dedup();
    codes
}

/// A plan of `n` rows, all from S0 (so one state besides Done).
fn rows(n: usize) -> String {
    let mut text =
        String::from("buffer In { a: bool }\ncontroller Big {\n    reads i: In\n    command GO\n    plan GO {\n        *0 when new_command -> same\n");
    for _ in 1..n {
        text.push_str("        S0 when i.a -> Done\n");
    }
    text.push_str("    }\n}\n");
    text
}

#[test]
fn one_row_too_many_is_refused_alone() {
    assert_eq!(codes(&rows(65_536)), ["too_large"]);
}
