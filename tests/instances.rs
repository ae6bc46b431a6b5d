//! Controller types expand to exactly the controllers one would write by
//! hand (LANGUAGE.md §8): a set of 100 instances of one type and the same
//! 100 axes written out check alike and draw the same graphs and tables,
//! apart from source places and the tables' instance line; the instances'
//! Rust shares one module for the type, so it is several times shorter.

#[path = "../rcs-dsl/benches/common/instance_set.rs"]
mod instance_set;

use rcs_dsl::{Options, PlanSet};

fn generated(text: &str) -> Vec<(String, String)> {
    let set = PlanSet::from_texts("axes", [("axes.rcs", text)], None);
    let checked = rcs_dsl::check(&set, &Options::default());
    assert!(
        checked.diagnostics.is_empty(),
        "{:?}",
        checked.diagnostics.first()
    );
    let ir = checked.ir.expect("checked");
    rcs_codegen::generate(&ir)
        .into_iter()
        .map(|f| (f.path, f.contents))
        .collect()
}

/// Row comments and graph tooltips give their source place
/// (`axes.rcs:12`), which differs between the two texts; tables of an
/// instance say its type.
fn without_places(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.starts_with("An instance of controller type") {
            lines.next(); // the blank line after it
            continue;
        }
        let mut rest = line;
        while let Some(i) = rest.find("axes.rcs:") {
            out.push_str(&rest[..i]);
            rest = rest[i + "axes.rcs:".len()..].trim_start_matches(|c: char| c.is_ascii_digit());
        }
        out.push_str(rest);
        out.push('\n');
    }
    out
}

#[test]
fn instances_generate_what_the_hand_copies_do() {
    let n = 100;
    let types = generated(&instance_set::instances(n));
    let copies = generated(&instance_set::copies(n));
    assert_eq!(types.len(), copies.len());
    let mut compared = 0;
    for ((tp, tt), (cp, ct)) in types.iter().zip(&copies) {
        assert_eq!(tp, cp);
        if tp.starts_with("rust/") {
            let (t, c) = (tt.lines().count(), ct.lines().count());
            assert!(
                t * 5 < c,
                "{tp}: {t} lines for the instances, {c} written out"
            );
            assert!(tt.contains("pub mod axis {"), "one module for the type");
            continue;
        }
        let (a, b) = (without_places(tt), without_places(ct));
        if a != b {
            let line = a
                .lines()
                .zip(b.lines())
                .position(|(x, y)| x != y)
                .unwrap_or(0);
            panic!(
                "{tp} differs at line {line}:\n  types:  {:?}\n  copies: {:?}",
                a.lines().nth(line),
                b.lines().nth(line)
            );
        }
        compared += 1;
    }
    // Per axis: its graphs (3 plans) and its table; plus the Rust, the
    // hierarchy graph.
    assert!(compared > 4 * n, "{compared} files");
}

/// Two checks of one text, each with its own allocations, generate the
/// same bytes (the shared modules' `Params` are numbered in the order of
/// the plans, never by where the IR sits in memory; the unit test
/// `slots_are_numbered_in_the_order_the_plans_use_them` holds the rule).
#[test]
fn shared_modules_are_deterministic() {
    let text = std::fs::read_to_string("tests/data/ok/0521_controller_types_shared.rcs")
        .expect("the ok case");
    let first = generated(&text);
    // Other allocations in between move the second IR elsewhere.
    let _ballast: Vec<Vec<u8>> = (0..64).map(|i| vec![0; 1024 * (i + 1)]).collect();
    let second = generated(&text);
    assert_eq!(first, second);
    let packml: Vec<(String, String)> = (0..2)
        .map(|_| {
            let set =
                rcs_dsl::load_folder(std::path::Path::new("plans/packml")).expect("plans/packml");
            let ir = rcs_dsl::check(&set, &Options::default()).ir.expect("clean");
            rcs_codegen::generate(&ir)
                .into_iter()
                .find(|f| f.path.starts_with("rust/"))
                .map(|f| (f.path, f.contents))
                .expect("the Rust")
        })
        .collect();
    assert_eq!(packml[0], packml[1]);
}
