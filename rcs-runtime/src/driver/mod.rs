//! Driving one controller alone, by name, from outside: the interface a
//! scenario runner or a differential test needs.
//!
//! A [`Driven`] controller plays against a world the caller scripts: the
//! caller writes its supervisor's command, its `reads` buffers, the results
//! its hooks return and its subordinates' status buffers, runs one cycle,
//! and gets back a [`Record`] of what the cycle did. rcsc has two backends
//! behind this one trait — the reference interpreter (`rcs-dsl`) and the
//! generated code (`rcs-codegen` emits a `Driver` per controller when asked
//! to, e.g. `Config::driver(true)`) — so a scenario means the same on both
//! and their traces can be compared cycle by cycle.
//!
//! Values cross this interface as dynamic [`Value`]s, which allocate: this
//! is test tooling, never the cycle path of a running system.
//!
//! This module holds what one driven controller is ([`Driven`],
//! [`DrivenCommand`]) and what a cycle gives back ([`Record`]); beside it,
//! `value` the dynamic values and their conversions, `error` what a driven
//! controller refuses, `protocol` the JSON-lines protocol that drives a
//! controller in another process and its server, `remote` its client, and
//! [`system`] several controllers driven together.

mod error;
mod protocol;
mod remote;
pub mod system;
mod value;

pub use error::{arg, arity, typed, unknown, DriveError};
pub use protocol::{serve, serve_systems, Factory, Request, Response};
pub use remote::Remote;
pub use system::{DrivenSystem, RemoteSystem, SystemFactory};
pub use value::{FromValue, ToValue, Value};

use crate::handshake::{ErrorCode, RowId, StateId, Status, StatusBuffer, VerbId};
use serde::{Deserialize, Serialize};

/// A controller's command enum seen by name: built from a verb name and
/// arguments, taken apart into a verb id and arguments.
pub trait DrivenCommand: Sized {
    /// The command `verb(args…)`; an error names what does not fit.
    fn from_parts(verb: &str, args: &[Value]) -> Result<Self, DriveError>;
    /// The verb id and the arguments in declaration order.
    fn parts(&self) -> (VerbId, Vec<Value>);
}

/// A command a cycle sent to a subordinate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sent {
    /// The subordinate, by its position in the controller's `subordinates`.
    pub sub: u16,
    /// The verb, by its position in the subordinate's commands.
    pub verb: VerbId,
    /// The arguments in declaration order.
    pub args: Vec<Value>,
    /// The serial it was sent with.
    pub serial: u32,
}

/// What one cycle did and left behind.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// The cycle (0 first).
    pub cycle: u64,
    /// The verb of the command being (or last) executed; `None` before the first.
    pub verb: Option<VerbId>,
    /// The row that fired, if one did.
    pub fired: Option<RowId>,
    /// The plan's state after the cycle.
    pub state: StateId,
    /// The status after the cycle.
    pub status: Status,
    /// The error code after the cycle.
    pub error: ErrorCode,
    /// The serial of the command the status is about (0: none yet).
    #[serde(default)]
    pub echo_serial: u32,
    /// The serial of the command refused last (0: none), docs/semantics.md
    /// step 3a: its sender sees `ERROR`/`REFUSED` for it.
    #[serde(default)]
    pub refused_serial: u32,
    /// Commands sent to subordinates this cycle, in subordinate order.
    pub sent: Vec<Sent>,
    /// The controller's vars after the cycle, in declaration order.
    pub vars: Vec<Value>,
    /// Its `writes` buffers after the cycle, in declaration order.
    pub writes: Vec<Value>,
    /// How many times each hook was called this cycle, in declaration
    /// order (a condition's call counts once however many rows ask).
    #[serde(default)]
    pub hook_calls: Vec<u32>,
    /// Each hook call this cycle that ran (not one answered from the
    /// cycle's condition cache): the hook's index and its arguments, in
    /// call order.
    #[serde(default)]
    pub hook_args: Vec<(u16, Vec<Value>)>,
}

/// One controller driven alone. Names are as written in the plans.
pub trait Driven {
    /// The controller's name.
    fn name(&self) -> &str;
    /// The supervisor writes a new command (the next serial), read at the
    /// next cycle. Returns the serial.
    fn command(&mut self, verb: &str, args: &[Value]) -> Result<u32, DriveError>;
    /// The world writes `reads` buffer `buffer`; the next cycle reads it.
    fn set_read(&mut self, buffer: &str, value: &Value) -> Result<(), DriveError>;
    /// From now on hook `hook` returns `value` (until set again). Before it
    /// is set a hook returns its type's zero.
    fn set_hook(&mut self, hook: &str, value: &Value) -> Result<(), DriveError>;
    /// Var `var` holds `value` from now on (until the plan assigns it):
    /// how a scenario's `initial:` sets the world model.
    fn set_var(&mut self, var: &str, value: &Value) -> Result<(), DriveError>;
    /// The controller's own `writes` buffer `buffer` holds `value` from now
    /// on (until a job writes it).
    fn set_write(&mut self, buffer: &str, value: &Value) -> Result<(), DriveError>;
    /// Subordinate `sub` writes its status buffer (a new generation) before
    /// the next cycle. A subordinate not written is silent: its status
    /// goes stale. An `echo_epoch` of 0 stands for the epoch of this
    /// controller's commands to `sub`, which the driver fills in: scenarios
    /// name serials only (the epoch is a detail of the handshake); a
    /// nonzero epoch is written as given.
    fn write_sub_status(&mut self, sub: &str, status: StatusBuffer) -> Result<(), DriveError>;
    /// The serial of the last command this controller sent `sub` (0: none).
    fn last_sent(&mut self, sub: &str) -> Result<u32, DriveError>;
    /// One control cycle.
    fn cycle(&mut self) -> Record;
    /// Subordinate `sub` publishes `value` for its status field `field`
    /// (`status NAME: TYPE`), read from the next cycle on as `sub.field`
    /// whatever serial its status buffer echoes. A controller whose
    /// subordinates have no status fields refuses every name. An unknown
    /// subordinate or field is `unknown(self, "status field", "sub.field")`.
    fn write_sub_field(&mut self, sub: &str, field: &str, value: &Value) -> Result<(), DriveError> {
        let _ = value;
        Err(unknown(
            self.name(),
            "status field",
            &format!("{sub}.{field}"),
        ))
    }
}
