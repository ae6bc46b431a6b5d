//! State sets and `except` (LANGUAGE.md §8) through the checks: the
//! analysis sees a set row in each of its states and an `except` row in
//! every state but those it leaves out, for shadowing, gaps
//! (`incomplete_state`), livelock and dead ends; the interpreter fires
//! them by the same rule.

use rcs_dsl::interp;
use rcs_dsl::ir::{From, StateId};
use rcs_dsl::{check, Options, PlanSet};
use rcs_runtime::driver::{Driven, Value};

/// The codes of every finding on `text`, in order, but `unused` (the
/// plans below do not all raise their error code).
fn codes(text: &str) -> Vec<String> {
    let set = PlanSet::from_texts("t", [("t.rcs", text)], None);
    check(&set, &Options::default())
        .diagnostics
        .iter()
        .map(|d| d.code.name().to_string())
        .filter(|c| c != "unused")
        .collect()
}

/// A filler whose plan has `rows` after its entry row.
fn filler(rows: &str) -> String {
    format!(
        "buffer Scale {{ litres: f64, high: bool }}
controller Filler {{
    command FILL(litres: u16)
    reads scale: Scale
    error TIMEOUT
    plan FILL {{
        E0: *0 when new_command -> S1
{rows}    }}
}}
"
    )
}

#[test]
fn a_set_row_shadows_a_later_row_only_if_it_takes_it_in_every_state() {
    // In S1 and S2 alike, E1 takes every cycle on which E3 could fire.
    let shadowed = filler(
        "        E1: S1 | S2 when scale.high -> Done
        E2: S1 when scale.litres > 1.0 -> S2
        E3: S2 when scale.high && scale.litres > 5.0 -> Error
",
    );
    assert_eq!(codes(&shadowed), ["shadowed_row"]);
    // A later set row that an earlier row of one state takes there still
    // fires in its other state.
    let not_shadowed = filler(
        "        E1: S1 when scale.high -> Done
        E2: S1 when scale.litres > 1.0 -> S2
        E3: S1 | S2 when scale.high -> Error
",
    );
    assert_eq!(codes(&not_shadowed), Vec::<String>::new());
    // Nor does a row an `except` row leaves out of a state get shadowed there.
    let except = filler(
        "        E1: *1 except S2 when scale.high -> Done
        E2: S1 when scale.litres > 1.0 -> S2
        E3: S2 when scale.high -> Error
",
    );
    assert_eq!(codes(&except), Vec::<String>::new());
}

#[test]
fn a_set_or_except_timeout_closes_a_gap_only_in_the_states_it_covers() {
    // With a fill of 0 litres nothing can fire in S1 (a gap), unless a
    // timeout covers S1.
    let gap = |timeout: &str| {
        filler(&format!(
            "        E1: S1 when cmd.litres > 0 && scale.litres >= 10.0 -> S2
        E2: S2 when scale.litres >= 20.0 -> Done
{timeout}"
        ))
    };
    for (timeout, findings) in [
        ("", vec!["incomplete_state"]),
        (
            "        E3: S1 | S2 when state_cycles > 50 -> Error(TIMEOUT)\n",
            vec![],
        ),
        (
            "        E3: *3 except S2 when state_cycles > 50 -> Error(TIMEOUT)\n",
            vec![],
        ),
        // Leaving S1 out leaves the gap open.
        (
            "        E3: *3 except S1 when state_cycles > 50 -> Error(TIMEOUT)\n",
            vec!["incomplete_state"],
        ),
    ] {
        assert_eq!(codes(&gap(timeout)), findings, "{timeout}");
    }
}

#[test]
fn a_retry_ring_defeats_a_set_timeout_on_state_cycles_but_not_on_plan_cycles() {
    let ring = |counter: &str| {
        filler(&format!(
            "        E1: S1 | S2 when {counter} > 20 -> Error(TIMEOUT)
        E2: S1 when !scale.high -> S2
        E3: S2 when !scale.high -> S1
        E4: S1 | S2 when scale.high -> Done
"
        ))
    };
    assert_eq!(codes(&ring("state_cycles")), ["livelock"]);
    assert_eq!(codes(&ring("plan_cycles")), Vec::<String>::new());
}

#[test]
fn a_state_an_except_row_leaves_out_is_a_dead_end_without_its_own_exit() {
    let plan = |exit: &str| {
        filler(&format!(
            "        E1: S1 when scale.high -> Hold
        E2: S1 when scale.litres > 9.0 -> Done
        E3: *3 except Hold when plan_cycles > 99 -> Error(TIMEOUT)
{exit}"
        ))
    };
    assert_eq!(codes(&plan("")), ["dead_end_state"]);
    assert_eq!(
        codes(&plan("        E4: Hold when !scale.high -> S1\n")),
        Vec::<String>::new()
    );
}

/// The interpreter fires a set row in each of its states and an `except`
/// row everywhere but where it leaves out.
#[test]
fn the_interpreter_fires_set_and_except_rows_by_the_states_they_cover() {
    let text = "buffer In { go: bool, stop: bool }
controller C {
    reads i: In
    command RUN
    plan RUN {
        E0: *0 when new_command -> A
        E1: A when i.go -> B
        E2: A | B when i.stop -> C
        E3: *3 except C when state_cycles > 5 -> Done
        E4: C when !i.stop -> A
    }
}
";
    let set = PlanSet::from_texts("t", [("t.rcs", text)], None);
    let ir = check(&set, &Options::default()).ir.expect("checks clean");
    let plan = &ir.controllers[0].plans[0];
    let (a, b, c) = (StateId(1), StateId(2), StateId(3));
    assert_eq!(plan.rows[2].from, From::States(vec![a, b]));
    assert_eq!(plan.rows[3].from, From::Except(Some(3), vec![c]));
    assert!(plan.rows[3].is_dont_care() && !plan.rows[3].applies_in(c));

    let mut d = interp::Driven::new(&ir, rcs_dsl::ir::CtrlId(0));
    d.command("RUN", &[]).expect("commands");
    let step = |d: &mut interp::Driven, go: bool, stop: bool| {
        d.set_read(
            "i",
            &Value::Buffer(vec![Value::Bool(go), Value::Bool(stop)]),
        )
        .expect("sets i");
        let r = d.cycle();
        (r.fired, r.state)
    };
    assert_eq!(step(&mut d, false, false), (Some(0), 1));
    // E2 from A, back with E4, then on to B and E2 from B.
    assert_eq!(step(&mut d, false, true), (Some(2), 3));
    // In C the except row E3 does not apply, however long the plan stays.
    for _ in 0..10 {
        assert_eq!(step(&mut d, false, true), (None, 3));
    }
    assert_eq!(step(&mut d, false, false), (Some(4), 1));
    assert_eq!(step(&mut d, true, false), (Some(1), 2));
    assert_eq!(step(&mut d, false, true), (Some(2), 3));
    assert_eq!(step(&mut d, false, false), (Some(4), 1));
    // In A it does: after more than five cycles there, E3 ends the plan.
    let fired: Vec<Option<u16>> = (0..6).map(|_| step(&mut d, false, false).0).collect();
    assert_eq!(fired, [None, None, None, None, None, Some(3)]);
}
