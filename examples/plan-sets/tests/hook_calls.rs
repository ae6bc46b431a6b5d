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
    system.run_cycles(1); // E0: new command → S1, no hook asked
    let calls = |system: &mut System<Counting>| {
        std::mem::take(&mut system.c_mut().expect("C").hooks_mut().calls)
    };
    assert_eq!(calls(&mut system), Vec::<String>::new());
    for cycle in 1..4 {
        system.run_cycles(1);
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
