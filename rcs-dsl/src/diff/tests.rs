//! Unit tests of the diff on in-memory plan sets; the CLI's golden tests
//! (`tests/cli_diff.rs`) cover the renderings.

use super::*;

fn checked(text: &str) -> (Ir, Vec<Diagnostic>) {
    let set = crate::PlanSet::from_texts("a", [("a.rcs", text)], None);
    let (ir, diags) = check_side(&set, &crate::Options::default());
    (ir.unwrap(), diags)
}

fn run(old: &str, new: &str) -> PlanSetDiff {
    let (oi, od) = checked(old);
    let (ni, nd) = checked(new);
    diff(
        &[Side {
            ir: &oi,
            diagnostics: &od,
        }],
        &[Side {
            ir: &ni,
            diagnostics: &nd,
        }],
    )
}

fn plan(rows: &str) -> String {
    format!(
        "buffer In {{ x: i32 }}\ncontroller A {{\n    reads i: In\n    command GO\n    plan GO {{\n{}    }}\n}}\n",
        rows.replace(" x ", " i.x ")
    )
}

const BASE: &str = "        E0: *0 when new_command -> S1\n        E1: S1 when x > 10 -> Done\n        E2: S1 when x > 5 -> S2\n        E3: S2 when x < 0 -> Done\n";

#[test]
fn whitespace_and_comments_are_no_change() {
    let new = BASE
        .replace("x > 5", "( x   >  5 )")
        .replace("-> Done\n", "-> Done // end\n");
    let d = run(&plan(BASE), &plan(&new));
    assert!(d.is_empty(), "{d:#?}");
}

#[test]
fn swapping_overlapping_rows_is_a_move_that_changes_firing() {
    let new = "        E0: *0 when new_command -> S1\n        E1: S1 when x > 5 -> S2\n        E2: S1 when x > 10 -> Done\n        E3: S2 when x < 0 -> Done\n";
    let d = run(&plan(BASE), &plan(new));
    let p = &d.systems[0].controllers[0].plans[0];
    assert_eq!(p.moves.len(), 1, "{p:#?}");
    let m = &p.moves[0];
    assert_eq!((m.now_first.as_str(), m.was.as_str()), ("E1", "E2"));
    assert_eq!((m.now_second.as_str(), m.second_was.as_str()), ("E2", "E1"));
    match &m.effect {
        Effect::ChangesFiring { state, input } => {
            assert_eq!(state, "S1");
            assert!(input.contains("i.x = "), "{input}");
        }
        e => panic!("{e:?}"),
    }
    // Matched by content: both renumbered, neither changed.
    assert!(p.rows.iter().all(|r| r.change == RowChange::Same));
    // Now E2 never fires: a finding the move introduced.
    let found = &d.systems[0].findings_introduced;
    assert_eq!(found.len(), 1, "{found:#?}");
    assert_eq!(found[0].code, "shadowed_row");
    assert_eq!(found[0].row.as_deref(), Some("E2"));
    assert!(d.systems[0].findings_removed.is_empty());
}

#[test]
fn swapping_disjoint_rows_is_no_move() {
    let base = "        E0: *0 when new_command -> S1\n        E1: S1 when x > 5 -> S2\n        E2: S1 when x < 0 -> Done\n";
    let new = "        E0: *0 when new_command -> S1\n        E1: S1 when x < 0 -> Done\n        E2: S1 when x > 5 -> S2\n";
    let d = run(&plan(base), &plan(new));
    let p = &d.systems[0].controllers[0].plans[0];
    assert!(p.moves.is_empty(), "{p:#?}");
}

#[test]
fn an_inserted_row_renumbers_the_rest_without_changing_them() {
    let new = BASE.replace(
        "        E1: S1 when x > 10 -> Done\n",
        "        E1: S1 when x == 3 -> S2\n        E2: S1 when x > 10 -> Done\n",
    );
    let new = new
        .replace("E2: S1 when x > 5", "E3: S1 when x > 5")
        .replace("E3: S2", "E4: S2");
    let d = run(&plan(BASE), &plan(&new));
    let p = &d.systems[0].controllers[0].plans[0];
    let kinds: Vec<(&str, &RowChange)> = p.rows.iter().map(|r| (r.label(), &r.change)).collect();
    assert_eq!(
        kinds,
        [
            ("E0", &RowChange::Same),
            ("E1", &RowChange::Added),
            ("E2", &RowChange::Same),
            ("E3", &RowChange::Same),
            ("E4", &RowChange::Same),
        ]
    );
    assert!(p.rows[2].renumbered());
    assert!(p.moves.is_empty());
}

#[test]
fn a_plan_past_the_analysis_limit_is_matched_but_gets_no_moves() {
    let n = crate::analysis::MAX_ANALYSED + 50;
    let rows = |order: &mut dyn Iterator<Item = usize>| -> String {
        let mut s = "        E0: *0 when new_command -> S1\n".to_string();
        for (pos, v) in order.enumerate() {
            s.push_str(&format!("        E{}: S1 when x == {v} -> S1\n", pos + 1));
        }
        s
    };
    let old = rows(&mut (0..n));
    let new = rows(&mut (0..n).rev());
    let d = run(&plan(&old), &plan(&new));
    let p = &d.systems[0].controllers[0].plans[0];
    assert!(p.moves.is_empty());
    assert_eq!(p.rows.len(), n + 1);
    assert!(p.rows.iter().all(|r| r.change == RowChange::Same));
    assert_eq!(p.rows.iter().filter(|r| r.renumbered()).count(), n - n % 2);
}

/// A change to a `rows` block is one block entry naming every plan it
/// lands in, and no plan reports it on its own.
#[test]
fn a_changed_block_is_reported_once_with_the_plans_it_affects() {
    let set = |cond: &str| {
        format!(
            "buffer In {{ x: i32 }}\ncontroller A {{\n    reads i: In\n    command GO\n    command JOG\n    rows guard {{\n        * when {cond} -> Error\n    }}\n    plan GO {{\n        E0: *0 when new_command -> S1\n        use guard\n        E2: S1 when i.x > 1 -> Done\n    }}\n    plan JOG {{\n        E0: *0 when new_command -> S1\n        E1: S1 when i.x > 2 -> Done\n        use guard\n    }}\n}}\n"
        )
    };
    let d = run(&set("i.x < 0"), &set("i.x < -5"));
    let c = &d.systems[0].controllers[0];
    assert_eq!(c.blocks.len(), 1, "{c:#?}");
    assert_eq!(c.blocks[0].name, "guard");
    assert_eq!(c.blocks[0].plans, ["GO E1", "JOG E2"]);
    assert_eq!(c.blocks[0].rows.len(), 1);
    assert!(
        c.plans.iter().all(|p| !p.changed_outside_blocks()),
        "{c:#?}"
    );
    // A change outside the block is still the plan's own.
    let d = run(
        &set("i.x < 0"),
        &set("i.x < 0").replace("i.x > 2", "i.x > 3"),
    );
    let c = &d.systems[0].controllers[0];
    assert!(c.blocks.is_empty(), "{c:#?}");
    assert_eq!(c.plans.len(), 1);
    assert!(c.plans[0].changed_outside_blocks());
}
