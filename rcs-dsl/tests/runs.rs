//! Runs as the lints to come will build them, replayed on the interpreter:
//! an oscillation (`livelock`), a command sent every cycle
//! (`command_every_cycle`) and a hang under one command value
//! (`incomplete_state`), plus what a run refuses to claim.

use rcs_dsl::analysis::run::{json_of, replay, scenario_text, Expect, Firing, Run, RunStep};
use rcs_dsl::analysis::terms::Leaf;
use rcs_dsl::analysis::PlanAnalysis;
use rcs_dsl::ir::{CtrlId, Ir, StateId, Type};
use rcs_runtime::driver::Value;
use serde_json::json;
use std::collections::BTreeMap;

fn lower(text: &str) -> Ir {
    let set = rcs_dsl::PlanSet::from_texts("p", [("p.rcs", text)], None);
    rcs_dsl::lower_unchecked(&set).unwrap_or_else(|| panic!("does not lower:\n{text}"))
}

fn firing(row: &str, state: &str) -> Firing {
    Firing {
        row: row.into(),
        state: state.into(),
    }
}

const SWING: &str = "buffer In { go: bool }
controller A {
    command GO
    reads i: In
    plan GO {
        E0: *0 when new_command -> S1
        E1: S1 when i.go -> S2
        E2: S2 when i.go -> S1
        E3: S1 when state_cycles > 10 -> Done
        E4: S2 when state_cycles > 10 -> Done
    }
}
";

/// A run of `A.GO`: `entry` fires into S1 on the command's cycle, then
/// `steps`.
fn go_then(entry: &str, steps: Vec<RunStep>) -> Run {
    let first = RunStep {
        cycles: 1,
        expect: Expect::Fires {
            row: entry.into(),
            state: "S1".into(),
        },
        ..RunStep::default()
    };
    Run {
        controller: "A".into(),
        command: "GO".into(),
        params: BTreeMap::new(),
        steps: std::iter::once(first).chain(steps).collect(),
    }
}

fn swing(rows: Vec<Firing>) -> Run {
    go_then(
        "E0",
        vec![RunStep {
            reads: BTreeMap::from([("i".to_string(), json!({ "go": true }))]),
            cycles: 6,
            expect: Expect::Repeats { rows },
            ..RunStep::default()
        }],
    )
}

#[test]
fn an_oscillation_replays_cycle_by_cycle() {
    let ir = lower(SWING);
    let run = swing(vec![firing("E1", "S2"), firing("E2", "S1")]);
    replay(&ir, CtrlId(0), &run).unwrap();
    // The other order is not what happens, and the replay says where.
    let wrong = swing(vec![firing("E2", "S1"), firing("E1", "S2")]);
    let e = replay(&ir, CtrlId(0), &wrong).unwrap_err();
    assert!(e.contains("E2"), "{e}");
    // The scenario ends on the last row of the sequence.
    let text = scenario_text(&run, "swing", "an oscillation").unwrap();
    assert!(text.starts_with("# an oscillation\n"), "{text}");
    assert!(text.contains("fired: E2"), "{text}");
    assert!(text.contains("state: S1"), "{text}");
}

#[test]
fn a_command_every_cycle_replays() {
    let ir = lower(
        "controller A {
    subordinates B
    command GO
    plan GO {
        *0 when new_command -> S1 { B <- RUN }
        E1: S1 when B.executing -> same { B <- RUN }
        E2: S1 when B.done -> Done
    }
}
controller B {
    command RUN
    plan RUN { *0 when new_command -> Done }
}
",
    );
    let run = go_then(
        "E0",
        vec![RunStep {
            subordinates: BTreeMap::from([("B".to_string(), "EXECUTING".to_string())]),
            cycles: 5,
            ..RunStep::default()
        }
        .fires_each_cycle("E1".into(), "S1".into())],
    );
    replay(&ir, CtrlId(0), &run).unwrap();
    let text = scenario_text(&run, "storm", "").unwrap();
    // Rows go by `E<position>`, labelled or not.
    assert!(text.contains("fired: E0") && !text.contains("*0"), "{text}");
}

#[test]
fn a_hang_under_one_command_value_is_reached_and_held() {
    let ir = lower(
        "controller A {
    command GO(n: u8)
    plan GO {
        E0: *0 when new_command -> S1
        E1: S1 when cmd.n > 3 -> Done
    }
}
",
    );
    let c = &ir.controllers[0];
    let a = PlanAnalysis::new(&ir, c, &c.plans[0]);
    let n = a
        .terms()
        .find(&Leaf::Param(rcs_dsl::ir::ParamId(0), vec![]))
        .unwrap();
    let given = [(n, Value::Int(2))];
    let paths = a.paths_given(&given);
    let s1 = StateId(1);
    assert!(a.nothing_matches_given(s1, &given));
    let idle = rcs_dsl::analysis::Witness {
        state: s1,
        inputs: Vec::new(),
        shown: Vec::new(),
    };
    let run = a.stall_run(&paths, s1, &idle, 30).expect("a hang");
    assert_eq!(run.params.get("n"), Some(&json!(2)));
    replay(&ir, CtrlId(0), &run).unwrap();
}

#[test]
fn what_a_scenario_cannot_write_is_refused() {
    let ir = lower(SWING);
    let f64_ty = Type::Float(rcs_dsl::ir::FloatTy::F64);
    assert_eq!(json_of(&ir, &f64_ty, &Value::Float(f64::NAN)), None);
    assert_eq!(json_of(&ir, &f64_ty, &Value::Float(f64::INFINITY)), None);
    assert_eq!(json_of(&ir, &f64_ty, &Value::Float(1.5)), Some(json!(1.5)));
    let u64_ty = Type::Int(rcs_dsl::ir::IntTy::U64);
    assert_eq!(
        json_of(&ir, &u64_ty, &Value::Int(u64::MAX as i128)),
        Some(json!(u64::MAX))
    );
    // A run of another controller is not replayed on this one.
    let mut run = swing(vec![firing("E1", "S2"), firing("E2", "S1")]);
    run.controller = "Z".into();
    assert!(replay(&ir, CtrlId(0), &run).is_err());
}

#[test]
fn a_path_fires_rows_that_stay_to_count_in_a_var() {
    let ir = lower(
        "controller A {
    command GO
    var count: u8 = 0
    plan GO {
        E0: *0 when new_command -> S1 { count = 0 }
        E1: S1 when count >= 3 -> S2
        E2: S1 when count < 3 -> same { count += 1 }
        E3: S2 when state_cycles > 1 -> Done
    }
}
",
    );
    let c = &ir.controllers[0];
    let a = PlanAnalysis::new(&ir, c, &c.plans[0]);
    let paths = a.paths();
    let to_s2 = paths[2].as_ref().expect("S2 is reached by counting");
    let rows: Vec<String> = to_s2
        .steps
        .iter()
        .map(|s| match &s.expect {
            Expect::Fires { row, .. } => row.clone(),
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(rows, ["E0", "E2", "E2", "E2", "E1"]);
    replay(&ir, CtrlId(0), to_s2).unwrap();
}
