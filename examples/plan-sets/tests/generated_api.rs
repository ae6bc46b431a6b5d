//! The generated `System`'s API on the submarine plans: hooks passed by
//! controller name, each controller reachable typed (its hooks, data,
//! status, verb and state by name) while its executive is in the system,
//! and the per-controller `verb_name` / `state_name` functions.

use rcs_plan_sets::set_submarine::submarine::types::{SpeedError, TurbineSensors};
use rcs_plan_sets::set_submarine::submarine::{pr, sm, tb, Hooks, System};

/// PR's hooks, with a field the test reads back through `system.pr()`.
#[derive(Debug)]
struct Model {
    asked: u32,
}

impl pr::Hooks for Model {
    fn required_rpm(&mut self, _: &pr::Data, speed: f64) -> f64 {
        self.asked += 1;
        10.0 * speed
    }
    fn speed_error(&mut self, _: &pr::Data) -> SpeedError {
        SpeedError::Below
    }
}

#[test]
fn names_of_verbs_and_states_come_from_the_plans() {
    assert_eq!(pr::verb_name(0), Some("INIT"));
    assert_eq!(pr::verb_name(2), Some("AHEAD"));
    assert_eq!(pr::verb_name(3), None);
    assert_eq!(tb::verb_name(3), Some("STOP"));
    assert_eq!(sm::state_name(1, 2), Some("S2"));
    assert_eq!(pr::state_name(2, 1), Some("S1"));
    assert_eq!(pr::state_name(2, 9), None);
    assert_eq!(pr::state_name(7, 0), None);
}

#[test]
fn a_system_gives_typed_controllers_while_it_holds_their_executive() {
    let mut system = System::new(Hooks {
        pr: Model { asked: 0 },
    })
    .expect("setup");
    let pr = system.pr().expect("PR");
    assert_eq!((pr.verb_name(), pr.state_name()), (None, None));
    assert_eq!(pr.status(), Some(pr::Status::NotReady));

    system.inputs.turbine.write(TurbineSensors { rpm: 0.0 }, 0);
    system
        .operators
        .sm
        .command(sm::Command::Transit { speed: 4.0 });
    system.run_cycles(2).expect("no hook panics");
    let pr = system.pr().expect("PR");
    assert_eq!(pr.verb_name(), Some("AHEAD"));
    assert_eq!(pr.state_name(), Some("S1"));
    assert_eq!(pr.status(), Some(pr::Status::Executing));
    assert_eq!(pr.data().command, pr::Command::Ahead { speed: 4.0 });
    assert_eq!(pr.hooks().asked, 1);
    let tb = system.tb().expect("TB");
    assert_eq!(
        (tb.verb_name(), tb.state_name()),
        (Some("AHEAD"), Some("S1"))
    );
    assert_eq!(system.outputs.drive.read().value.rpm_setpoint, 40.0);

    system.pr_mut().expect("PR").hooks_mut().asked = 10;
    assert_eq!(system.pr().map(|pr| pr.hooks().asked), Some(10));

    // The timing report names each supervisor's subordinates with their
    // stale echoes: none here, as each subordinate runs after its
    // supervisor in the same heartbeat and answers at once.
    let exec = &system.executives[0];
    assert_eq!(exec.old_echoes("SM"), vec![("PR".to_string(), 0)]);
    assert_eq!(exec.old_echoes("PR"), vec![("TB".to_string(), 0)]);
    assert!(exec.old_echoes("TB").is_empty());

    // Out of the system (to run on a thread), an executive's controllers
    // are not reachable; back in, they are.
    let executives = std::mem::take(&mut system.executives);
    assert!(system.pr().is_none() && system.sm().is_none());
    system.executives = executives;
    assert_eq!(
        system.sm().and_then(|sm| sm.status()),
        Some(sm::Status::Executing)
    );
}

/// Every error a controller can report has a variant of its `Error`: the
/// built-ins (`UNKNOWN_COMMAND`, `INDEX_RANGE`, `HOOK_PANIC`) as well as the declared
/// codes, each going to its runtime code and back and named as in the plans.
#[test]
fn built_in_and_declared_errors_round_trip_through_the_typed_error() {
    use rcs_runtime::ErrorCode;
    let cases = [
        (
            pr::Error::UnknownCommand,
            ErrorCode::UNKNOWN_COMMAND,
            "UNKNOWN_COMMAND",
        ),
        (pr::Error::IndexRange, ErrorCode::INDEX_RANGE, "INDEX_RANGE"),
        (pr::Error::HookPanic, ErrorCode::HOOK_PANIC, "HOOK_PANIC"),
        (
            pr::Error::TurbineFailed,
            pr::error::TURBINE_FAILED,
            "TURBINE_FAILED",
        ),
    ];
    for (typed, raw, name) in cases {
        assert_eq!(pr::Error::from_raw(raw), Some(typed), "{name}");
        assert_eq!(typed.raw(), raw, "{name}");
        assert_eq!(typed.name(), name);
    }
    assert_eq!(pr::error::INDEX_RANGE, ErrorCode::INDEX_RANGE);
    assert_eq!(pr::error::HOOK_PANIC, ErrorCode::HOOK_PANIC);
    assert_eq!(pr::Error::from_raw(ErrorCode::NONE), None);
    // The declared codes sit between the built-ins.
    assert_eq!(
        pr::Error::from_raw(ErrorCode(ErrorCode::HOOK_PANIC.0 - 1)),
        None
    );
}
