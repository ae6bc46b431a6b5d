//! Plan bookkeeping: docs/semantics.md steps 2–4 (all but evaluating rows) and 6,
//! implemented once for generated controllers and the interpreter alike.
//!
//! A [`Bookkeeping`] holds what the seed's controller template keeps in its
//! private variables (Appendix A): the echo serial, the active verb, the
//! current state, status and error, `state_cycles` and `plan_cycles`, whether
//! the plan has finished, and which row fired this cycle. The caller owns the
//! rows: it evaluates them and tells the bookkeeping which one fired and
//! where it leads.
//!
//! A cycle of a controller, with `bk` its bookkeeping:
//!
//! 1. read inputs (command buffer, subordinates, `reads` buffers);
//! 2. `bk.begin_cycle(tick, &cmd, has_plan)` — the new-command check (step 3);
//! 3. if `bk.is_active()`: walk the rows of the plan of `bk.verb()` in
//!    `bk.state()`, run the first match's jobs (which may call
//!    `bk.report(..)`), then `bk.fire(row, target)` (step 4);
//! 4. write outputs, the status buffer from `bk.status_buffer()` (step 5);
//! 5. `bk.end_cycle()` (step 6).

use std::time::Instant;

use crate::handshake::{
    Command, CommandBuffer, ErrorCode, RowId, StateId, Status, StatusBuffer, VerbId, S0,
};

/// Where a fired row leads (the `to` of a row).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// A state of the plan.
    State(StateId),
    /// Keep the current state.
    Same,
    /// End the plan with status DONE.
    Done,
    /// End the plan with status ERROR and this code.
    Error(ErrorCode),
}

/// The executive's clock for one controller cycle: the cycle count and the
/// moment the controller started.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tick {
    /// The executive's cycle count (0 on the first cycle).
    pub cycle: u64,
    /// When this controller's cycle began.
    pub now: Instant,
}

impl Tick {
    /// A tick for `cycle` at the current instant.
    pub fn now(cycle: u64) -> Self {
        Self {
            cycle,
            now: Instant::now(),
        }
    }
}

/// Last, min, max and mean of a series of `u64` samples (nanoseconds or
/// cycles). All zeros before the first sample.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct SampleStats {
    /// Number of samples.
    pub count: u64,
    /// The latest sample.
    pub last: u64,
    /// The smallest sample.
    pub min: u64,
    /// The largest sample.
    pub max: u64,
    /// Sum of all samples (saturating).
    pub total: u64,
}

impl SampleStats {
    /// Add a sample.
    #[inline]
    pub fn record(&mut self, v: u64) {
        if self.count == 0 || v < self.min {
            self.min = v;
        }
        if v > self.max {
            self.max = v;
        }
        self.last = v;
        self.count = self.count.saturating_add(1);
        self.total = self.total.saturating_add(v);
    }

    /// The mean sample (0 with no samples).
    pub fn mean(&self) -> u64 {
        self.total.checked_div(self.count).unwrap_or(0)
    }
}

/// How long the commands of one verb took, from the cycle the new command
/// arrived to the cycle its plan reached DONE or ERROR (§3.9.1, §5.3.3).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct VerbStats {
    /// Commands of this verb that ended DONE.
    pub done: u64,
    /// Commands of this verb that ended ERROR.
    pub errors: u64,
    /// Commands of this verb superseded by a new command before finishing.
    pub superseded: u64,
    /// Duration in cycles, counting the first and the last cycle (a plan
    /// that is done on the cycle its command arrived took 1 cycle).
    pub cycles: SampleStats,
    /// Duration in nanoseconds, from the start of the controller's cycle
    /// that saw the new command to the start of the one that finished it.
    pub nanos: SampleStats,
}

/// Step 3's result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NewCommand {
    /// Same serial as before: keep going.
    No,
    /// A new command with a plan: it is active from `S0`.
    Started,
    /// A new command whose verb has no plan: status ERROR, UNKNOWN_COMMAND.
    Unknown,
}

/// The plan bookkeeping of one controller. See the module docs for the call
/// order. Never allocates after construction and never panics.
#[derive(Debug, Clone)]
pub struct Bookkeeping {
    echo_serial: u32,
    verb: VerbId,
    state: StateId,
    status: Status,
    error: ErrorCode,
    running: bool,
    new_command: bool,
    fired: Option<RowId>,
    state_cycles: u32,
    plan_cycles: u32,
    now: Option<Instant>,
    started_at: Option<Instant>,
    verb_stats: Vec<VerbStats>,
    /// An index out of range was met this cycle (see [`Bookkeeping::index_range`]).
    index_range: bool,
}

impl Bookkeeping {
    /// Bookkeeping for a controller with `verb_count` verbs (ids
    /// `0..verb_count`; the per-verb statistics are sized here, once).
    pub fn new(verb_count: usize) -> Self {
        Self {
            echo_serial: 0,
            verb: 0,
            state: S0,
            status: Status::NOT_READY,
            error: ErrorCode::NONE,
            running: false,
            new_command: false,
            fired: None,
            state_cycles: 0,
            plan_cycles: 0,
            now: None,
            started_at: None,
            verb_stats: vec![VerbStats::default(); verb_count],
            index_range: false,
        }
    }

    /// Step 3 for a typed command buffer; see [`begin_cycle_raw`](Self::begin_cycle_raw).
    #[inline]
    pub fn begin_cycle<C: Command>(
        &mut self,
        tick: Tick,
        cmd: &CommandBuffer<C>,
        has_plan: bool,
    ) -> NewCommand {
        self.begin_cycle_raw(tick, cmd.serial, cmd.verb(), has_plan)
    }

    /// Step 3: the new-command check. `has_plan` says whether `verb` has a
    /// plan (generated code: always, for a verb of its enum; an interpreter:
    /// whether its plan table has the verb).
    ///
    /// On a new serial: echo it, status EXECUTING, error cleared, the plan of
    /// `verb` becomes active in `S0` with both counters 0. The running
    /// command, if any, is superseded at once and never resumed. Without a
    /// plan: status ERROR, error UNKNOWN_COMMAND, no active plan.
    #[inline]
    pub fn begin_cycle_raw(
        &mut self,
        tick: Tick,
        serial: u32,
        verb: VerbId,
        has_plan: bool,
    ) -> NewCommand {
        self.fired = None;
        self.index_range = false;
        self.now = Some(tick.now);
        if serial == self.echo_serial {
            self.new_command = false;
            return NewCommand::No;
        }
        if self.running {
            if let Some(s) = self.verb_stats.get_mut(usize::from(self.verb)) {
                s.superseded = s.superseded.saturating_add(1);
            }
        }
        self.new_command = true;
        self.echo_serial = serial;
        self.verb = verb;
        self.state = S0;
        self.state_cycles = 0;
        self.plan_cycles = 0;
        self.error = ErrorCode::NONE;
        self.started_at = Some(tick.now);
        if has_plan {
            self.status = Status::EXECUTING;
            self.running = true;
            NewCommand::Started
        } else {
            self.status = Status::ERROR;
            self.error = ErrorCode::UNKNOWN_COMMAND;
            self.running = true; // so that finish() records it
            self.finish(false);
            NewCommand::Unknown
        }
    }

    /// Whether a plan is active and has not finished: only then are its rows
    /// walked (step 4).
    #[inline]
    pub fn is_active(&self) -> bool {
        self.running
    }

    /// Step 4: row `row` fired and leads to `target`. A state change resets
    /// `state_cycles` only if the state differs; `Done` and `Error` finish the
    /// plan. Returns `false` (and changes nothing) if no plan is active or a
    /// row already fired this cycle: at most one row fires per cycle.
    #[inline]
    pub fn fire(&mut self, row: RowId, target: Target) -> bool {
        if !self.running || self.fired.is_some() {
            return false;
        }
        self.fired = Some(row);
        let target = if self.index_range {
            Target::Error(ErrorCode::INDEX_RANGE)
        } else {
            target
        };
        match target {
            Target::State(s) => {
                if s != self.state {
                    self.state = s;
                    self.state_cycles = 0;
                }
            }
            Target::Same => {}
            Target::Done => {
                self.status = Status::DONE;
                self.finish(true);
            }
            Target::Error(code) => {
                self.status = Status::ERROR;
                self.error = code;
                self.finish(false);
            }
        }
        true
    }

    fn finish(&mut self, done: bool) {
        if !self.running {
            return;
        }
        self.running = false;
        let cycles = u64::from(self.plan_cycles).saturating_add(1);
        let nanos = match (self.now, self.started_at) {
            (Some(now), Some(start)) => {
                u64::try_from(now.saturating_duration_since(start).as_nanos()).unwrap_or(u64::MAX)
            }
            _ => 0,
        };
        if let Some(s) = self.verb_stats.get_mut(usize::from(self.verb)) {
            if done {
                s.done = s.done.saturating_add(1);
            } else {
                s.errors = s.errors.saturating_add(1);
            }
            s.cycles.record(cycles);
            s.nanos.record(nanos);
        }
    }

    /// `report S`: set the status (it stays until the next report, `Done`,
    /// `Error` or new command) and clear any error code a `report
    /// ERROR(CODE)` left; the plan goes on. `report DONE` makes a
    /// supervisor's `X.done` true while the plan keeps running.
    #[inline]
    pub fn report(&mut self, status: Status) {
        self.status = status;
        self.error = ErrorCode::NONE;
    }

    /// `report ERROR(CODE)`: status `ERROR` with `code`, and the plan goes
    /// on (unlike `-> Error(CODE)`, which ends it).
    #[inline]
    pub fn report_error(&mut self, code: ErrorCode) {
        self.status = Status::ERROR;
        self.error = code;
    }

    /// An array was indexed outside its bounds this cycle: the rest of the
    /// cycle's jobs is skipped (the caller's part), a row firing now ends
    /// the plan with `INDEX_RANGE` instead of its target, and
    /// [`end_index_range`](Self::end_index_range) ends the plan if no row fires.
    #[inline]
    pub fn index_range(&mut self) {
        self.index_range = true;
    }

    /// Whether an index was out of range this cycle.
    #[inline]
    pub fn index_range_hit(&self) -> bool {
        self.index_range
    }

    /// If an index was out of range this cycle: status ERROR, error
    /// `INDEX_RANGE`, and the active plan (if any) ends. Called after the
    /// conditions, `pre` and `post` jobs that index by a value.
    #[inline]
    pub fn end_index_range(&mut self) {
        if self.index_range {
            self.status = Status::ERROR;
            self.error = ErrorCode::INDEX_RANGE;
            self.finish(false);
        }
    }

    /// Step 6: count the cycle (`state_cycles` and `plan_cycles` grow by
    /// one, saturating).
    #[inline]
    pub fn end_cycle(&mut self) {
        self.state_cycles = self.state_cycles.saturating_add(1);
        self.plan_cycles = self.plan_cycles.saturating_add(1);
    }

    /// The status buffer to publish in step 5.
    #[inline]
    pub fn status_buffer(&self) -> StatusBuffer {
        StatusBuffer {
            echo_serial: self.echo_serial,
            status: self.status,
            error: self.error,
            verb: self.verb,
            state: self.state,
        }
    }

    /// True only on the cycle a new command arrived.
    #[inline]
    pub fn new_command(&self) -> bool {
        self.new_command
    }
    /// The serial of the command being executed (0: none yet).
    pub fn echo_serial(&self) -> u32 {
        self.echo_serial
    }
    /// The verb of the current (or last) command.
    pub fn verb(&self) -> VerbId {
        self.verb
    }
    /// The current state.
    pub fn state(&self) -> StateId {
        self.state
    }
    /// The current status.
    pub fn status(&self) -> Status {
        self.status
    }
    /// The current error code.
    pub fn error(&self) -> ErrorCode {
        self.error
    }
    /// Whether the plan reached `Done` or `Error` (or the verb was unknown)
    /// and waits for a new command.
    pub fn finished(&self) -> bool {
        !self.running && self.echo_serial != 0
    }
    /// The row that fired this cycle, if any.
    pub fn fired(&self) -> Option<RowId> {
        self.fired
    }
    /// Cycles since the current state was entered.
    pub fn state_cycles(&self) -> u32 {
        self.state_cycles
    }
    /// Cycles since the current command began.
    pub fn plan_cycles(&self) -> u32 {
        self.plan_cycles
    }
    /// Per-verb durations, indexed by verb id.
    pub fn verb_stats(&self) -> &[VerbStats] {
        &self.verb_stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const INIT: VerbId = 0;
    const MOVE: VerbId = 1;

    fn tick(c: u64) -> Tick {
        Tick::now(c)
    }

    #[test]
    fn idle_until_first_command() {
        let mut bk = Bookkeeping::new(2);
        assert_eq!(bk.begin_cycle_raw(tick(0), 0, 0, true), NewCommand::No);
        assert!(!bk.is_active() && !bk.new_command() && !bk.finished());
        assert_eq!(bk.status_buffer(), StatusBuffer::default());
        assert!(!bk.fire(0, Target::Done), "nothing fires without a plan");
    }

    #[test]
    fn new_command_resets_and_starts_in_s0() {
        let mut bk = Bookkeeping::new(2);
        assert_eq!(
            bk.begin_cycle_raw(tick(0), 1, MOVE, true),
            NewCommand::Started
        );
        assert!(bk.new_command() && bk.is_active());
        assert_eq!(
            bk.status_buffer(),
            StatusBuffer {
                echo_serial: 1,
                status: Status::EXECUTING,
                error: ErrorCode::NONE,
                verb: MOVE,
                state: S0
            }
        );
        assert!(bk.fire(0, Target::State(1)));
        bk.end_cycle();
        assert_eq!(bk.begin_cycle_raw(tick(1), 1, MOVE, true), NewCommand::No);
        assert!(!bk.new_command());
        assert_eq!((bk.state(), bk.state_cycles(), bk.plan_cycles()), (1, 1, 1));
    }

    #[test]
    fn state_cycles_reset_only_when_state_differs() {
        let mut bk = Bookkeeping::new(1);
        bk.begin_cycle_raw(tick(0), 1, 0, true);
        bk.fire(0, Target::State(1));
        bk.end_cycle();
        for c in 1..5 {
            bk.begin_cycle_raw(tick(c), 1, 0, true);
            bk.fire(1, Target::State(1)); // same state by name
            bk.end_cycle();
        }
        assert_eq!(bk.state_cycles(), 5);
        bk.begin_cycle_raw(tick(5), 1, 0, true);
        bk.fire(2, Target::Same);
        bk.end_cycle();
        assert_eq!(bk.state_cycles(), 6);
        bk.begin_cycle_raw(tick(6), 1, 0, true);
        bk.fire(3, Target::State(2));
        assert_eq!(bk.state_cycles(), 0);
        bk.end_cycle();
        assert_eq!((bk.state_cycles(), bk.plan_cycles()), (1, 7));
    }

    #[test]
    fn at_most_one_row_fires_per_cycle() {
        let mut bk = Bookkeeping::new(1);
        bk.begin_cycle_raw(tick(0), 1, 0, true);
        assert!(bk.fire(0, Target::State(1)));
        assert!(!bk.fire(1, Target::State(2)));
        assert_eq!((bk.fired(), bk.state()), (Some(0), 1));
        bk.end_cycle();
        bk.begin_cycle_raw(tick(1), 1, 0, true);
        assert_eq!(bk.fired(), None, "fired is per cycle");
    }

    #[test]
    fn done_and_error_finish_the_plan() {
        let mut bk = Bookkeeping::new(2);
        bk.begin_cycle_raw(tick(0), 1, INIT, true);
        bk.end_cycle();
        bk.begin_cycle_raw(tick(1), 1, INIT, true);
        assert!(bk.fire(1, Target::Done));
        assert!(bk.finished() && !bk.is_active());
        assert_eq!(bk.status(), Status::DONE);
        bk.end_cycle();
        // A finished plan does nothing until a new command.
        bk.begin_cycle_raw(tick(2), 1, INIT, true);
        assert!(!bk.is_active());
        assert!(!bk.fire(0, Target::State(3)));
        assert_eq!(bk.status(), Status::DONE);
        let s = bk.verb_stats()[usize::from(INIT)];
        assert_eq!((s.done, s.errors, s.cycles.last), (1, 0, 2));

        bk.begin_cycle_raw(tick(3), 2, MOVE, true);
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
        bk.begin_cycle_raw(tick(4), 3, MOVE, true);
        assert_eq!(
            (bk.status(), bk.error()),
            (Status::EXECUTING, ErrorCode::NONE)
        );
    }

    #[test]
    fn unknown_verb_reports_unknown_command() {
        let mut bk = Bookkeeping::new(2);
        assert_eq!(
            bk.begin_cycle_raw(tick(0), 1, 9, false),
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
        bk.begin_cycle_raw(tick(0), 1, MOVE, true);
        bk.fire(0, Target::State(3));
        bk.report(Status::custom(0));
        bk.end_cycle();
        bk.begin_cycle_raw(tick(1), 2, INIT, true);
        assert!(bk.new_command() && bk.is_active());
        assert_eq!(
            (bk.verb(), bk.state(), bk.status()),
            (INIT, S0, Status::EXECUTING)
        );
        assert_eq!((bk.state_cycles(), bk.plan_cycles()), (0, 0));
        assert_eq!(bk.verb_stats()[usize::from(MOVE)].superseded, 1);
    }

    #[test]
    fn report_stays_until_changed() {
        let mut bk = Bookkeeping::new(1);
        bk.begin_cycle_raw(tick(0), 1, 0, true);
        bk.report(Status::custom(0));
        bk.fire(0, Target::State(1));
        bk.end_cycle();
        for c in 1..4 {
            bk.begin_cycle_raw(tick(c), 1, 0, true);
            bk.end_cycle();
            assert_eq!(bk.status(), Status::custom(0));
        }
        bk.begin_cycle_raw(tick(4), 1, 0, true);
        bk.fire(1, Target::Done);
        assert_eq!(bk.status(), Status::DONE);
    }

    #[test]
    fn counters_saturate() {
        let mut bk = Bookkeeping::new(1);
        bk.begin_cycle_raw(tick(0), 1, 0, true);
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
}
