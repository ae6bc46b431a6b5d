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
//! 2. `bk.begin_cycle(tick, &cmd, has_plan)` — the new-command check (step 3),
//!    on the command's serial and epoch together;
//! 3. if `bk.is_active()`: walk the rows of the plan of `bk.verb()` in
//!    `bk.state()`, run the first match's jobs (which may call
//!    `bk.report(..)`), then `bk.fire(row, target)` (step 4);
//! 4. write outputs, the status buffer from `bk.status_buffer()` (step 5);
//! 5. `bk.end_cycle()` (step 6).
//!
//! If the cycle panicked (a hook), the executive calls the controller's
//! [`fault`](crate::Controller::fault), which ends the plan through
//! [`Bookkeeping::fault`] with `HOOK_PANIC` and publishes the status.

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
    echo_epoch: u32,
    /// Commands overwritten in the command buffer before this controller
    /// read them (serial jumps within one epoch).
    commands_lost: u64,
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
    /// The command refused last (step 3a): serial and epoch, 0 for none.
    refused_serial: u32,
    refused_epoch: u32,
    /// The newest command taken from the command buffer, accepted or
    /// refused, for counting lost commands.
    last_serial: u32,
    last_epoch: u32,
    /// The plan as it stood before this cycle's new command, to put back
    /// if the command is refused.
    before: Before,
}

/// What step 3 changes, kept so that a refusal (step 3a) undoes it.
#[derive(Debug, Clone, Copy)]
struct Before {
    echo_serial: u32,
    echo_epoch: u32,
    verb: VerbId,
    state: StateId,
    status: Status,
    error: ErrorCode,
    running: bool,
    state_cycles: u32,
    plan_cycles: u32,
    started_at: Option<Instant>,
    superseded: bool,
}

impl Bookkeeping {
    /// Bookkeeping for a controller with `verb_count` verbs (ids
    /// `0..verb_count`; the per-verb statistics are sized here, once).
    pub fn new(verb_count: usize) -> Self {
        Self {
            echo_serial: 0,
            echo_epoch: 0,
            commands_lost: 0,
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
            refused_serial: 0,
            refused_epoch: 0,
            last_serial: 0,
            last_epoch: 0,
            before: Before {
                echo_serial: 0,
                echo_epoch: 0,
                verb: 0,
                state: S0,
                status: Status::NOT_READY,
                error: ErrorCode::NONE,
                running: false,
                state_cycles: 0,
                plan_cycles: 0,
                started_at: None,
                superseded: false,
            },
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
        self.begin_cycle_raw(tick, cmd.serial, cmd.epoch, cmd.verb(), has_plan)
    }

    /// Step 3: the new-command check. `has_plan` says whether `verb` has a
    /// plan (generated code: always, for a verb of its enum; an interpreter:
    /// whether its plan table has the verb).
    ///
    /// A command is new when its serial or its epoch differs from the ones
    /// echoed (a restarted supervisor, or one whose serials wrapped, sends
    /// another epoch). On a new command: echo both, status EXECUTING, error
    /// cleared, the plan of `verb` becomes active in `S0` with both counters
    /// 0. The running command, if any, is superseded at once and never
    /// resumed. Without a plan: status ERROR, error UNKNOWN_COMMAND, no
    /// active plan. A serial more than one past the echoed one in the same
    /// epoch means commands were overwritten unread: they are counted in
    /// [`commands_lost`](Self::commands_lost).
    #[inline]
    pub fn begin_cycle_raw(
        &mut self,
        tick: Tick,
        serial: u32,
        epoch: u32,
        verb: VerbId,
        has_plan: bool,
    ) -> NewCommand {
        self.fired = None;
        self.index_range = false;
        self.now = Some(tick.now);
        // Serial 0 is a buffer never written, whatever its epoch.
        // A refused command stays in the buffer until the next one: it is
        // not new again.
        if serial == 0
            || (serial == self.echo_serial && epoch == self.echo_epoch)
            || (serial == self.refused_serial && epoch == self.refused_epoch)
        {
            self.new_command = false;
            return NewCommand::No;
        }
        self.start_command(serial, epoch, verb, has_plan)
    }

    /// The rest of step 3 when the command is new. Out of line: it runs
    /// once per command, not per cycle, and inlined it was most of every
    /// generated controller's cycle code (issue 30).
    #[cold]
    #[inline(never)]
    fn start_command(
        &mut self,
        serial: u32,
        epoch: u32,
        verb: VerbId,
        has_plan: bool,
    ) -> NewCommand {
        self.before = Before {
            echo_serial: self.echo_serial,
            echo_epoch: self.echo_epoch,
            verb: self.verb,
            state: self.state,
            status: self.status,
            error: self.error,
            running: self.running,
            state_cycles: self.state_cycles,
            plan_cycles: self.plan_cycles,
            started_at: self.started_at,
            superseded: self.running,
        };
        if self.running {
            if let Some(s) = self.verb_stats.get_mut(usize::from(self.verb)) {
                s.superseded = s.superseded.saturating_add(1);
            }
        }
        if self.last_serial != 0 && epoch == self.last_epoch && serial > self.last_serial {
            let skipped = serial - self.last_serial - 1;
            self.commands_lost = self.commands_lost.saturating_add(u64::from(skipped));
        }
        self.last_serial = serial;
        self.last_epoch = epoch;
        self.new_command = true;
        self.echo_serial = serial;
        self.echo_epoch = epoch;
        self.verb = verb;
        self.state = S0;
        self.state_cycles = 0;
        self.plan_cycles = 0;
        self.error = ErrorCode::NONE;
        // `now` is this cycle's start (`begin_cycle_raw` set it).
        self.started_at = self.now;
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

    /// Step 3a: refuse this cycle's new command (its verb's `accept when`
    /// condition is false). Everything step 3 changed is put back — the
    /// running plan keeps its verb, state, counters, status and echo, and
    /// `new_command` is false — and the status buffer names the command as
    /// refused, so that its sender sees `ERROR`/`REFUSED` until it sends
    /// again. Does nothing on a cycle without a new command.
    #[inline]
    pub fn refuse(&mut self) {
        if !self.new_command {
            return;
        }
        let b = self.before;
        self.refused_serial = self.echo_serial;
        self.refused_epoch = self.echo_epoch;
        if b.superseded {
            if let Some(s) = self.verb_stats.get_mut(usize::from(b.verb)) {
                s.superseded = s.superseded.saturating_sub(1);
            }
        }
        self.echo_serial = b.echo_serial;
        self.echo_epoch = b.echo_epoch;
        self.verb = b.verb;
        self.state = b.state;
        self.status = b.status;
        self.error = b.error;
        self.running = b.running;
        self.state_cycles = b.state_cycles;
        self.plan_cycles = b.plan_cycles;
        self.started_at = b.started_at;
        self.new_command = false;
        self.fired = None;
        self.index_range = false;
    }

    /// The serial of the command refused last (0: none).
    pub fn refused_serial(&self) -> u32 {
        self.refused_serial
    }

    /// The epoch of the command refused last (0: none).
    pub fn refused_epoch(&self) -> u32 {
        self.refused_epoch
    }

    /// Whether a plan is active and has not finished: only then are its
    /// rows walked (step 4).
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

    /// The cycle was cut short by a fault (a panicking hook): status ERROR
    /// with `code`, and the active plan (if any) ends as `Error(code)`
    /// would end it. The next command starts normally.
    #[inline]
    pub fn fault(&mut self, code: ErrorCode) {
        self.status = Status::ERROR;
        self.error = code;
        self.finish(false);
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
            echo_epoch: self.echo_epoch,
            status: self.status,
            error: self.error,
            verb: self.verb,
            state: self.state,
            refused_serial: self.refused_serial,
            refused_epoch: self.refused_epoch,
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
    /// The epoch of the command being executed (0: none yet).
    pub fn echo_epoch(&self) -> u32 {
        self.echo_epoch
    }
    /// Commands overwritten in the command buffer before this controller
    /// read them: a supervisor that sends several commands within one of
    /// this controller's cycles loses all but the last (the subordinate sees
    /// the serial jump by more than one within one epoch).
    pub fn commands_lost(&self) -> u64 {
        self.commands_lost
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
mod tests;
