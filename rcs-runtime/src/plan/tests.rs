//! Unit tests of [`super`] (plan.rs), kept apart to keep that file short.
use super::*;

const INIT: VerbId = 0;
const MOVE: VerbId = 1;

fn tick(c: u64) -> Tick {
    Tick::now(c)
}

#[test]
fn idle_until_first_command() {
    let mut bk = Bookkeeping::new(2);
    assert_eq!(bk.begin_cycle_raw(tick(0), 0, 1, 0, true), NewCommand::No);
    assert!(!bk.is_active() && !bk.new_command() && !bk.finished());
    assert_eq!(bk.status_buffer(), StatusBuffer::default());
    assert!(!bk.fire(0, Target::Done), "nothing fires without a plan");
}

#[test]
fn new_command_resets_and_starts_in_s0() {
    let mut bk = Bookkeeping::new(2);
    assert_eq!(
        bk.begin_cycle_raw(tick(0), 1, 1, MOVE, true),
        NewCommand::Started
    );
    assert!(bk.new_command() && bk.is_active());
    assert_eq!(
        bk.status_buffer(),
        StatusBuffer {
            echo_serial: 1,
            echo_epoch: 1,
            status: Status::EXECUTING,
            error: ErrorCode::NONE,
            verb: MOVE,
            state: S0,
            ..Default::default()
        }
    );
    assert!(bk.fire(0, Target::State(1)));
    bk.end_cycle();
    assert_eq!(
        bk.begin_cycle_raw(tick(1), 1, 1, MOVE, true),
        NewCommand::No
    );
    assert!(!bk.new_command());
    assert_eq!((bk.state(), bk.state_cycles(), bk.plan_cycles()), (1, 1, 1));
}

#[test]
fn state_cycles_reset_only_when_state_differs() {
    let mut bk = Bookkeeping::new(1);
    bk.begin_cycle_raw(tick(0), 1, 1, 0, true);
    bk.fire(0, Target::State(1));
    bk.end_cycle();
    for c in 1..5 {
        bk.begin_cycle_raw(tick(c), 1, 1, 0, true);
        bk.fire(1, Target::State(1)); // same state by name
        bk.end_cycle();
    }
    assert_eq!(bk.state_cycles(), 5);
    bk.begin_cycle_raw(tick(5), 1, 1, 0, true);
    bk.fire(2, Target::Same);
    bk.end_cycle();
    assert_eq!(bk.state_cycles(), 6);
    bk.begin_cycle_raw(tick(6), 1, 1, 0, true);
    bk.fire(3, Target::State(2));
    assert_eq!(bk.state_cycles(), 0);
    bk.end_cycle();
    assert_eq!((bk.state_cycles(), bk.plan_cycles()), (1, 7));
}

#[test]
fn at_most_one_row_fires_per_cycle() {
    let mut bk = Bookkeeping::new(1);
    bk.begin_cycle_raw(tick(0), 1, 1, 0, true);
    assert!(bk.fire(0, Target::State(1)));
    assert!(!bk.fire(1, Target::State(2)));
    assert_eq!((bk.fired(), bk.state()), (Some(0), 1));
    bk.end_cycle();
    bk.begin_cycle_raw(tick(1), 1, 1, 0, true);
    assert_eq!(bk.fired(), None, "fired is per cycle");
}

#[test]
fn done_and_error_finish_the_plan() {
    let mut bk = Bookkeeping::new(2);
    bk.begin_cycle_raw(tick(0), 1, 1, INIT, true);
    bk.end_cycle();
    bk.begin_cycle_raw(tick(1), 1, 1, INIT, true);
    assert!(bk.fire(1, Target::Done));
    assert!(bk.finished() && !bk.is_active());
    assert_eq!(bk.status(), Status::DONE);
    bk.end_cycle();
    // A finished plan does nothing until a new command.
    bk.begin_cycle_raw(tick(2), 1, 1, INIT, true);
    assert!(!bk.is_active());
    assert!(!bk.fire(0, Target::State(3)));
    assert_eq!(bk.status(), Status::DONE);
    let s = bk.verb_stats()[usize::from(INIT)];
    assert_eq!((s.done, s.errors, s.cycles.last), (1, 0, 2));

    bk.begin_cycle_raw(tick(3), 2, 1, MOVE, true);
    assert_eq!(
        (bk.status(), bk.error()),
        (Status::EXECUTING, ErrorCode::NONE)
    );
    bk.fire(0, Target::Error(ErrorCode::custom(1)));
    assert_eq!(
        (bk.status(), bk.error()),
        (Status::ERROR, ErrorCode::custom(1))
    );
    assert_eq!(bk.verb_stats()[usize::from(MOVE)].errors, 1);
    // The error is cleared by the next new command.
    bk.end_cycle();
    bk.begin_cycle_raw(tick(4), 3, 1, MOVE, true);
    assert_eq!(
        (bk.status(), bk.error()),
        (Status::EXECUTING, ErrorCode::NONE)
    );
}

#[test]
fn unknown_verb_reports_unknown_command() {
    let mut bk = Bookkeeping::new(2);
    assert_eq!(
        bk.begin_cycle_raw(tick(0), 1, 1, 9, false),
        NewCommand::Unknown
    );
    assert!(bk.new_command());
    assert!(!bk.is_active());
    assert_eq!(
        (bk.status(), bk.error(), bk.echo_serial()),
        (Status::ERROR, ErrorCode::UNKNOWN_COMMAND, 1)
    );
    assert!(!bk.fire(0, Target::Done));
}

#[test]
fn new_command_supersedes_running_one_at_once() {
    let mut bk = Bookkeeping::new(2);
    bk.begin_cycle_raw(tick(0), 1, 1, MOVE, true);
    bk.fire(0, Target::State(3));
    bk.report(Status::custom(0));
    bk.end_cycle();
    bk.begin_cycle_raw(tick(1), 2, 1, INIT, true);
    assert!(bk.new_command() && bk.is_active());
    assert_eq!(
        (bk.verb(), bk.state(), bk.status()),
        (INIT, S0, Status::EXECUTING)
    );
    assert_eq!((bk.state_cycles(), bk.plan_cycles()), (0, 0));
    assert_eq!(bk.verb_stats()[usize::from(MOVE)].superseded, 1);
}

#[test]
fn a_new_epoch_with_the_echoed_serial_is_a_new_command() {
    let mut bk = Bookkeeping::new(2);
    bk.begin_cycle_raw(tick(0), 1, 10, MOVE, true);
    bk.fire(0, Target::Done);
    bk.end_cycle();
    assert_eq!(
        bk.begin_cycle_raw(tick(1), 1, 10, MOVE, true),
        NewCommand::No
    );
    // A restarted supervisor counts from 1 again, in another epoch.
    assert_eq!(
        bk.begin_cycle_raw(tick(2), 1, 11, INIT, true),
        NewCommand::Started
    );
    assert_eq!(
        (bk.status(), bk.verb(), bk.status_buffer().echo_epoch),
        (Status::EXECUTING, INIT, 11)
    );
    assert_eq!(bk.commands_lost(), 0);
}

#[test]
fn a_burst_of_a_thousand_commands_in_one_cycle_counts_999_lost() {
    let mut bk = Bookkeeping::new(2);
    bk.begin_cycle_raw(tick(0), 1, 5, MOVE, true);
    bk.end_cycle();
    // The supervisor sent serials 2..=1001 before this cycle read the
    // buffer: only 1001 arrives.
    bk.begin_cycle_raw(tick(1), 1001, 5, INIT, true);
    assert_eq!(bk.commands_lost(), 999);
    assert_eq!(bk.verb_stats()[usize::from(MOVE)].superseded, 1);
    bk.end_cycle();
    // One at a time loses none; another epoch (a restart, a wrap) is
    // no jump.
    bk.begin_cycle_raw(tick(2), 1002, 5, INIT, true);
    bk.begin_cycle_raw(tick(3), 7, 6, INIT, true);
    assert_eq!(bk.commands_lost(), 999);
}

#[test]
fn a_fault_ends_the_plan_with_its_code_and_the_next_command_runs() {
    let mut bk = Bookkeeping::new(2);
    bk.begin_cycle_raw(tick(0), 1, 1, MOVE, true);
    bk.fault(ErrorCode::HOOK_PANIC);
    assert!(bk.finished() && !bk.is_active());
    assert_eq!(
        (bk.status(), bk.error()),
        (Status::ERROR, ErrorCode::HOOK_PANIC)
    );
    assert_eq!(bk.verb_stats()[usize::from(MOVE)].errors, 1);
    bk.end_cycle();
    assert_eq!(
        bk.begin_cycle_raw(tick(1), 2, 1, MOVE, true),
        NewCommand::Started
    );
    assert_eq!(
        (bk.status(), bk.error()),
        (Status::EXECUTING, ErrorCode::NONE)
    );
}

#[test]
fn report_stays_until_changed() {
    let mut bk = Bookkeeping::new(1);
    bk.begin_cycle_raw(tick(0), 1, 1, 0, true);
    bk.report(Status::custom(0));
    bk.fire(0, Target::State(1));
    bk.end_cycle();
    for c in 1..4 {
        bk.begin_cycle_raw(tick(c), 1, 1, 0, true);
        bk.end_cycle();
        assert_eq!(bk.status(), Status::custom(0));
    }
    bk.begin_cycle_raw(tick(4), 1, 1, 0, true);
    bk.fire(1, Target::Done);
    assert_eq!(bk.status(), Status::DONE);
}

#[test]
fn counters_saturate() {
    let mut bk = Bookkeeping::new(1);
    bk.begin_cycle_raw(tick(0), 1, 1, 0, true);
    bk.state_cycles = u32::MAX - 1;
    bk.plan_cycles = u32::MAX;
    bk.end_cycle();
    bk.end_cycle();
    assert_eq!((bk.state_cycles(), bk.plan_cycles()), (u32::MAX, u32::MAX));
}

#[test]
fn sample_stats() {
    let mut s = SampleStats::default();
    assert_eq!(s.mean(), 0);
    for v in [5, 1, 9] {
        s.record(v);
    }
    assert_eq!((s.count, s.last, s.min, s.max, s.mean()), (3, 9, 1, 9, 5));
}

#[test]
fn a_refused_command_puts_the_running_plan_back_and_is_not_new_again() {
    let mut bk = Bookkeeping::new(2);
    bk.begin_cycle_raw(tick(0), 1, 9, MOVE, true);
    bk.fire(0, Target::State(2));
    bk.report(Status::custom(0));
    bk.end_cycle();
    bk.begin_cycle_raw(tick(1), 1, 9, MOVE, true);
    bk.end_cycle();
    let running = (
        bk.verb(),
        bk.state(),
        bk.status(),
        bk.state_cycles(),
        bk.plan_cycles(),
    );
    assert_eq!(running, (MOVE, 2, Status::custom(0), 2, 2));

    // Serial 2 (INIT) arrives and is refused.
    assert_eq!(
        bk.begin_cycle_raw(tick(2), 2, 9, INIT, true),
        NewCommand::Started
    );
    assert_eq!((bk.verb(), bk.state_cycles()), (INIT, 0));
    bk.refuse();
    assert!(!bk.new_command() && bk.is_active());
    assert_eq!(
        (
            bk.verb(),
            bk.state(),
            bk.status(),
            bk.state_cycles(),
            bk.plan_cycles()
        ),
        running
    );
    let sb = bk.status_buffer();
    assert_eq!(
        (sb.echo_serial, sb.echo_epoch),
        (1, 9),
        "the echo stays on the running command"
    );
    assert_eq!((sb.refused_serial, sb.refused_epoch), (2, 9));
    assert_eq!(bk.verb_stats()[usize::from(MOVE)].superseded, 0);
    bk.end_cycle();

    // The refused command stays in the buffer: not new on later cycles.
    assert_eq!(
        bk.begin_cycle_raw(tick(3), 2, 9, INIT, true),
        NewCommand::No
    );
    assert_eq!(bk.plan_cycles(), 3, "the running plan's counters go on");
    bk.end_cycle();
    // The next one is new, and nothing was lost between them.
    assert_eq!(
        bk.begin_cycle_raw(tick(4), 3, 9, INIT, true),
        NewCommand::Started
    );
    assert_eq!(bk.commands_lost(), 0);
    assert_eq!(
        bk.status_buffer().refused_serial,
        2,
        "the refusal names serial 2 still"
    );
    assert_eq!(bk.verb_stats()[usize::from(MOVE)].superseded, 1);
}

#[test]
fn refuse_without_a_new_command_does_nothing() {
    let mut bk = Bookkeeping::new(2);
    bk.begin_cycle_raw(tick(0), 1, 9, MOVE, true);
    bk.end_cycle();
    bk.begin_cycle_raw(tick(1), 1, 9, MOVE, true);
    let before = bk.status_buffer();
    bk.refuse();
    assert_eq!(bk.status_buffer(), before);
    assert_eq!(bk.refused_serial(), 0);
}

#[test]
fn a_refusal_before_any_command_keeps_not_ready() {
    let mut bk = Bookkeeping::new(2);
    bk.begin_cycle_raw(tick(0), 1, 9, MOVE, true);
    bk.refuse();
    let sb = bk.status_buffer();
    assert_eq!(
        (sb.echo_serial, sb.status, sb.refused_serial),
        (0, Status::NOT_READY, 1)
    );
    assert!(!bk.is_active() && !bk.finished());
}
