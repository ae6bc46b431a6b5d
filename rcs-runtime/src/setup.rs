//! Setting a system up: what generated `System::new` (and `System::process`)
//! call, instead of one `?` per buffer, handle and controller.
//!
//! Generated setup used to be one function per plan set with a `?` exit
//! after every step, each exit dropping everything built before it: code
//! that grew with the square of the number of controllers and kept LLVM
//! busy for minutes at a few hundred (issue 30). Here setup is a walk over
//! a static table of buffers ([`BufferDecl`]) and a straight line of calls
//! that never return early: each step that fails is recorded and answered
//! with a stand-in (a handle to a cell no Global Memory knows), and
//! [`Setup::finish`] returns every error at once, so nothing half-built
//! ever runs. The typed calls are thin wrappers over type-erased cores in
//! [`crate::gm`].

use std::time::Duration;

use crate::error::SetupError;
use crate::exec::{Controller, Executive, ExecutiveConfig};
use crate::gm::{BufferData, GlobalMemory, Reader, Writer};
use crate::handshake::Command;
use crate::operator::Operator;

mod ports;
pub use ports::Ports;

/// One Global Memory buffer of a plan set: its name and how to declare it
/// with its type. Generated code keeps a static table of them.
#[derive(Clone, Copy)]
pub struct BufferDecl {
    name: &'static str,
    declare: fn(&GlobalMemory, &str) -> Result<(), SetupError>,
}

impl BufferDecl {
    /// Buffer `name`, holding a `T`.
    pub const fn of<T: BufferData>(name: &'static str) -> Self {
        Self {
            name,
            declare: GlobalMemory::declare::<T>,
        }
    }

    /// The buffer's name in Global Memory.
    pub const fn name(&self) -> &'static str {
        self.name
    }
}

impl std::fmt::Debug for BufferDecl {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("BufferDecl").field(&self.name).finish()
    }
}

/// A system being set up: its Global Memory, its executives, and the
/// errors met so far.
#[derive(Debug)]
pub struct Setup {
    /// Global Memory and the errors met so far.
    ports: Ports,
    /// `None` where the executive could not be made (its error recorded).
    executives: Vec<Option<Executive>>,
}

impl Setup {
    /// A fresh Global Memory with every buffer of `buffers` declared.
    pub fn new(buffers: &[BufferDecl]) -> Self {
        let mut ports = Ports::new(&GlobalMemory::new());
        for b in buffers {
            let declared = (b.declare)(ports.gm(), b.name);
            ports.record(declared);
        }
        Self {
            ports,
            executives: Vec::new(),
        }
    }

    /// The Global Memory being set up.
    pub fn gm(&self) -> &GlobalMemory {
        self.ports.gm()
    }

    /// The errors met so far, in the order they happened.
    pub fn errors(&self) -> &[SetupError] {
        self.ports.errors()
    }

    /// Record the error of a step, if it failed.
    pub fn record(&mut self, step: Result<(), SetupError>) {
        self.ports.record(step);
    }

    /// A new executive `name` running every `period_ns` nanoseconds; the
    /// index to [`add`](Self::add) its controllers with.
    pub fn executive(&mut self, name: &str, period_ns: u64) -> usize {
        let made = Executive::new(ExecutiveConfig::new(name, Duration::from_nanos(period_ns)));
        let exec = match made {
            Ok(exec) => Some(exec),
            Err(e) => {
                self.record(Err(e));
                None
            }
        };
        self.executives.push(exec);
        self.executives.len() - 1
    }

    /// Schedule a controller, as made by its setup function, last on
    /// executive `exec` (its cycle order is the order of the calls).
    pub fn add(&mut self, exec: usize, made: Result<Box<dyn Controller>, SetupError>) {
        let added = match (made, self.executives.get_mut(exec)) {
            (Ok(ctrl), Some(Some(exec))) => exec.add(ctrl),
            (Err(e), _) => Err(e),
            // The executive's own error is recorded already.
            (Ok(_), Some(None)) => Ok(()),
            (Ok(ctrl), None) => Err(SetupError::UnknownExecutive(ctrl.name().to_owned())),
        };
        self.record(added);
    }

    /// Declare buffer `name` holding a `T` (beyond the table of
    /// [`new`](Self::new)).
    pub fn declare<T: BufferData>(&mut self, name: &str) {
        self.ports.declare::<T>(name);
    }

    /// Declare controller `ctrl`'s command and status buffers.
    pub fn declare_controller<C: Command>(&mut self, ctrl: &str) {
        self.ports.declare_controller::<C>(ctrl);
    }

    /// The writer of buffer `name` (a stand-in if that fails: the error is
    /// recorded and [`finish`](Self::finish) returns it).
    pub fn writer<T: BufferData>(&mut self, name: &str) -> Writer<T> {
        self.ports.writer(name)
    }

    /// A reader of buffer `name` (a stand-in if that fails, as
    /// [`writer`](Self::writer)).
    pub fn reader<T: BufferData>(&mut self, name: &str) -> Reader<T> {
        self.ports.reader(name)
    }

    /// The operator of root controller `root` (stand-ins if that fails, as
    /// [`writer`](Self::writer)): declares the root's buffers, takes the
    /// writer of its command buffer and a reader of its status.
    pub fn operator<C: Command>(&mut self, root: &str) -> Operator<C> {
        self.ports.operator(root)
    }

    /// Global Memory and the executives, in the order they were made, if
    /// every step succeeded; else the one error, or all of them
    /// ([`SetupError::Several`]).
    pub fn finish(self) -> Result<(GlobalMemory, Vec<Executive>), SetupError> {
        let gm = self.ports.gm().clone();
        self.ports.finish()?;
        Ok((gm, self.executives.into_iter().flatten().collect()))
    }
}

#[cfg(test)]
mod tests;
