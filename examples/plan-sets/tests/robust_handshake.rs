//! Command identity and fault containment through generated code (the
//! submarine plans): a restarted supervisor is not answered by the DONE its
//! previous incarnation got (both backends), and a panicking hook ends its
//! controller's plan with `HOOK_PANIC` while the others run on.

use rcs_plan_sets::set_submarine::submarine::types::{SpeedError, TurbineSensors};
use rcs_plan_sets::set_submarine::submarine::{pr, sm, tb, Hooks, System};
use rcs_runtime::driver::Driven;
use rcs_runtime::{ErrorCode, Status, StatusBuffer};

/// Plays PR's supervisor and TB on a driver of either backend: PR sends TB
/// its serial 1 while TB still shows DONE for serial 1 of an earlier
/// incarnation of PR (another epoch). PR must wait for TB's own answer.
fn restarted_pr_waits_for_the_new_answer(d: &mut dyn Driven) {
    let name = d.name().to_string();
    d.command("INIT", &[]).expect("INIT");
    // The previous incarnation's epoch: any epoch this process drew is
    // another than the one the driver's link drew.
    let old_done = StatusBuffer {
        echo_serial: 1,
        echo_epoch: rcs_runtime::fresh_epoch(),
        status: Status::DONE,
        ..StatusBuffer::default()
    };
    d.write_sub_status("TB", old_done).expect("TB");
    let first = d.cycle();
    assert_eq!(d.last_sent("TB").expect("TB"), 1, "{name}: serials restart");
    assert_eq!(first.status, Status::EXECUTING, "{name}");
    for _ in 0..10 {
        d.write_sub_status("TB", old_done).expect("TB");
        let rec = d.cycle();
        assert_eq!(
            rec.status,
            Status::EXECUTING,
            "{name}: the old DONE answered the new command"
        );
    }
    // TB answers the command PR sent (echo epoch 0: the driver fills in
    // the epoch of PR's commands to TB).
    let answer = StatusBuffer {
        echo_serial: 1,
        status: Status::DONE,
        ..StatusBuffer::default()
    };
    d.write_sub_status("TB", answer).expect("TB");
    assert_eq!(d.cycle().status, Status::DONE, "{name}");
}

#[test]
fn a_restarted_supervisor_is_not_answered_by_the_old_done_on_both_backends() {
    let path = "plans/submarine";
    let set = rcs_plan_sets::SETS
        .iter()
        .find(|s| s.path == path)
        .expect("the set is compiled");
    let mut generated = (set.new_driver)("PR").expect("PR").expect("setup");
    restarted_pr_waits_for_the_new_answer(&mut *generated);

    let dir = std::path::Path::new("../..").join(path);
    let plans = rcs_dsl::load_folder(&dir).expect("plans load");
    let ir = rcs_dsl::check(&plans, &rcs_dsl::Options::default())
        .ir
        .expect("checks clean");
    let pr = ir.controller_by_name("PR").expect("PR");
    let mut interp = rcs_dsl::interp::Driven::new(&ir, pr);
    restarted_pr_waits_for_the_new_answer(&mut interp);
}

/// PR's hooks; `required_rpm` panics while `broken` is set.
#[derive(Debug)]
struct Model {
    broken: bool,
}

impl pr::Hooks for Model {
    fn required_rpm(&mut self, _: &pr::Data, speed: f64) -> f64 {
        assert!(!self.broken, "propulsion model unavailable");
        10.0 * speed
    }
    fn speed_error(&mut self, _: &pr::Data) -> SpeedError {
        SpeedError::Below
    }
}

#[test]
fn a_panicking_hook_ends_its_plan_with_hook_panic_and_the_others_run_on() {
    let mut system = System::new(Hooks {
        pr: Model { broken: true },
    })
    .expect("setup");
    system.inputs.turbine.write(TurbineSensors { rpm: 0.0 }, 0);
    system
        .operators
        .sm
        .command(sm::Command::Transit { speed: 4.0 });
    let tb_status = system.gm.status_reader("TB").expect("TB");
    let sm_status = system.gm.status_reader("SM").expect("SM");
    let (tb_before, sm_before) = (tb_status.generation(), sm_status.generation());

    let fault = system.run_cycles(3).expect_err("PR's hook panics");
    assert_eq!(fault.total, 1, "{fault}");
    let panic = &fault.panics[0];
    assert_eq!(
        (panic.controller.as_str(), panic.cycle),
        ("PR", 0),
        "{fault}"
    );
    assert_eq!(panic.message, "propulsion model unavailable");

    // PR shows ERROR with HOOK_PANIC through the handshake; SM saw it and
    // ended its transit; TB and SM kept writing their statuses.
    let pr_status = rcs_runtime::read_status(&system.gm, "PR").expect("PR");
    assert_eq!(
        (pr_status.value.status, pr_status.value.error),
        (Status::ERROR, ErrorCode::HOOK_PANIC)
    );
    assert_eq!(
        pr::Error::from_raw(pr_status.value.error),
        Some(pr::Error::HookPanic)
    );
    assert_eq!(pr::Error::HookPanic.name(), "HOOK_PANIC");
    assert_eq!(
        system.pr().and_then(pr::Controller::status),
        Some(pr::Status::Error)
    );
    assert_eq!(
        system.sm().map(|c| c.bookkeeping().error()),
        Some(sm::error::SUBORDINATE_FAILED)
    );
    assert_eq!(tb_status.generation(), tb_before + 3);
    assert_eq!(sm_status.generation(), sm_before + 3);
    let exec = &system.executives[0];
    assert_eq!(exec.controller_stats("PR").map(|s| s.panics), Some(1));
    assert_eq!(exec.last_panic("PR"), Some("propulsion model unavailable"));

    // Mended, PR takes the next command normally.
    system.pr_mut().expect("PR").hooks_mut().broken = false;
    system
        .operators
        .sm
        .command(sm::Command::Transit { speed: 4.0 });
    system.run_cycles(2).expect("no panic");
    let pr = system.pr().expect("PR");
    assert_eq!(pr.status(), Some(pr::Status::Executing));
    assert_eq!(pr.state_name(), Some("S1"));
    let tb = system.tb().expect("TB");
    assert_eq!(tb.verb_name(), Some("AHEAD"));
    assert_eq!(tb.status(), Some(tb::Status::Executing));
    assert_eq!(system.outputs.drive.read().value.rpm_setpoint, 40.0);
}
