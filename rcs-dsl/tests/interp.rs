//! The reference interpreter on Figure 13's plan: the principal sequence,
//! the wait loops, the exception loop, the don't-care fault row and the
//! `otherwise` NOP fire exactly as the state table says.

use rcs_dsl::interp::{HookData, Hooks, Interpreter, Value};
use rcs_dsl::ir::{CommandId, HookId, Ir};
use rcs_dsl::{check, Options, PlanSet};

const FIGURE13: &str = include_str!("../../plans/figure13/figure13.rcs");

struct NoHooks;
impl Hooks for NoHooks {
    fn call(&mut self, _: &HookData, _: HookId, _: &[Value]) -> Value {
        Value::Unit
    }
}

fn ir() -> Ir {
    let set = PlanSet::from_texts("figure13", [("figure13.rcs", FIGURE13)], None);
    check(&set, &Options::default())
        .ir
        .expect("figure13 checks clean")
}

/// Run one cycle with event `e` (1..=9) raised, or none; returns the fired
/// row's name as the table prints it and the state after the cycle.
fn step(interp: &mut Interpreter, ir: &Ir, e: Option<usize>) -> (String, String, u32) {
    let events: Vec<Value> = (1..=9).map(|i| Value::Bool(Some(i) == e)).collect();
    interp.set_read(0, Value::Buffer(events));
    let rec = interp.cycle(&mut NoHooks);
    let ctrl = interp.controller();
    let plan = &ctrl.plans[0];
    let fired = rec
        .fired
        .map(|r| plan.rows[r.index()].display_name())
        .unwrap_or_else(|| "none".into());
    let _ = ir;
    (
        fired,
        plan.states[rec.state.index()].name.clone(),
        rec.status.0,
    )
}

#[test]
fn figure13_principal_sequence_and_exception_loop() {
    let ir = ir();
    let gx = ir.controller_by_name("GX").unwrap();
    let mut interp = Interpreter::new(&ir, gx);
    interp.command(CommandId(0), vec![]);
    let script: [(Option<usize>, &str, &str); 12] = [
        (None, "E0", "S1"),    // new command → S1
        (Some(2), "E2", "S1"), // wait loop
        (None, "E10", "S1"),   // nothing happens: otherwise NOP
        (Some(3), "E3", "S2"), // principal sequence
        (Some(4), "E4", "S3"), // exception
        (Some(5), "E5", "S3"), // exception wait loop
        (Some(6), "E6", "S1"), // back to S1
        (Some(3), "E3", "S2"),
        (Some(7), "E7", "S4"),
        (Some(8), "E8", "S4"),
        (Some(9), "E9", "S4"),   // Done: the state stays, the plan ends
        (Some(3), "none", "S4"), // a finished plan does nothing
    ];
    for (i, (event, row, state)) in script.iter().enumerate() {
        let (fired, now, _) = step(&mut interp, &ir, *event);
        assert_eq!(
            (fired.as_str(), now.as_str()),
            (*row, *state),
            "cycle {i} with event {event:?}"
        );
    }
    assert_eq!(interp.bookkeeping().status(), rcs_runtime::Status::DONE);
}

#[test]
fn figure13_fault_from_any_state_ends_in_error() {
    let ir = ir();
    let gx = ir.controller_by_name("GX").unwrap();
    let mut interp = Interpreter::new(&ir, gx);
    interp.command(CommandId(0), vec![]);
    step(&mut interp, &ir, None);
    step(&mut interp, &ir, Some(3));
    let (fired, _, status) = step(&mut interp, &ir, Some(1));
    assert_eq!(fired, "E1");
    assert_eq!(status, u32::from(rcs_runtime::Status::ERROR.0));
    assert_eq!(
        interp.bookkeeping().error(),
        rcs_runtime::ErrorCode::custom(0),
        "FAULT"
    );
    // A new command supersedes the finished one at once and starts in S0.
    interp.command(CommandId(0), vec![]);
    let (fired, state, status) = step(&mut interp, &ir, None);
    assert_eq!(
        (fired.as_str(), state.as_str(), status),
        ("E0", "S1", u32::from(rcs_runtime::Status::EXECUTING.0))
    );
}

const HOOK_CALLS: &str = include_str!("../../tests/data/ok/0019_hook_calls_once_per_cycle.rcs");

/// Hooks that log every call: `depth` returns 5 and `over` false.
#[derive(Default)]
struct Counting {
    calls: Vec<String>,
}

impl Hooks for Counting {
    fn call(&mut self, data: &HookData, hook: HookId, args: &[Value]) -> Value {
        let name = &data.ctrl.hooks[hook.index()].name;
        let args: Vec<String> = args
            .iter()
            .map(|a| match a {
                Value::Int(i) => i.to_string(),
                other => format!("{other:?}"),
            })
            .collect();
        self.calls.push(format!("{name}({})", args.join(", ")));
        match name.as_str() {
            "depth" => Value::Int(5),
            "over" => Value::Bool(false),
            _ => Value::Unit,
        }
    }
}

#[test]
fn a_conditions_hook_call_runs_once_per_cycle_and_a_jobs_every_time() {
    let set = PlanSet::from_texts("calls", [("calls.rcs", HOOK_CALLS)], None);
    let ir = check(&set, &Options::default()).ir.expect("checks clean");
    let c = ir.controller_by_name("C").unwrap();
    let mut interp = Interpreter::new(&ir, c);
    interp.command(CommandId(0), vec![]);
    let mut hooks = Counting::default();
    interp.cycle(&mut hooks); // E0: new command → S1, no hook asked
    assert_eq!(hooks.calls, Vec::<String>::new());
    for cycle in 1..4 {
        let rec = interp.cycle(&mut hooks);
        assert_eq!(rec.fired.map(|r| r.index()), Some(3), "cycle {cycle}");
        // E1 asks depth() (false, so over(1) is never reached); E2 asks
        // over(2) and depth() again (cached); E3 asks both (cached). The
        // jobs call depth() and log() every time they are written.
        assert_eq!(
            hooks.calls,
            ["depth()", "over(2)", "depth()", "log(5)", "depth()", "log(5)"],
            "cycle {cycle}"
        );
        hooks.calls.clear();
    }
}
