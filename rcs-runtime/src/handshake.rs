//! Command and status buffers and the supervisor/subordinate handshake
//! (§5.5 of the methodology; docs/semantics.md "Global Memory and its buffers" and step 2).
//!
//! A supervisor commands a subordinate by writing its command buffer with a
//! fresh serial number and its link's epoch ([`crate::epoch`]); the
//! subordinate echoes both of the command it works on in its status buffer.
//! The supervisor trusts a status only when serial and epoch both match the
//! ones it last sent: otherwise the subordinate has not picked the command up
//! yet (or answers a command of an earlier incarnation of the supervisor, or
//! of the serials before a wrap), and the supervisor sees EXECUTING. The
//! generation stamps of Global Memory give the watchdog count
//! `stale_cycles`.
//!
//! The ids here are small plain integers so that both generated code (typed
//! enums converted to ids) and an interpreter (ids known at run time) use the
//! same types.

use serde::{Deserialize, Serialize};

use crate::epoch::fresh_epoch;
use crate::gm::{GlobalMemory, Reader, Stamped, Writer};
use crate::seqlock::Staged;
use crate::SetupError;

/// A command verb of one controller, by its position in the declaration.
pub type VerbId = u16;
/// A state of one plan; `S0` is 0.
pub type StateId = u16;
/// A row of one plan, by its 0-based position (precedence order).
pub type RowId = u16;

/// The state every plan starts in after a new command.
pub const S0: StateId = 0;

/// A status code: 0..=3 are the built-in statuses, custom statuses (declared
/// with `status NAME` in a controller) follow from 4.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(transparent)]
pub struct Status(pub u16);

impl Status {
    /// No command has been received yet.
    pub const NOT_READY: Status = Status(0);
    /// Working on the command whose serial is echoed.
    pub const EXECUTING: Status = Status(1);
    /// The command's plan ended with `Done`.
    pub const DONE: Status = Status(2);
    /// The command's plan ended with `Error(CODE)`, or the verb had no plan.
    pub const ERROR: Status = Status(3);
    /// The code of the first custom status.
    pub const FIRST_CUSTOM: u16 = 4;

    /// The `index`-th custom status of a controller (0-based).
    pub const fn custom(index: u16) -> Status {
        Status(Self::FIRST_CUSTOM.saturating_add(index))
    }

    /// The built-in name, or `None` for a custom status.
    pub const fn builtin_name(self) -> Option<&'static str> {
        match self.0 {
            0 => Some("NOT_READY"),
            1 => Some("EXECUTING"),
            2 => Some("DONE"),
            3 => Some("ERROR"),
            _ => None,
        }
    }
}

/// An error code: 0 is "no error", 1 is the runtime's `UNKNOWN_COMMAND`,
/// error codes declared by a controller follow from 2; `u16::MAX` is the
/// runtime's `INDEX_RANGE` and `u16::MAX - 1` its `HOOK_PANIC`.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(transparent)]
pub struct ErrorCode(pub u16);

impl ErrorCode {
    /// No error.
    pub const NONE: ErrorCode = ErrorCode(0);
    /// A command verb for which the controller has no plan.
    pub const UNKNOWN_COMMAND: ErrorCode = ErrorCode(1);
    /// An array indexed by a run-time value outside its bounds: the plan
    /// ends with this built-in error. The last code, so that the codes of
    /// declared errors (from [`FIRST_CUSTOM`](Self::FIRST_CUSTOM)) keep
    /// their numbers.
    pub const INDEX_RANGE: ErrorCode = ErrorCode(u16::MAX);
    /// A hook (or anything else in the controller's cycle) panicked: the
    /// executive caught the panic and ended the plan with this built-in
    /// error ([`Controller::fault`](crate::Controller::fault)). Next to
    /// [`INDEX_RANGE`](Self::INDEX_RANGE) at the top, so that declared
    /// codes keep their numbers.
    pub const HOOK_PANIC: ErrorCode = ErrorCode(u16::MAX - 1);
    /// A command refused by its verb's `accept when` condition
    /// (docs/semantics.md step 3a). Never in a controller's own status: a
    /// supervisor's handshake view shows it for the serial named in
    /// [`StatusBuffer::refused_serial`].
    pub const REFUSED: ErrorCode = ErrorCode(u16::MAX - 2);
    /// The code of the first declared error.
    pub const FIRST_CUSTOM: u16 = 2;

    /// The `index`-th declared error code of a controller (0-based).
    pub const fn custom(index: u16) -> ErrorCode {
        ErrorCode(Self::FIRST_CUSTOM.saturating_add(index))
    }

    /// Whether this is [`ErrorCode::NONE`].
    pub const fn is_none(self) -> bool {
        self.0 == 0
    }

    /// Whether this is one of the runtime's built-in error codes (which
    /// any controller can end with, whatever it declares).
    pub const fn is_builtin(self) -> bool {
        self.0 == Self::UNKNOWN_COMMAND.0
            || self.0 == Self::INDEX_RANGE.0
            || self.0 == Self::HOOK_PANIC.0
            || self.0 == Self::REFUSED.0
    }
}

/// The payload of a command buffer: a generated command enum (verb and
/// parameters) or anything else that knows its verb id. Its `Default` is the
/// value of a never-written buffer.
pub trait Command: Copy + Default + Send + 'static {
    /// The verb of this command.
    fn verb(&self) -> VerbId;
}

/// A bare verb id is a command without parameters (handy for tests and for
/// an interpreter that keeps parameters elsewhere).
impl Command for VerbId {
    fn verb(&self) -> VerbId {
        *self
    }
}

/// A controller's command buffer: `{serial, epoch, verb, params}`, with verb
/// and parameters in `command`. Serial 0 means "no command yet".
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct CommandBuffer<C> {
    /// Serial number of this command; a new serial (or epoch) is a new command.
    pub serial: u32,
    /// The sending link's epoch ([`crate::epoch`]): with the serial, the
    /// command's identity across supervisor restarts and serial wrap-around.
    pub epoch: u32,
    /// The verb and its parameters.
    pub command: C,
}

impl<C: Command> CommandBuffer<C> {
    /// The verb of the command.
    pub fn verb(&self) -> VerbId {
        self.command.verb()
    }
}

/// A controller's status buffer, plain data. All zeros before the first
/// write: `{echo_serial: 0, echo_epoch: 0, NOT_READY, no error}`.
///
/// A refused command (docs/semantics.md step 3a) is not echoed: the echo
/// stays on the command whose plan goes on, and `refused_serial` /
/// `refused_epoch` name the command refused last, so that its sender sees
/// `ERROR`/`REFUSED` until it sends again while the running plan's reports
/// never answer it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct StatusBuffer {
    /// Serial of the command this status is about.
    pub echo_serial: u32,
    /// Epoch of the command this status is about.
    pub echo_epoch: u32,
    /// The status.
    pub status: Status,
    /// The error code when `status` is ERROR, else NONE.
    pub error: ErrorCode,
    /// The verb of the echoed command.
    pub verb: VerbId,
    /// The current state of its plan.
    pub state: StateId,
    /// Serial of the command refused last (0: none).
    pub refused_serial: u32,
    /// Epoch of the command refused last.
    pub refused_epoch: u32,
}

impl StatusBuffer {
    /// Whether every field is one a controller with `statuses` custom
    /// statuses, `errors` declared error codes, `verbs` verbs and plans of
    /// at most `states` states can write: `Err` names the field that is
    /// not. The bridge refuses an imported status that fails this (a forged
    /// or corrupt sample), so a supervisor never sees a status that does
    /// not exist.
    pub fn check_range(
        &self,
        statuses: u16,
        errors: u16,
        verbs: u16,
        states: u16,
    ) -> Result<(), &'static str> {
        if self.status.0 >= Status::FIRST_CUSTOM.saturating_add(statuses) {
            return Err("status");
        }
        let e = self.error;
        let declared =
            e.0 >= ErrorCode::FIRST_CUSTOM && e.0 < ErrorCode::FIRST_CUSTOM.saturating_add(errors);
        if !(e.is_none() || e.is_builtin() || declared) {
            return Err("error code");
        }
        if self.verb >= verbs.max(1) {
            return Err("verb");
        }
        if self.state >= states.max(1) {
            return Err("state");
        }
        Ok(())
    }
}

/// The serial after `serial`: one more, wrapping from `u32::MAX` to 1, never 0.
#[inline]
pub const fn next_serial(serial: u32) -> u32 {
    match serial.wrapping_add(1) {
        0 => 1,
        n => n,
    }
}

/// What a supervisor sees of one subordinate in one cycle (step 2).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SubordinateView {
    /// The status through the handshake: EXECUTING while the echo differs
    /// from the serial last sent.
    pub status: Status,
    /// The error code, only when `status` is ERROR through the handshake.
    pub error: ErrorCode,
    /// Cycles of the supervisor since the subordinate last wrote its status.
    pub stale_cycles: u32,
    /// The buffer exactly as read.
    pub raw: StatusBuffer,
}

impl SubordinateView {
    /// `X.done`.
    pub fn done(&self) -> bool {
        self.status == Status::DONE
    }
    /// `X.executing`.
    pub fn executing(&self) -> bool {
        self.status == Status::EXECUTING
    }
    /// `X.error`.
    pub fn error(&self) -> bool {
        self.status == Status::ERROR
    }
}

/// A supervisor's bookkeeping for one subordinate: the serial and epoch it
/// last sent, the last status generation it saw and the resulting view.
/// Works on plain values, so it serves generated code and interpreters alike.
#[derive(Debug, Clone, Copy)]
pub struct SubordinateLink {
    last_sent: u32,
    /// The epoch of the commands sent (0: not drawn yet).
    epoch: u32,
    seen_generation: u64,
    view: SubordinateView,
    old_echoes: u64,
}

impl Default for SubordinateLink {
    fn default() -> Self {
        Self::new()
    }
}

impl SubordinateLink {
    /// A link that has sent nothing yet; its epoch is drawn
    /// ([`fresh_epoch`]) when it sends its first command.
    pub const fn new() -> Self {
        Self::with_epoch(0)
    }

    /// A link that has sent nothing yet, with its epoch drawn now (keeps the
    /// first draw of the process off the cycle path).
    pub fn fresh() -> Self {
        Self::with_epoch(fresh_epoch())
    }

    /// A link whose commands carry `epoch` (0: draw one at the first
    /// command) until its serials wrap. For tests, and for whoever keeps
    /// epochs itself.
    pub const fn with_epoch(epoch: u32) -> Self {
        Self {
            last_sent: 0,
            epoch,
            seen_generation: 0,
            view: SubordinateView {
                status: Status::NOT_READY,
                error: ErrorCode::NONE,
                stale_cycles: 0,
                raw: StatusBuffer {
                    echo_serial: 0,
                    echo_epoch: 0,
                    status: Status::NOT_READY,
                    error: ErrorCode::NONE,
                    verb: 0,
                    state: 0,
                    refused_serial: 0,
                    refused_epoch: 0,
                },
            },
            old_echoes: 0,
        }
    }

    /// Step 2 for this subordinate: take this cycle's read of its status
    /// buffer (call once per cycle of the supervisor) and compute the view.
    ///
    /// `stale_cycles` is 0 when the read shows a generation not seen before
    /// and one more than last cycle otherwise. A buffer that was never written
    /// (generation 0) counts as not new, so a subordinate that never spoke
    /// is stale from the first cycle.
    #[inline]
    pub fn observe(&mut self, read: &Stamped<StatusBuffer>) -> SubordinateView {
        let stale = if read.generation != self.seen_generation {
            self.seen_generation = read.generation;
            0
        } else {
            self.view.stale_cycles.saturating_add(1)
        };
        let raw = read.value;
        // Nothing sent: only "no command" (serial 0, whatever epoch) is ours.
        let ours = raw.echo_serial == self.last_sent
            && (self.last_sent == 0 || raw.echo_epoch == self.epoch);
        let refused = self.last_sent != 0
            && raw.refused_serial == self.last_sent
            && raw.refused_epoch == self.epoch;
        let (status, error) = if refused {
            // Step 3a: the latest command was refused; the plan that goes on
            // (whatever it echoes and reports) never answers it.
            (Status::ERROR, ErrorCode::REFUSED)
        } else if ours {
            (raw.status, raw.error)
        } else {
            // A status for an older command (of this incarnation, an earlier
            // one, or before a wrap) never counts for the newer one.
            self.old_echoes = self.old_echoes.saturating_add(1);
            (Status::EXECUTING, ErrorCode::NONE)
        };
        // Field by field: a whole-struct store is built on the stack with
        // narrow stores and copied with wide loads, which stall the CPU
        // (see `seqlock`'s module docs).
        self.view.status = status;
        self.view.error = error;
        self.view.stale_cycles = stale;
        self.view.raw = raw;
        SubordinateView {
            status,
            error,
            stale_cycles: stale,
            raw,
        }
    }

    /// The view computed by the last [`observe`](Self::observe).
    #[inline]
    pub fn view(&self) -> SubordinateView {
        self.view
    }

    /// Cycles whose read showed an older serial than the last one sent (the
    /// supervisor saw EXECUTING in their place). A cycle or two after each
    /// command is the subordinate picking it up; a count that grows every
    /// cycle is a subordinate that answers but does not take the commands
    /// (a stale echo), which `stale_cycles` cannot show since it keeps
    /// writing.
    #[inline]
    pub fn old_echoes(&self) -> u64 {
        self.old_echoes
    }

    /// Allocate the serial of a new command to this subordinate and remember
    /// it as the last one sent; send it with [`epoch`](Self::epoch). When
    /// the serials wrap (`u32::MAX` → 1) the link takes a fresh epoch, so a
    /// wrapped serial never names an older command. The view of this cycle
    /// is not changed (the conditions of a cycle are evaluated before its
    /// jobs run).
    #[inline]
    pub fn next_command(&mut self) -> u32 {
        let serial = next_serial(self.last_sent);
        if self.epoch == 0 || serial < self.last_sent {
            self.epoch = fresh_epoch();
        }
        self.last_sent = serial;
        serial
    }

    /// The epoch of the commands this link sends (0: none drawn yet).
    #[inline]
    pub fn epoch(&self) -> u32 {
        self.epoch
    }

    /// The identity of the last command sent as a subordinate echoes it:
    /// a status buffer with this serial and epoch answers it.
    #[inline]
    pub fn echo_of_last(&self) -> (u32, u32) {
        (self.last_sent, self.epoch)
    }

    /// The serial of the last command sent (0: none).
    #[inline]
    pub fn last_sent(&self) -> u32 {
        self.last_sent
    }

    /// Start the serials after `serial` (e.g. to test wrap-around). The
    /// epoch stays; the next command after `u32::MAX` takes a fresh one.
    pub fn set_last_sent(&mut self, serial: u32) {
        self.last_sent = serial;
    }
}

/// Everything a supervisor needs for one subordinate: the link, a reader of
/// its status buffer and the writer of its command buffer.
///
/// Per cycle: [`read`](Self::read) in pre-processing, [`view`](Self::view) in
/// the decision, [`send`](Self::send) in a job, [`flush`](Self::flush) in
/// post-processing.
#[derive(Debug)]
pub struct Subordinate<C: Command> {
    link: SubordinateLink,
    status: Reader<StatusBuffer>,
    command: Writer<CommandBuffer<C>>,
    /// The command of the last `send`, kept as words so that `flush`
    /// reads it back without a store-forwarding stall.
    out: Staged<CommandBuffer<C>>,
    dirty: bool,
}

impl<C: Command> Subordinate<C> {
    /// Connect to subordinate `ctrl` in `gm` (its buffers are declared if
    /// needed; taking its command writer makes this the only supervisor).
    pub fn connect(gm: &GlobalMemory, ctrl: &str) -> Result<Self, SetupError> {
        gm.supervise::<C>(ctrl).map(Self::from_parts)
    }

    /// A subordinate through these handles ([`crate::setup::Ports`]).
    pub(crate) fn from_parts(
        (command, status): (Writer<CommandBuffer<C>>, Reader<StatusBuffer>),
    ) -> Self {
        Self {
            link: SubordinateLink::fresh(),
            status,
            command,
            out: Staged::new(CommandBuffer::default()),
            dirty: false,
        }
    }

    /// Step 1 and 2: read the status buffer once and compute the view.
    #[inline]
    pub fn read(&mut self) -> SubordinateView {
        let s = self.status.read();
        self.link.observe(&s)
    }

    /// This cycle's view (from the last [`read`](Self::read)).
    #[inline]
    pub fn view(&self) -> SubordinateView {
        self.link.view()
    }

    /// `X <- VERB(...)`: a new command with the next serial, written to
    /// Global Memory at the next [`flush`](Self::flush). Returns the serial.
    #[inline]
    pub fn send(&mut self, command: C) -> u32 {
        let serial = self.link.next_command();
        let epoch = self.link.epoch();
        self.out.set(CommandBuffer {
            serial,
            epoch,
            command,
        });
        self.dirty = true;
        serial
    }

    /// Step 5: write the command buffer if a command was sent since the last
    /// flush. Returns whether it wrote.
    #[inline]
    pub fn flush(&mut self, cycle: u64) -> bool {
        if self.dirty {
            self.command.write(self.out.get(), cycle);
            self.dirty = false;
            true
        } else {
            false
        }
    }

    /// The command most recently sent (serial 0: none).
    pub fn last_command(&self) -> CommandBuffer<C> {
        self.out.get()
    }

    /// The underlying link.
    pub fn link(&self) -> &SubordinateLink {
        &self.link
    }

    /// The underlying link, mutably.
    pub fn link_mut(&mut self) -> &mut SubordinateLink {
        &mut self.link
    }
}

#[cfg(test)]
mod tests;
