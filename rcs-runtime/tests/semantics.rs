//! docs/semantics.md rules checked through the runtime: Global Memory, the
//! handshake, the bookkeeping and the executive together.

mod common;

use std::io::Write;
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

use common::{Relay, GO, HOLD, SUB_FAILED};
use rcs_runtime::{
    read_trace, Controller, CycleContext, ErrorCode, Executive, ExecutiveConfig, GlobalMemory,
    Operator, SetupError, Status, StatusBuffer, TraceSink, VerbId, Wait,
};

fn exec(name: &str, period_ms: u64) -> Executive {
    Executive::new(ExecutiveConfig::new(name, Duration::from_millis(period_ms))).unwrap()
}

/// SM -> PR -> TB on one executive, top-down.
fn hierarchy(tb_work: u32) -> (GlobalMemory, Executive, Operator<VerbId>) {
    let gm = GlobalMemory::new();
    let mut e = exec("main", 10);
    e.add(Box::new(Relay::new(&gm, "SM", Some("PR"), 0).unwrap()))
        .unwrap();
    e.add(Box::new(Relay::new(&gm, "PR", Some("TB"), 0).unwrap()))
        .unwrap();
    e.add(Box::new(Relay::new(&gm, "TB", None, tb_work).unwrap()))
        .unwrap();
    let op = Operator::connect(&gm, "SM").unwrap();
    (gm, e, op)
}

fn status(gm: &GlobalMemory, ctrl: &str) -> StatusBuffer {
    rcs_runtime::read_status(gm, ctrl).unwrap().value
}

#[test]
fn command_flows_down_and_done_flows_up() {
    let (gm, mut e, mut op) = hierarchy(2);
    assert_eq!(status(&gm, "SM"), StatusBuffer::default());
    let serial = op.command(GO);
    assert_eq!(serial, 1);
    // Cycle 0: SM, PR and TB all pick up their command in the same cycle,
    // since a subordinate that runs after its supervisor sees the write.
    e.step().unwrap();
    for c in ["SM", "PR", "TB"] {
        let s = status(&gm, c);
        assert_eq!(
            (s.echo_serial, s.status, s.state),
            (1, Status::EXECUTING, 1),
            "{c}"
        );
    }
    let mut cycles = 1;
    while op.outcome().is_none() {
        e.step().unwrap();
        cycles += 1;
        assert!(cycles < 20);
    }
    assert_eq!(op.outcome(), Some((Status::DONE, ErrorCode::NONE)));
    // TB is done after 2 cycles in S1 (cycle 2), PR sees it on cycle 3, SM on 4.
    assert_eq!(cycles, 5);
    let tb = e.controller("TB").unwrap().bookkeeping().unwrap();
    let stats = tb.verb_stats()[usize::from(GO)];
    assert_eq!((stats.done, stats.cycles.last), (1, 3));
    let sm = e.controller("SM").unwrap().bookkeeping().unwrap();
    assert_eq!(sm.verb_stats()[usize::from(GO)].cycles.last, 5);
    let cs = e.controller_stats("PR").unwrap();
    assert_eq!(cs.exec_ns.count, 5);
    assert!(cs.exec_ns.min <= cs.exec_ns.mean() && cs.exec_ns.mean() <= cs.exec_ns.max);
}

/// A controller whose subordinate is played by the test.
fn sup_with_fake_sub() -> (
    GlobalMemory,
    Executive,
    Operator<VerbId>,
    rcs_runtime::Writer<StatusBuffer>,
    rcs_runtime::Reader<rcs_runtime::CommandBuffer<VerbId>>,
) {
    let gm = GlobalMemory::new();
    let mut e = exec("main", 10);
    e.add(Box::new(Relay::new(&gm, "PR", Some("X"), 0).unwrap()))
        .unwrap();
    let op = Operator::connect(&gm, "PR").unwrap();
    let xs = gm.status_writer("X").unwrap();
    let xc = gm.command_reader::<VerbId>("X").unwrap();
    (gm, e, op, xs, xc)
}

#[test]
fn stale_done_never_completes_a_newer_command() {
    let (gm, mut e, mut op, mut xs, xc) = sup_with_fake_sub();
    op.command(GO);
    e.step().unwrap();
    let first = xc.read().value.serial;
    assert_eq!(first, 1);
    let epoch = xc.read().value.epoch;
    // X finishes the first command.
    let done = |serial| StatusBuffer {
        echo_serial: serial,
        echo_epoch: epoch,
        status: Status::DONE,
        ..Default::default()
    };
    xs.write(done(first), 1);
    // A new command to PR before it saw the DONE: PR sends X a new command.
    op.command(GO);
    e.step().unwrap();
    let second = xc.read().value.serial;
    assert_eq!(second, 2);
    // X keeps showing DONE for the first command for many cycles.
    for c in 0..10 {
        xs.write(done(first), 2 + c);
        e.step().unwrap();
        assert_eq!(status(&gm, "PR").status, Status::EXECUTING);
        assert_eq!(op.outcome(), None);
    }
    // X echoes the second command: now it counts.
    xs.write(done(second), 20);
    e.step().unwrap();
    assert_eq!(status(&gm, "PR").status, Status::DONE);
    assert_eq!(op.outcome(), Some((Status::DONE, ErrorCode::NONE)));
}

#[test]
fn subordinate_error_is_passed_up() {
    let (_gm, mut e, mut op, mut xs, xc) = sup_with_fake_sub();
    op.command(GO);
    e.step().unwrap();
    xs.write(
        StatusBuffer {
            echo_serial: xc.read().value.serial,
            echo_epoch: xc.read().value.epoch,
            status: Status::ERROR,
            error: ErrorCode::custom(5),
            ..Default::default()
        },
        1,
    );
    e.step().unwrap();
    assert_eq!(op.outcome(), Some((Status::ERROR, SUB_FAILED)));
}

#[test]
fn new_command_supersedes_the_running_one_at_once() {
    let (gm, mut e, mut op) = hierarchy(1000);
    op.command(GO);
    e.run_cycles(5).unwrap();
    assert_eq!(status(&gm, "TB").status, Status::EXECUTING);
    let s = op.command(HOLD);
    e.step().unwrap();
    // In the very cycle of the new command every level switched to HOLD.
    for c in ["SM", "PR", "TB"] {
        let st = status(&gm, c);
        assert_eq!(
            (st.verb, st.state, st.status),
            (HOLD, 1, Status::EXECUTING),
            "{c}"
        );
    }
    assert_eq!(status(&gm, "SM").echo_serial, s);
    // GO is never resumed: HOLD is continuous, it stays EXECUTING forever.
    e.run_cycles(2000).unwrap();
    for c in ["SM", "PR", "TB"] {
        assert_eq!(status(&gm, c).verb, HOLD);
    }
    let sm = e.controller("SM").unwrap().bookkeeping().unwrap();
    assert_eq!(sm.verb_stats()[usize::from(GO)].superseded, 1);
    assert_eq!(sm.verb_stats()[usize::from(GO)].done, 0);
}

#[test]
fn serial_wrap_around_is_still_a_new_command() {
    let (gm, mut e, mut op) = hierarchy(1);
    op.set_last_serial(u32::MAX - 1);
    assert_eq!(op.command(GO), u32::MAX);
    e.run_cycles(10).unwrap();
    assert_eq!(op.outcome(), Some((Status::DONE, ErrorCode::NONE)));
    assert_eq!(status(&gm, "SM").echo_serial, u32::MAX);
    // Wraps to 1, never 0.
    assert_eq!(op.command(GO), 1);
    e.step().unwrap();
    assert_eq!(status(&gm, "SM").echo_serial, 1);
    assert_eq!(status(&gm, "SM").status, Status::EXECUTING);
    e.run_cycles(10).unwrap();
    assert_eq!(op.outcome(), Some((Status::DONE, ErrorCode::NONE)));
}

/// What a subordinate shows when it finished `cmd`.
fn done_for(cmd: rcs_runtime::CommandBuffer<VerbId>) -> StatusBuffer {
    StatusBuffer {
        echo_serial: cmd.serial,
        echo_epoch: cmd.epoch,
        status: Status::DONE,
        ..Default::default()
    }
}

#[test]
fn a_restarted_supervisor_is_not_answered_by_the_old_done_for_serial_one() {
    // The first incarnation of PR sends X its command 1, and X finishes it.
    let (_gm, mut e, mut op, mut xs, xc) = sup_with_fake_sub();
    op.command(GO);
    e.step().unwrap();
    let old = xc.read().value;
    assert_eq!(old.serial, 1);
    xs.write(done_for(old), 1);
    e.step().unwrap();
    assert_eq!(op.outcome(), Some((Status::DONE, ErrorCode::NONE)));
    drop((e, op));

    // PR's process restarts (fresh Global Memory and links); X, in another
    // process, still shows DONE for serial 1 of the previous incarnation.
    let (gm, mut e, mut op, mut xs, xc) = sup_with_fake_sub();
    xs.write(done_for(old), 1);
    op.command(GO);
    e.step().unwrap();
    let new = xc.read().value;
    assert_eq!(new.serial, 1, "the serials start again");
    assert_ne!(new.epoch, old.epoch);
    for c in 0..10 {
        xs.write(done_for(old), 2 + c);
        e.step().unwrap();
        assert_eq!(status(&gm, "PR").status, Status::EXECUTING);
        assert_eq!(op.outcome(), None, "the old DONE answered the new command");
    }
    xs.write(done_for(new), 20);
    e.step().unwrap();
    assert_eq!(op.outcome(), Some((Status::DONE, ErrorCode::NONE)));
}

#[test]
fn after_a_serial_wrap_the_old_done_for_serial_one_does_not_answer() {
    let (gm, mut e, mut op, mut xs, xc) = sup_with_fake_sub();
    op.command(GO);
    e.step().unwrap();
    let old = xc.read().value;
    assert_eq!(old.serial, 1);
    xs.write(done_for(old), 1);
    e.step().unwrap();
    assert_eq!(op.outcome(), Some((Status::DONE, ErrorCode::NONE)));
    // 2³² - 2 commands later PR's serials to X wrap back to 1.
    let pr = e.controller_as_mut::<Relay>("PR").unwrap();
    pr.sub.as_mut().unwrap().link_mut().set_last_sent(u32::MAX);
    op.command(GO);
    e.step().unwrap();
    let new = xc.read().value;
    assert_eq!(new.serial, 1);
    assert_ne!(new.epoch, old.epoch);
    for c in 0..10 {
        xs.write(done_for(old), 2 + c);
        e.step().unwrap();
        assert_eq!(status(&gm, "PR").status, Status::EXECUTING);
    }
    xs.write(done_for(new), 20);
    e.step().unwrap();
    assert_eq!(op.outcome(), Some((Status::DONE, ErrorCode::NONE)));
}

#[test]
fn a_burst_of_a_thousand_commands_in_one_cycle_is_counted() {
    let (_gm, mut e, mut op) = hierarchy(1000);
    op.command(GO);
    e.step().unwrap();
    assert_eq!(e.commands_lost("SM"), 0);
    // 1,000 commands before SM's next cycle: it reads only the last.
    for _ in 0..1000 {
        op.command(HOLD);
    }
    e.step().unwrap();
    assert_eq!(e.commands_lost("SM"), 999);
    let sm = e.controller("SM").unwrap().bookkeeping().unwrap();
    assert_eq!(sm.verb_stats()[usize::from(GO)].superseded, 1);
    assert_eq!(sm.verb(), HOLD);
    // SM sends PR one command per cycle: nothing lost below.
    assert_eq!(e.commands_lost("PR"), 0);
    assert_eq!(e.commands_lost("NOBODY"), 0);
}

#[test]
fn unknown_verb_from_an_outside_writer() {
    let (gm, mut e, mut op) = hierarchy(1);
    op.command(7);
    e.step().unwrap();
    let s = status(&gm, "SM");
    assert_eq!(
        (s.status, s.error, s.echo_serial),
        (Status::ERROR, ErrorCode::UNKNOWN_COMMAND, 1)
    );
    // No active plan: nothing sent down.
    assert_eq!(status(&gm, "PR").echo_serial, 0);
    e.run_cycles(3).unwrap();
    assert_eq!(status(&gm, "SM").status, Status::ERROR);
}

/// A silent subordinate's `stale_cycles` grows while a live one's stays 0,
/// as the supervisor sees them inside its cycle.
#[test]
fn silent_subordinate_goes_stale_live_one_does_not() {
    struct Watch {
        live: rcs_runtime::Subordinate<VerbId>,
        mute: rcs_runtime::Subordinate<VerbId>,
        seen: Arc<Mutex<Vec<(u32, u32)>>>,
    }
    impl Controller for Watch {
        fn name(&self) -> &str {
            "W"
        }
        fn cycle(&mut self, _ctx: &CycleContext) {
            let l = self.live.read().stale_cycles;
            let m = self.mute.read().stale_cycles;
            if let Ok(mut s) = self.seen.lock() {
                s.push((l, m));
            }
        }
    }
    let gm = GlobalMemory::new();
    let seen = Arc::new(Mutex::new(Vec::new()));
    let mut e = exec("main", 10);
    // LIVE runs before W, so W sees a fresh generation every cycle.
    e.add(Box::new(Relay::new(&gm, "LIVE", None, 1).unwrap()))
        .unwrap();
    e.add(Box::new(Watch {
        live: rcs_runtime::Subordinate::connect(&gm, "LIVE").unwrap(),
        mute: rcs_runtime::Subordinate::connect(&gm, "MUTE").unwrap(),
        seen: Arc::clone(&seen),
    }))
    .unwrap();
    e.run_cycles(10).unwrap();
    let seen = seen.lock().unwrap();
    let expect: Vec<(u32, u32)> = (1..=10).map(|n| (0, n)).collect();
    assert_eq!(*seen, expect);
}

struct Sleeper(Duration);
impl Controller for Sleeper {
    fn name(&self) -> &str {
        "SLOW"
    }
    fn cycle(&mut self, _ctx: &CycleContext) {
        thread::sleep(self.0);
    }
}

#[test]
fn overrun_is_counted_when_a_controller_exceeds_the_period() {
    let mut e = exec("main", 1);
    e.add(Box::new(Sleeper(Duration::from_millis(3)))).unwrap();
    let h = e.handle();
    e.run_cycles(3).unwrap();
    assert_eq!(e.overruns(), 3);
    assert_eq!(h.overruns(), 3);
    assert_eq!(e.controller_stats("SLOW").unwrap().overruns, 3);
    assert!(e.stats().cycle_ns.max >= 3_000_000);
    // And on the heartbeat.
    e.run_for(2);
    assert_eq!(e.overruns(), 5);
    // A fast controller does not overrun (a period no scheduler delay on a
    // loaded machine comes near).
    let mut fast = Executive::new(ExecutiveConfig::new("fast", Duration::from_secs(3600))).unwrap();
    fast.add(Box::new(Sleeper(Duration::ZERO))).unwrap();
    fast.run_cycles(10).unwrap();
    assert_eq!(fast.overruns(), 0);
}

#[test]
fn single_step_runs_exactly_one_cycle() {
    let (_gm, mut e, _op) = hierarchy(1);
    e.step().unwrap();
    assert_eq!(e.cycle(), 1);
    e.run_cycles(4).unwrap();
    assert_eq!(e.cycle(), 5);

    // Through the handle, on a running heartbeat executive.
    let mut e = exec("bg", 1);
    e.add(Box::new(Sleeper(Duration::ZERO))).unwrap();
    let h = e.handle();
    h.pause();
    let (h, join) = e.spawn().unwrap();
    thread::sleep(Duration::from_millis(20));
    assert_eq!(h.cycle(), 0, "paused: no cycle runs");
    // Wait for the cycle itself (the step is taken before its cycle runs),
    // then give the thread time to run a wrong extra one.
    h.step();
    wait_until(|| h.pending_steps() == 0 && h.cycle() >= 1);
    thread::sleep(Duration::from_millis(20));
    assert_eq!(h.cycle(), 1, "exactly one cycle per step");
    h.step();
    h.step();
    wait_until(|| h.pending_steps() == 0 && h.cycle() >= 3);
    thread::sleep(Duration::from_millis(20));
    assert_eq!(h.cycle(), 3);
    assert!(h.is_paused());
    h.go();
    wait_until(|| h.cycle() > 10);
    h.stop();
    let e = join.join().unwrap();
    assert!(e.cycle() > 10);
    assert!(e.stats().lateness_ns.count > 10);
}

/// Poll `f` until it holds. The limit only turns a hang into a failure: it
/// is far beyond any scheduling delay on a loaded machine.
fn wait_until(mut f: impl FnMut() -> bool) {
    let start = Instant::now();
    while !f() {
        assert!(start.elapsed() < Duration::from_secs(300), "timed out");
        thread::sleep(Duration::from_millis(1));
    }
}

#[test]
fn two_executives_on_two_threads_complete_a_handshake() {
    let gm = GlobalMemory::new();
    let mut upper = exec("upper", 2);
    let mut lower = exec("lower", 5);
    upper
        .add(Box::new(Relay::new(&gm, "SM", Some("PR"), 0).unwrap()))
        .unwrap();
    lower
        .add(Box::new(Relay::new(&gm, "PR", Some("TB"), 0).unwrap()))
        .unwrap();
    lower
        .add(Box::new(Relay::new(&gm, "TB", None, 3).unwrap()))
        .unwrap();
    let mut op = Operator::<VerbId>::connect(&gm, "SM").unwrap();
    let (hu, ju) = upper.spawn().unwrap();
    let (hl, jl) = lower.spawn().unwrap();
    for _ in 0..3 {
        op.command(GO);
        wait_until(|| op.outcome().is_some());
        assert_eq!(op.outcome(), Some((Status::DONE, ErrorCode::NONE)));
    }
    hu.stop();
    hl.stop();
    let upper = ju.join().unwrap();
    let lower = jl.join().unwrap();
    // Both ran (how many cycles each ran depends on the machine's load:
    // a starved thread skips missed deadlines, so no ratio is asserted).
    assert!(upper.cycle() > 0 && lower.cycle() > 0);
    let tb = lower.controller("TB").unwrap().bookkeeping().unwrap();
    assert_eq!(tb.verb_stats()[usize::from(GO)].done, 3);
}

#[test]
fn pause_stops_cycles_go_resumes() {
    let mut e =
        Executive::new(ExecutiveConfig::new("p", Duration::from_millis(1)).with_wait(Wait::Sleep))
            .unwrap();
    e.add(Box::new(Sleeper(Duration::ZERO))).unwrap();
    let h = e.handle();
    h.pause();
    e.run_for(5);
    assert_eq!(e.cycle(), 0);
    h.go();
    e.run_for(5);
    assert_eq!(e.cycle(), 5);
    h.stop();
    e.run();
    assert_eq!(e.cycle(), 5, "a stop before run returns at once");
    h.clear_stop();
    e.run_for(2);
    assert_eq!(e.cycle(), 7);
}

#[test]
fn setup_errors_are_errors() {
    let gm = GlobalMemory::new();
    let mut e = exec("main", 10);
    e.add(Box::new(Relay::new(&gm, "A", None, 1).unwrap()))
        .unwrap();
    // A second controller with the name A cannot even get A's status writer…
    assert!(matches!(
        Relay::new(&gm, "A", None, 1),
        Err(SetupError::WriterTaken(_))
    ));
    // …and a second controller named A on one executive is refused.
    let gm2 = GlobalMemory::new();
    assert!(matches!(
        e.add(Box::new(Relay::new(&gm2, "A", None, 1).unwrap())),
        Err(SetupError::DuplicateController(..))
    ));
    // Two supervisors for one subordinate.
    let _sup = Relay::new(&gm, "S1", Some("A"), 0).unwrap();
    assert!(matches!(
        Relay::new(&gm, "S2", Some("A"), 0),
        Err(SetupError::WriterTaken(_))
    ));
    assert!(matches!(
        Executive::new(ExecutiveConfig::new("z", Duration::ZERO)),
        Err(SetupError::ZeroPeriod(_))
    ));
    let cfg = ExecutiveConfig::new("x", Duration::from_millis(1))
        .with_wait(Wait::Sleep)
        .with_measure(false);
    assert_eq!(cfg.wait, Wait::Sleep);
}

#[derive(Clone, Default)]
struct SharedBuf(Arc<Mutex<Vec<u8>>>);
impl Write for SharedBuf {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        self.0
            .lock()
            .map_err(|_| std::io::Error::other("poisoned"))?
            .extend_from_slice(b);
        Ok(b.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn trace_sink_writes_one_json_line_per_controller_per_cycle() {
    let (_gm, mut e, mut op) = hierarchy(1);
    let buf = SharedBuf::default();
    e.set_trace(TraceSink::new(buf.clone()));
    op.command(GO);
    e.run_cycles(4).unwrap();
    let sink = e.take_trace().unwrap();
    assert_eq!((sink.records(), sink.errors()), (12, 0));
    let text = String::from_utf8(buf.0.lock().unwrap().clone()).unwrap();
    let recs = read_trace(&text).unwrap();
    assert_eq!(recs.len(), 12);
    let tb: Vec<_> = recs.iter().filter(|r| r.controller == "TB").collect();
    assert_eq!(tb[0].cycle, 0);
    assert!(tb[0].new_command);
    assert_eq!(tb[0].fired, Some(0));
    assert_eq!(tb[0].state, Some(1));
    assert_eq!(tb[1].fired, Some(2), "done after one cycle in S1");
    assert_eq!(tb[1].status, Some(Status::DONE.0));
    assert_eq!(tb[2].fired, None);
    assert_eq!(recs[0].executive, "main");
    assert_eq!(recs[0].controller, "SM");
}

#[test]
fn same_inputs_give_the_same_trace() {
    let run = || {
        let (_gm, mut e, mut op) = hierarchy(2);
        let buf = SharedBuf::default();
        e.set_trace(TraceSink::new(buf.clone()));
        op.command(GO);
        e.run_cycles(6).unwrap();
        op.command(HOLD);
        e.run_cycles(3).unwrap();
        op.command(GO);
        e.run_cycles(8).unwrap();
        let out = buf.0.lock().unwrap().clone();
        out
    };
    assert_eq!(run(), run());
}
