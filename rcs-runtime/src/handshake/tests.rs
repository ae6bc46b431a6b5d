//! Unit tests of [`super`] (handshake.rs), kept apart to keep that file short.
use super::*;

/// The epoch of the links in these tests.
const E: u32 = 7;

fn stamped(echo: u32, status: Status, generation: u64) -> Stamped<StatusBuffer> {
    stamped_in(E, echo, status, generation)
}

fn stamped_in(epoch: u32, echo: u32, status: Status, generation: u64) -> Stamped<StatusBuffer> {
    Stamped {
        value: StatusBuffer {
            echo_serial: echo,
            echo_epoch: epoch,
            status,
            error: if status == Status::ERROR {
                ErrorCode::custom(0)
            } else {
                ErrorCode::NONE
            },
            verb: 0,
            state: 0,
            ..Default::default()
        },
        generation,
        writer_cycle: generation,
    }
}

#[test]
fn serials_wrap_to_one_never_zero() {
    assert_eq!(next_serial(0), 1);
    assert_eq!(next_serial(41), 42);
    assert_eq!(next_serial(u32::MAX - 1), u32::MAX);
    assert_eq!(next_serial(u32::MAX), 1);
    let mut l = SubordinateLink::with_epoch(E);
    l.set_last_sent(u32::MAX);
    assert_eq!(l.next_command(), 1);
    assert_eq!(l.last_sent(), 1);
    assert_ne!(l.epoch(), E, "a wrap takes a fresh epoch");
    assert_ne!(l.epoch(), 0);
}

#[test]
fn a_restarted_supervisor_is_not_answered_by_the_old_done() {
    // The previous incarnation sent serial 1 and the subordinate still
    // shows DONE for it.
    let mut before = SubordinateLink::fresh();
    let old = before.next_command();
    let old_done = stamped_in(before.epoch(), old, Status::DONE, 1);
    assert!(before.observe(&old_done).done());
    // The supervisor restarts: a fresh link counts from 1 again.
    let mut after = SubordinateLink::fresh();
    let new = after.next_command();
    assert_eq!(new, old, "the serial alone repeats");
    assert_ne!(after.epoch(), before.epoch());
    let v = after.observe(&old_done);
    assert_eq!((v.status, v.raw.status), (Status::EXECUTING, Status::DONE));
    assert!(!v.done());
    assert_eq!(after.old_echoes(), 1);
    // The subordinate picks the new command up and answers it.
    let (serial, epoch) = after.echo_of_last();
    assert!(after
        .observe(&stamped_in(epoch, serial, Status::DONE, 2))
        .done());
}

#[test]
fn after_a_wrap_the_old_done_for_serial_one_does_not_answer() {
    let mut l = SubordinateLink::fresh();
    let first = l.next_command();
    assert_eq!(first, 1);
    let old_done = stamped_in(l.epoch(), first, Status::DONE, 1);
    assert!(l.observe(&old_done).done());
    // 2³² - 1 commands later the serials wrap back to 1.
    l.set_last_sent(u32::MAX);
    assert_eq!(l.next_command(), 1);
    let v = l.observe(&old_done);
    assert_eq!(
        v.status,
        Status::EXECUTING,
        "the old DONE is not the answer"
    );
    let (serial, epoch) = l.echo_of_last();
    assert!(l
        .observe(&stamped_in(epoch, serial, Status::DONE, 2))
        .done());
}

#[test]
fn a_link_draws_its_epoch_with_its_first_command() {
    let mut l = SubordinateLink::new();
    assert_eq!(l.epoch(), 0);
    // Nothing sent: a zeroed status (no epoch) is the true NOT_READY.
    assert_eq!(l.observe(&Stamped::default()).status, Status::NOT_READY);
    l.next_command();
    assert_ne!(l.epoch(), 0);
    // A status without the epoch does not answer the command.
    assert!(l.observe(&stamped_in(0, 1, Status::DONE, 1)).executing());
}

#[test]
fn zeroed_buffers_read_not_ready() {
    let s = StatusBuffer::default();
    assert_eq!(s.echo_serial, 0);
    assert_eq!(s.status, Status::NOT_READY);
    assert!(s.error.is_none());
    let c = CommandBuffer::<VerbId>::default();
    assert_eq!((c.serial, c.epoch, c.verb()), (0, 0, 0));
    // Nothing sent, nothing written: the real NOT_READY shows through.
    let mut l = SubordinateLink::with_epoch(E);
    assert_eq!(l.observe(&Stamped::default()).status, Status::NOT_READY);
}

#[test]
fn status_echoing_older_serial_reads_executing() {
    let mut l = SubordinateLink::with_epoch(E);
    let s1 = l.next_command();
    assert_eq!(
        l.observe(&stamped(s1, Status::DONE, 1)).status,
        Status::DONE
    );
    let s2 = l.next_command();
    assert_eq!(s2, s1 + 1);
    // The subordinate still shows DONE for s1: a stale DONE.
    let v = l.observe(&stamped(s1, Status::DONE, 2));
    assert_eq!(v.status, Status::EXECUTING);
    assert!(!v.done());
    assert_eq!(v.raw.status, Status::DONE);
    // An ERROR for the older command is masked too.
    let v = l.observe(&stamped(s1, Status::ERROR, 3));
    assert_eq!((v.status, v.error), (Status::EXECUTING, ErrorCode::NONE));
    // The echo arrives.
    let v = l.observe(&stamped(s2, Status::ERROR, 4));
    assert!(v.error());
    assert_eq!(v.error, ErrorCode::custom(0));
}

#[test]
fn a_stale_echo_every_cycle_is_counted() {
    // The subordinate writes its status every cycle (so `stale_cycles`
    // stays 0) but keeps echoing the command before the last one.
    let mut link = SubordinateLink::with_epoch(E);
    let first = link.next_command();
    let v = link.observe(&stamped(first, Status::DONE, 1));
    assert_eq!(v.status, Status::DONE);
    assert_eq!(link.old_echoes(), 0);
    link.next_command();
    for g in 2..12 {
        let v = link.observe(&stamped(first, Status::DONE, g));
        assert_eq!(v.stale_cycles, 0);
        assert_eq!(v.status, Status::EXECUTING);
    }
    assert_eq!(link.old_echoes(), 10);
}

#[test]
fn stale_cycles_grow_for_silent_and_reset_for_live() {
    let mut silent = SubordinateLink::with_epoch(E);
    let mut live = SubordinateLink::with_epoch(E);
    let frozen = stamped(0, Status::NOT_READY, 5);
    for cycle in 0..10u64 {
        let vs = silent.observe(&frozen);
        let vl = live.observe(&stamped(0, Status::NOT_READY, 6 + cycle));
        assert_eq!(vs.stale_cycles as u64, cycle);
        assert_eq!(vl.stale_cycles, 0);
    }
    // Never written: stale from the first cycle.
    let mut mute = SubordinateLink::with_epoch(E);
    assert_eq!(mute.observe(&Stamped::default()).stale_cycles, 1);
    assert_eq!(mute.observe(&Stamped::default()).stale_cycles, 2);
}

#[test]
fn status_codes() {
    assert_eq!(Status::custom(0), Status(4));
    assert_eq!(Status::DONE.builtin_name(), Some("DONE"));
    assert_eq!(Status::custom(1).builtin_name(), None);
    assert_eq!(ErrorCode::custom(0), ErrorCode(2));
    assert!(!ErrorCode::UNKNOWN_COMMAND.is_none());
    assert_eq!(ErrorCode::HOOK_PANIC, ErrorCode(u16::MAX - 1));
    assert_ne!(ErrorCode::HOOK_PANIC, ErrorCode::INDEX_RANGE);
}

#[test]
fn subordinate_port_round_trip() {
    let gm = GlobalMemory::new();
    let mut sub = Subordinate::<VerbId>::connect(&gm, "TB").unwrap();
    // Only one supervisor: the command writer is taken.
    assert!(matches!(
        Subordinate::<VerbId>::connect(&gm, "TB"),
        Err(SetupError::WriterTaken(_))
    ));
    let cmd = gm.command_reader::<VerbId>("TB").unwrap();
    let mut st = gm.status_writer("TB").unwrap();
    assert!(!sub.flush(1));
    assert_eq!(cmd.read().generation, 0);
    let serial = sub.send(3);
    assert!(sub.flush(1));
    let c = cmd.read();
    assert_eq!(
        (c.value.serial, c.value.verb(), c.writer_cycle),
        (serial, 3, 1)
    );
    assert_eq!(c.value.epoch, sub.link().epoch());
    assert_ne!(c.value.epoch, 0);
    assert!(sub.read().executing());
    // The right serial from another epoch does not answer.
    st.write(
        StatusBuffer {
            echo_serial: serial,
            echo_epoch: c.value.epoch.wrapping_add(1),
            status: Status::DONE,
            ..Default::default()
        },
        6,
    );
    assert!(sub.read().executing());
    st.write(
        StatusBuffer {
            echo_serial: serial,
            echo_epoch: c.value.epoch,
            status: Status::DONE,
            ..Default::default()
        },
        7,
    );
    assert!(sub.read().done());
    assert!(sub.view().done());
    assert_eq!(sub.last_command().serial, serial);
}

#[test]
fn status_ranges() {
    let ok = StatusBuffer {
        echo_serial: 9,
        echo_epoch: 5,
        status: Status::custom(1),
        error: ErrorCode::custom(2),
        verb: 1,
        state: 4,
        ..Default::default()
    };
    assert_eq!(ok.check_range(2, 3, 2, 5), Ok(()));
    let bad = |f: fn(&mut StatusBuffer)| {
        let mut s = ok;
        f(&mut s);
        s.check_range(2, 3, 2, 5)
    };
    assert_eq!(bad(|s| s.status = Status(u16::MAX)), Err("status"));
    assert_eq!(bad(|s| s.status = Status::custom(2)), Err("status"));
    assert_eq!(
        bad(|s| s.error = ErrorCode(u16::MAX - 7)),
        Err("error code")
    );
    assert_eq!(bad(|s| s.error = ErrorCode::custom(3)), Err("error code"));
    assert_eq!(bad(|s| s.error = ErrorCode::INDEX_RANGE), Ok(()));
    assert_eq!(bad(|s| s.error = ErrorCode::UNKNOWN_COMMAND), Ok(()));
    assert_eq!(bad(|s| s.verb = 2), Err("verb"));
    assert_eq!(bad(|s| s.state = 5), Err("state"));
    // The zeroed buffer of a controller that has no verbs yet.
    assert_eq!(StatusBuffer::default().check_range(0, 0, 0, 0), Ok(()));
}

#[test]
fn a_refusal_answers_only_the_command_it_names() {
    let mut l = SubordinateLink::with_epoch(E);
    let s1 = l.next_command();
    let mut read = stamped(s1, Status::EXECUTING, 1);
    assert_eq!(l.observe(&read).status, Status::EXECUTING);
    let s2 = l.next_command();
    // X refuses s2 and its plan for s1 goes on, then completes: DONE for s1.
    read.value.refused_serial = s2;
    read.value.refused_epoch = E;
    read.generation = 2;
    let v = l.observe(&read);
    assert_eq!((v.status, v.error), (Status::ERROR, ErrorCode::REFUSED));
    read.value.status = Status::DONE;
    read.generation = 3;
    let v = l.observe(&read);
    assert_eq!(
        (v.status, v.error),
        (Status::ERROR, ErrorCode::REFUSED),
        "the running plan's DONE never answers the refused command"
    );
    // A refusal of another epoch (another incarnation) is not ours.
    read.value.refused_epoch = E + 1;
    read.generation = 4;
    assert_eq!(l.observe(&read).status, Status::EXECUTING);
    // Sending again ends it: the old refusal names s2, not s3.
    read.value.refused_epoch = E;
    let s3 = l.next_command();
    read.generation = 5;
    assert_eq!(l.observe(&read).status, Status::EXECUTING);
    read.value.echo_serial = s3;
    read.generation = 6;
    assert_eq!(l.observe(&read).status, Status::DONE);
    assert!(ErrorCode::REFUSED.is_builtin());
}
