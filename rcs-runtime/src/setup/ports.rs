//! [`Ports`]: how a generated controller (and [`Setup`](super::Setup))
//! connects to Global Memory — its command and status buffers, the buffers
//! it reads and writes, its subordinates — with one exit at the end instead
//! of a `?` after every handle.
//!
//! Each step that fails is recorded and answered with a stand-in handle (a
//! cell of the right type that no Global Memory knows), so the steps run
//! straight through and [`Ports::finish`] returns every error met. Every
//! typed method is a thin wrapper over a type-erased core of
//! [`crate::gm`]: what a plan set instantiates per controller is a
//! downcast, not a copy of the lookups and their error paths (issue 30).

use std::sync::Arc;

use crate::error::SetupError;
use crate::gm::{
    command_buffer_name, status_buffer_name, AnyCell, BufferData, ErasedWriter, GlobalMemory,
    Reader, TypeKey, Writer,
};
use crate::handshake::{Command, CommandBuffer, StatusBuffer, Subordinate};
use crate::operator::{Operator, OperatorCore};

/// Global Memory being connected to, and the errors met so far.
#[derive(Debug, Clone)]
pub struct Ports {
    gm: GlobalMemory,
    errors: Vec<SetupError>,
}

impl Ports {
    /// Connect to `gm` (a clone of the handle: they share the buffers).
    pub fn new(gm: &GlobalMemory) -> Self {
        Self {
            gm: gm.clone(),
            errors: Vec::new(),
        }
    }

    /// The Global Memory connected to.
    pub fn gm(&self) -> &GlobalMemory {
        &self.gm
    }

    /// The errors met so far, in the order they happened.
    pub fn errors(&self) -> &[SetupError] {
        &self.errors
    }

    /// Record the error of a step, if it failed.
    pub fn record(&mut self, step: Result<(), SetupError>) {
        if let Err(e) = step {
            self.errors.push(e);
        }
    }

    /// Declare buffer `name` holding a `T`.
    pub fn declare<T: BufferData>(&mut self, name: &str) {
        let declared = self.gm.declare::<T>(name);
        self.record(declared);
    }

    /// Declare controller `ctrl`'s command and status buffers.
    pub fn declare_controller<C: Command>(&mut self, ctrl: &str) {
        self.declare_controller_erased(ctrl, TypeKey::of::<CommandBuffer<C>>());
    }

    /// The writer of buffer `name` (a stand-in if that fails).
    pub fn writer<T: BufferData>(&mut self, name: &str) -> Writer<T> {
        Writer::from_parts(self.handle(name, TypeKey::of::<T>(), true))
    }

    /// A reader of buffer `name` (a stand-in if that fails).
    pub fn reader<T: BufferData>(&mut self, name: &str) -> Reader<T> {
        Reader::from_parts(self.handle(name, TypeKey::of::<T>(), false))
    }

    /// A reader of controller `ctrl`'s command buffer (the controller's own).
    pub fn command_reader<C: Command>(&mut self, ctrl: &str) -> Reader<CommandBuffer<C>> {
        let key = TypeKey::of::<CommandBuffer<C>>();
        Reader::from_parts(self.command_handle(ctrl, key))
    }

    /// The writer of controller `ctrl`'s status buffer (the controller's own).
    pub fn status_writer(&mut self, ctrl: &str) -> Writer<StatusBuffer> {
        self.writer(&status_buffer_name(ctrl))
    }

    /// Subordinate `ctrl`: its buffers declared, the writer of its command
    /// buffer taken (this is its one supervisor), a reader of its status.
    pub fn subordinate<C: Command>(&mut self, ctrl: &str) -> Subordinate<C> {
        let (command, status) = self.supervise(ctrl, TypeKey::of::<CommandBuffer<C>>());
        Subordinate::from_parts((Writer::from_parts(command), status))
    }

    /// The operator of root controller `root`: as a
    /// [`subordinate`](Self::subordinate), for the human at the top.
    pub fn operator<C: Command>(&mut self, root: &str) -> Operator<C> {
        Operator::from_core(self.operator_core(
            root,
            TypeKey::of::<CommandBuffer<C>>(),
            ErasedWriter::of::<CommandBuffer<C>>,
        ))
    }

    /// `Ok` if every step succeeded; else the one error, or all of them
    /// ([`SetupError::Several`]).
    pub fn finish(self) -> Result<(), SetupError> {
        let mut errors = self.errors;
        match errors.len() {
            0 => Ok(()),
            1 => Err(errors.remove(0)),
            _ => Err(SetupError::Several(errors)),
        }
    }

    // The type-erased cores of the typed calls above.

    fn declare_controller_erased(&mut self, ctrl: &str, command: TypeKey) {
        let declared = self.gm.declare_controller_erased(ctrl, command);
        self.record(declared);
    }

    fn handle(&mut self, name: &str, key: TypeKey, writer: bool) -> (AnyCell, Arc<str>) {
        self.gm
            .handle_or_stand_in(name, key, writer, &mut self.errors)
    }

    fn command_handle(&mut self, ctrl: &str, key: TypeKey) -> (AnyCell, Arc<str>) {
        self.handle(&command_buffer_name(ctrl), key, false)
    }

    /// The core of [`operator`](Self::operator): all but the typed writer,
    /// which `erase` makes from the command buffer's cell.
    fn operator_core(
        &mut self,
        root: &str,
        command: TypeKey,
        erase: fn((AnyCell, Arc<str>)) -> ErasedWriter,
    ) -> OperatorCore {
        let (command, status) = self.supervise(root, command);
        OperatorCore::new(erase(command), status)
    }

    /// What a supervisor (or the operator) holds of controller `ctrl`: the
    /// writer's cell of its command buffer and a reader of its status.
    fn supervise(
        &mut self,
        ctrl: &str,
        command: TypeKey,
    ) -> ((AnyCell, Arc<str>), Reader<StatusBuffer>) {
        self.declare_controller_erased(ctrl, command);
        let status = self.reader::<StatusBuffer>(&status_buffer_name(ctrl));
        (
            self.handle(&command_buffer_name(ctrl), command, true),
            status,
        )
    }
}
