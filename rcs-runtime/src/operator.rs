//! The operator interface (§3.7, Appendix B): command a root controller and
//! read any status buffer. Pause, single-step and go are on
//! [`ExecutiveHandle`](crate::ExecutiveHandle).
//!
//! The operator is the supervisor of a root controller: it holds the single
//! writer of the root's command buffer and follows the same handshake as a
//! controller, so the human never bypasses the chain of command. An
//! [`Operator`] is `Send` and works from any thread.
//!
//! In a distributed plan set the operator may also sit in another process
//! (a console): the bridge of the root's process then shares the root's
//! command writer with the local [`Operator`] and writes the remote
//! operator's commands through it (`BridgeBuilder::import_operator`), so the
//! root still has one writer. Commanding is not the cycle path: the short
//! lock around the write is taken only by the two operators.

use std::marker::PhantomData;
use std::sync::{Arc, Mutex, MutexGuard};

use crate::gm::{ErasedWriter, GlobalMemory, Reader, Stamped};
use crate::handshake::{
    Command, CommandBuffer, ErrorCode, Status, StatusBuffer, SubordinateLink, SubordinateView,
};
use crate::SetupError;

/// The operator's connection to one root controller.
///
/// A thin typed face over [`OperatorCore`]: a plan set has an operator per
/// root, each with its own command type, and all but the typed write of
/// [`command`](Self::command) is the one non-generic core (issue 30: the
/// operators of a hundred roots were a kilobyte of code each).
#[derive(Debug)]
pub struct Operator<C: Command> {
    core: OperatorCore,
    command: PhantomData<fn(C)>,
}

/// What an [`Operator`] holds, whatever the root's command type: the
/// handshake link, the root's command writer (type-erased, shared with a
/// bridge) and a reader of its status.
#[derive(Debug)]
pub(crate) struct OperatorCore {
    link: SubordinateLink,
    command: Arc<Mutex<ErasedWriter>>,
    status: Reader<StatusBuffer>,
    sent: u64,
}

impl OperatorCore {
    /// An operator core through these handles (the writer of the root's
    /// command buffer, erased, and a reader of its status).
    pub(crate) fn new(command: ErasedWriter, status: Reader<StatusBuffer>) -> Self {
        Self {
            link: SubordinateLink::fresh(),
            command: Arc::new(Mutex::new(command)),
            status,
            sent: 0,
        }
    }

    /// The next command's serial, epoch and write stamp, and the command
    /// writer, locked for the typed write.
    fn next_command(&mut self) -> (u32, u32, u64, MutexGuard<'_, ErasedWriter>) {
        let serial = self.link.next_command();
        let epoch = self.link.epoch();
        self.sent = self.sent.wrapping_add(1);
        let writer = self.command.lock().unwrap_or_else(|p| p.into_inner());
        (serial, epoch, self.sent, writer)
    }
}

impl<C: Command> Operator<C> {
    /// Connect to root controller `root` (declares its buffers if needed and
    /// takes the writer of its command buffer).
    pub fn connect(gm: &GlobalMemory, root: &str) -> Result<Self, SetupError> {
        let (command, status) = gm.supervise::<C>(root)?;
        Ok(Self::from_core(OperatorCore::new(
            ErasedWriter::new(command),
            status,
        )))
    }

    /// An operator over this core ([`crate::setup::Ports`]), whose command
    /// writer holds a `CommandBuffer<C>`.
    pub(crate) fn from_core(core: OperatorCore) -> Self {
        Self {
            core,
            command: PhantomData,
        }
    }

    /// Send a new command (next serial, this operator's epoch) at once.
    /// Returns its serial. The write is stamped with the number of commands
    /// the operator has sent.
    pub fn command(&mut self, command: C) -> u32 {
        let (serial, epoch, sent, mut writer) = self.core.next_command();
        // The writer holds a `CommandBuffer<C>` (the core was made for
        // one), so the typed write always lands.
        writer.write(
            CommandBuffer {
                serial,
                epoch,
                command,
            },
            sent,
        );
        serial
    }

    /// The root's status buffer as it is.
    pub fn status(&self) -> Stamped<StatusBuffer> {
        self.core.status.read()
    }

    /// The root's status through the handshake: EXECUTING until the root
    /// echoes the serial of the last command sent.
    pub fn view(&mut self) -> SubordinateView {
        let s = self.core.status.read();
        self.core.link.observe(&s)
    }

    /// `Some((status, error))` once the root finished the last command with
    /// DONE or ERROR; `None` while it runs (or has not picked it up).
    pub fn outcome(&mut self) -> Option<(Status, ErrorCode)> {
        let v = self.view();
        (v.done() || v.error()).then_some((v.status, v.error))
    }

    /// Cycles (reads of [`view`](Self::view)) in which the root showed an
    /// older serial than the last one sent: see
    /// [`SubordinateLink::old_echoes`](crate::SubordinateLink::old_echoes).
    pub fn old_echoes(&self) -> u64 {
        self.core.link.old_echoes()
    }

    /// Serial of the last command sent (0: none).
    pub fn last_serial(&self) -> u32 {
        self.core.link.last_sent()
    }

    /// The root's command writer, shared with the bridge that takes a
    /// remote operator's commands for this root.
    #[cfg(feature = "zenoh")]
    pub(crate) fn shared_writer(&self) -> Arc<Mutex<ErasedWriter>> {
        Arc::clone(&self.core.command)
    }

    /// Start serials after `serial` (e.g. to test wrap-around; the command
    /// after `u32::MAX` takes a fresh epoch).
    pub fn set_last_serial(&mut self, serial: u32) {
        self.core.link.set_last_sent(serial);
    }

    /// The epoch of this operator's commands (a fresh one per connection:
    /// a restarted operator is never answered by its predecessor's status).
    pub fn epoch(&self) -> u32 {
        self.core.link.epoch()
    }
}

/// Read controller `ctrl`'s status buffer once (setup-time lookup; keep a
/// [`Reader`] from [`GlobalMemory::status_reader`] to poll repeatedly).
pub fn read_status(gm: &GlobalMemory, ctrl: &str) -> Result<Stamped<StatusBuffer>, SetupError> {
    Ok(gm.status_reader(ctrl)?.read())
}
