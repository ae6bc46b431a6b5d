//! The generated Rust calls a condition's hook at most once per cycle and a
//! job's hook every time it is written, as the interpreter does
//! (`rcs-dsl/tests/interp.rs` runs the same plan):
//! `tests/data/ok/0019_hook_calls_once_per_cycle.rcs`.

use rcs_plan_sets::set_0019_hook_calls_once_per_cycle::_0019_hook_calls_once_per_cycle::{
    c, Hooks, System,
};

/// Logs every call: `depth` returns 5 and `over` false.
#[derive(Debug, Default)]
struct Counting {
    calls: Vec<String>,
}

impl c::Hooks for Counting {
    fn depth(&mut self, _: &c::Data) -> i32 {
        self.calls.push("depth()".into());
        5
    }
    fn over(&mut self, _: &c::Data, n: i32) -> bool {
        self.calls.push(format!("over({n})"));
        false
    }
    fn log(&mut self, _: &c::Data, value: i32) {
        self.calls.push(format!("log({value})"));
    }
}

#[test]
fn a_conditions_hook_call_runs_once_per_cycle_and_a_jobs_every_time() {
    let mut system = System::new(Hooks {
        c: Counting::default(),
    })
    .expect("setup");
    system.operators.c.command(c::Command::Watch);
    system.run_cycles(1).expect("no hook panics"); // E0: new command → S1, no hook asked
    let calls = |system: &mut System<Counting>| {
        std::mem::take(&mut system.c_mut().expect("C").hooks_mut().calls)
    };
    assert_eq!(calls(&mut system), Vec::<String>::new());
    for cycle in 1..4 {
        system.run_cycles(1).expect("no hook panics");
        assert_eq!(system.c().expect("C").bookkeeping().fired(), Some(3));
        // E1 asks depth() (false, so over(1) is never reached); E2 asks
        // over(2) and depth() again (cached); E3 asks both (cached). The
        // jobs call depth() and log() every time they are written.
        assert_eq!(
            calls(&mut system),
            ["depth()", "over(2)", "depth()", "log(5)", "depth()", "log(5)"],
            "cycle {cycle}"
        );
    }
}

/// The scenario drivers of both backends count each hook's calls in the
/// cycle's record (which the differential test compares): a condition's
/// call once however many rows ask, a job's every time.
#[test]
fn both_backends_record_the_same_hook_call_counts() {
    use rcs_runtime::driver::{Driven, Value};
    let path = "tests/data/ok/0019_hook_calls_once_per_cycle.rcs";
    let set = rcs_plan_sets::SETS
        .iter()
        .find(|s| s.path == path)
        .expect("the set is compiled");
    let mut generated = (set.new_driver)("C").expect("C").expect("setup");
    let text = std::fs::read_to_string(format!("../../{path}")).expect("plan");
    let plans = rcs_dsl::PlanSet::from_texts("calls", [("calls.rcs", text.as_str())], None);
    let ir = rcs_dsl::check(&plans, &rcs_dsl::Options::default())
        .ir
        .expect("checks clean");
    let c = ir.controller_by_name("C").expect("C");
    let mut interp = rcs_dsl::interp::Driven::new(&ir, c);
    for d in [&mut *generated as &mut dyn Driven, &mut interp] {
        d.set_hook("depth", &Value::Int(5)).expect("depth");
        d.command("WATCH", &[]).expect("WATCH");
        assert_eq!(
            d.cycle().hook_calls,
            [0, 0, 0],
            "{}: E0 asks none",
            d.name()
        );
        for _ in 0..3 {
            // depth: once for the conditions, twice in E3's jobs; over(2)
            // once (over(1) is never reached); log twice.
            assert_eq!(d.cycle().hook_calls, [3, 1, 2], "{}", d.name());
        }
    }
}
