//! Error codes as values (LANGUAGE.md §8) on the reference interpreter,
//! through scenarios with the §8 keys: `X.error_code` against X's codes
//! (built-ins included), vars, status fields and job-list parameters of
//! type `error`, `-> Error(v)` and `report ERROR(v)`. The same plan runs on
//! generated code in tests/data/ok (golden) and the differential test.

mod scenario_run;
use rcs_dsl::ir::Ir;
use scenario_run::{failure, ir_of, passes};

const PLANS: &str = include_str!("../../tests/data/ok/0710_error_codes.rcs");

fn ir() -> Ir {
    ir_of(PLANS)
}

#[test]
fn a_subordinate_error_code_picks_the_row_and_a_held_code_ends_the_plan() {
    let ir = ir();
    passes(
        &ir,
        r#"
controller: CELL
steps:
  - command: { RUN: { x: 1.0 } }
    expect: { fired: E0, vars: { cause: AXIS_LOST } }
  - subordinates: { AXIS: { status: ERROR, error: FAULTED, last_fault: FAULTED } }
    expect: { fired: E3, state: S2, status: ERROR, error: AXIS_FAULTED, vars: { cause: AXIS_FAULTED } }
  - cycles: 3
    expect: { fired: E6, status: ERROR, error: AXIS_FAULTED }
"#,
    );
}

#[test]
fn built_in_codes_are_told_apart() {
    let ir = ir();
    for (code, row, ends) in [
        ("REFUSED", "E2", "AXIS_REFUSED"),
        ("HOOK_PANIC", "E4", "AXIS_LOST"),
        ("INDEX_RANGE", "E4", "AXIS_LOST"),
        ("TIMED_OUT", "E5", "AXIS_LOST"),
    ] {
        let answer = if code == "REFUSED" {
            "AXIS: REFUSED".to_string()
        } else {
            format!("AXIS: {{ status: ERROR, error: {code} }}")
        };
        passes(
            &ir,
            &format!(
                "controller: CELL\nsteps:\n  - command: {{ RUN: {{ x: 1.0 }} }}\n  - subordinates: {{ {answer} }}\n    expect: {{ fired: {row}, status: ERROR, error: {ends} }}\n"
            ),
        );
    }
}

#[test]
fn a_var_of_type_error_ends_the_plan_with_its_code() {
    let ir = ir();
    passes(
        &ir,
        r#"
controller: AXIS
initial:
  reads: { io: { enabled: true, position: 0.0 } }
steps:
  - command: { MOVE: { x: 5.0 } }
    expect: { fired: E0 }
  - cycles: 101
    expect: { fired: E3, status: ERROR, error: TIMED_OUT, vars: { last_fault: TIMED_OUT } }
"#,
    );
    let f = failure(
        &ir,
        "controller: AXIS\ninitial:\n  reads: { io: { enabled: true } }\nsteps:\n  - command: { MOVE: { x: 5.0 } }\n  - reads: { io: { fault: true } }\n    expect: { error: TIMED_OUT, vars: { last_fault: TIMED_OUT } }\n",
    );
    assert!(f.contains("error: expected TIMED_OUT, got FAULTED"), "{f}");
    assert!(
        f.contains("vars.last_fault: expected TIMED_OUT, got FAULTED"),
        "{f}"
    );
}
