//! Driving a whole plan set, or a subtree of it, from outside: the
//! interface a *system* scenario runs on (docs/scenarios.md, "System
//! scenarios"). Where [`Driven`](super::Driven) plays everything around one
//! controller, a [`DrivenSystem`] runs several controllers that command and
//! answer each other for real through Global Memory, and the caller plays
//! only the environment: the external `reads` buffers (those no controller
//! of the run writes), the hooks, and the supervisor of each root of the run.
//!
//! The caller also owns the schedule: it asks for one cycle of one CPU at a
//! time ([`DrivenSystem::run_cpu`]), so that the interpreter and the
//! generated code run a multi-rate set in exactly the same interleaving
//! (`rcs_dsl::scenario` computes it from the schedule's periods).
//!
//! Like the rest of [`super`], this allocates: test tooling, never the
//! cycle path of a running system.

use super::{DriveError, Record, Value};

/// Several controllers of one plan set, on their real schedule. Names are
/// as written in the plans.
pub trait DrivenSystem {
    /// The supervisor of `root` (a controller of the run whose supervisor
    /// is not in the run) writes a new command, read at `root`'s next
    /// cycle. Returns the serial.
    fn command(&mut self, root: &str, verb: &str, args: &[Value]) -> Result<u32, DriveError>;
    /// The world writes external buffer `buffer` (one no controller of the
    /// run writes): a new generation, read at each reader's next cycle.
    fn set_read(&mut self, buffer: &str, value: &Value) -> Result<(), DriveError>;
    /// From now on hook `hook` of `controller` returns `value`.
    fn set_hook(&mut self, controller: &str, hook: &str, value: &Value) -> Result<(), DriveError>;
    /// Var `var` of `controller` holds `value` from now on (until a plan
    /// assigns it): a scenario's `initial: vars`.
    fn set_var(&mut self, controller: &str, var: &str, value: &Value) -> Result<(), DriveError>;
    /// One cycle of CPU `cpu` (its name in the schedule): each controller
    /// of the run on it runs once, in the CPU's order, each reading what
    /// the others last wrote. Returns each one's name and record, in that
    /// order (`sent` indexes the controller's own `subordinates`).
    fn run_cpu(&mut self, cpu: &str) -> Result<Vec<(String, Record)>, DriveError>;
}

/// Makes a fresh generated run of the named controllers (whole subtrees);
/// `Err` names what is wrong with the list. The generated
/// `new_system_driver` of each plan set has this type.
pub type SystemFactory = fn(&[&str]) -> Result<Box<dyn DrivenSystem>, String>;
