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

/// Hostile sizes go through the front end in O(n log n): a file declaring
/// 300,000 statuses, and a plan of 100,000 rows naming 100,000 states, are
/// refused as `too_large` (a name looked up linearly per declaration would
/// take hours here, which CI's time limit would show).
#[test]
fn huge_declarations_are_refused_without_quadratic_lookups() {
    let list: Vec<String> = (0..300_000).map(|i| format!("S{i}")).collect();
    let statuses = format!(
        "controller Big {{\n    command GO\n    status {}\n    plan GO {{ *0 when new_command -> Done }}\n}}\n",
        list.join(", ")
    );
    assert_eq!(codes(&statuses), ["too_large"]);
    let mut states =
        String::from("buffer In { a: bool }\ncontroller Big {\n    reads i: In\n    command GO\n    plan GO {\n        *0 when new_command -> S1\n");
    for k in 1..100_000 {
        states.push_str(&format!("        S{k} when i.a -> S{}\n", k + 1));
    }
    states.push_str("    }\n}\n");
    assert_eq!(codes(&states), ["too_large"]);
}

/// References are looked up through the index too: 60,000 statuses, each
/// reported by one job of one row, check in O(n log n) (a linear search
/// per reference would be 3.6 billion comparisons).
#[test]
fn many_references_are_looked_up_by_name() {
    let n = 60_000;
    let list: Vec<String> = (0..n).map(|i| format!("S{i}")).collect();
    let jobs: Vec<String> = (0..n).map(|i| format!("report S{i}")).collect();
    let text = format!(
        "controller Big {{\n    command GO\n    status {}\n    plan GO {{ *0 when new_command -> Done {{ {} }} }}\n}}\n",
        list.join(", "),
        jobs.join("; ")
    );
    assert!(codes(&text).is_empty(), "{:?}", codes(&text));
}

/// A plan far past the rule of ten but within the runtime's limits (30,000
/// rows and states) is checked in linear time: the analysis of conditions
/// leaves plans of more than `MAX_ANALYSED` rows or states alone (its cost
/// grows as rows² × states), and the plan graph is built from the rows'
/// state patterns. Only `rule_of_ten` speaks.
#[test]
fn a_huge_plan_is_checked_without_its_analysis() {
    let mut text = String::from(
        "buffer In { a: bool }\ncontroller Big {\n    reads i: In\n    command GO\n    plan GO {\n        *0 when new_command -> S1\n        *1 when !i.a && i.a -> Error\n",
    );
    let n = 30_000;
    for k in 1..n {
        text.push_str(&format!("        S{k} when i.a -> S{}\n", k + 1));
    }
    text.push_str(&format!("        S{n} when i.a -> Done\n    }}\n}}\n"));
    assert_eq!(codes(&text), ["rule_of_ten"]);
}
