//! Refusing a command (LANGUAGE.md §8 `accept when`, docs/semantics.md
//! step 3a) on the reference interpreter, through scenarios written with
//! the §8 keys: the running plan goes on untouched (state, counters, vars,
//! `cmd.P`), the sender sees ERROR / REFUSED for exactly that serial until
//! it sends again, and nothing the running plan reports answers it. The
//! same plans run on generated code in the differential test (plans/packml,
//! plans/fieldbus_drive) and across processes in examples/submarine-split.

mod scenario_run;
use rcs_dsl::ir::Ir;
use rcs_dsl::scenario;
use rcs_dsl::source::SourceFile;
use scenario_run::{failure, ir_of, passes};

const PLANS: &str = include_str!("../../tests/data/ok/0700_accept_when.rcs");

fn ir() -> Ir {
    ir_of(PLANS)
}

#[test]
fn a_refused_command_leaves_the_running_plan_and_answers_refused() {
    let ir = ir();
    passes(
        &ir,
        r#"
controller: AXIS
initial:
  reads: { io: { position: 0.0, enabled: true } }
steps:
  - command: { MOVE: { x: 10.0 } }
    expect: { fired: E0, state: S1, status: EXECUTING, answered: 1, vars: { goal: 10.0, moving: true } }
  - command: { MOVE: { x: 900.0 } }          # beyond LIMIT: refused
    expect: { fired: none, state: S1, status: ERROR, error: REFUSED, answered: 2, vars: { goal: 10.0, moving: true } }
  - cycles: 3                                 # the refusal stays until the next command
    expect: { fired: none, state: S1, status: ERROR, error: REFUSED, answered: 2 }
  - reads: { io: { position: 10.0 } }         # the plan that goes on completes...
    expect: { fired: E1, status: ERROR, error: REFUSED, answered: 2, vars: { moving: false } }
  - command: STOP                             # ...and is not taken as the answer
    expect: { fired: E0, status: DONE, error: none, answered: 3 }
"#,
    );
}

#[test]
fn a_refusal_reads_vars_computed_by_pre_on_the_arrival_cycle() {
    let ir = ir();
    // `ready` is set by `pre` from this cycle's read: the same step that
    // disables the axis and sends MOVE is refused.
    passes(
        &ir,
        r#"
controller: AXIS
steps:
  - reads: { io: { enabled: false } }
    command: { MOVE: { x: 1.0 } }
    expect: { fired: none, status: ERROR, error: REFUSED, vars: { ready: false, goal: 0.0, moving: false } }
  - reads: { io: { enabled: true } }
    command: { MOVE: { x: 1.0 } }
    expect: { fired: E0, status: EXECUTING, vars: { ready: true, goal: 1.0, moving: true } }
  - command: HOME                            # refused while moving
    expect: { fired: none, state: S1, status: ERROR, error: REFUSED, vars: { goal: 1.0 } }
"#,
    );
}

#[test]
fn the_expectation_fails_when_the_refusal_is_not_what_the_scenario_says() {
    let ir = ir();
    let f = failure(
        &ir,
        "controller: AXIS\nsteps:\n  - command: { MOVE: { x: 900.0 } }\n    expect: { status: EXECUTING }\n",
    );
    assert!(f.contains("status: expected EXECUTING, got ERROR"), "{f}");
    let f = failure(
        &ir,
        "controller: AXIS\nsteps:\n  - command: { MOVE: { x: 900.0 } }\n    expect: { answered: 7 }\n",
    );
    assert!(f.contains("answered: expected serial 7, got 1"), "{f}");
}

#[test]
fn a_supervisor_sees_a_subordinate_refusal_as_an_error() {
    let ir = ir();
    passes(
        &ir,
        r#"
controller: CELL
steps:
  - command: { RUN: { x: 1.0 } }
    expect: { fired: E0, sent: { AXIS: { MOVE: { x: 1.0 } } } }
  - subordinates: { AXIS: REFUSED }
    expect: { fired: E2, status: ERROR, error: AXIS_SAID_NO }
"#,
    );
    passes(
        &ir,
        r#"
controller: CELL
steps:
  - command: { RUN: { x: 1.0 } }
  - subordinates: { AXIS: { status: ERROR, error: REFUSED } }
    expect: { fired: E2 }
"#,
    );
}

#[test]
fn only_a_controller_that_can_refuse_answers_refused_in_a_scenario() {
    let ir = ir();
    let s = scenario::parse(
        &ir,
        &SourceFile::new(
            "t.scenario.yaml",
            "controller: AXIS\nsteps:\n  - expect: { error: NOPE }\n",
        ),
        "t",
    );
    let e = s.err().expect("an unknown error code");
    assert!(
        e.message.contains("has no error code `NOPE`"),
        "{}",
        e.message
    );
}
