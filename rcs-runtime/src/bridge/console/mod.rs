//! What a process's bridge offers a remote console (feature `zenoh`): its
//! executives' figures out, executive controls in.
//!
//! Where it sits: beside the bridge's buffer exports and imports, off the
//! cycle path. A program that wants to be watched calls
//! [`Bridge::serve_console`](super::Bridge::serve_console) once its
//! executives are set up; from then on
//!
//! * a thread of the bridge (`rcs-console-<process>`) reads every
//!   executive's [`ExecutiveMonitor`](crate::ExecutiveMonitor) (atomics the
//!   executive stores each cycle) and handle, and the status buffers'
//!   stamps (seqlock reads), and publishes them as one
//!   [`ProcessFigures`] sample every [`DISPLAY_PERIOD`] on
//!   [`figures_key`] — it never touches an executive's lock or cycle;
//! * a subscriber on [`control_key`] takes [`ExecutiveControl`]s (pause,
//!   step N, resume) and applies them through the executives'
//!   [`ExecutiveHandle`](crate::ExecutiveHandle)s. Each is checked like
//!   every imported buffer sample: size before decoding, schema, decoding
//!   with nothing left over, the writer (only [`OPERATOR`]), a generation
//!   after the last one of the same sender, the executive's name and the
//!   step count; a refusal is counted in
//!   [`Bridge::refusals`](super::Bridge::refusals) under the buffer name
//!   [`CONTROL`] and never applied.
//!
//! Who may do either is the generated access-control policy's business
//! (docs/distribution.md "Security"): only the `operator` identity may
//! subscribe to the figures and put controls.
//!
//! Samples use the bridge's wire format (its `wire` module): the schema hash
//! of the type, the writer's name and instance, a generation and a cycle,
//! then the value in postcard. [`command`] encodes a root's command from
//! its verb and typed arguments for a console that has no generated types.

pub mod command;
pub(in crate::bridge) mod serve;

use serde::{Deserialize, Serialize};

use crate::schema::{combine, Schema};

pub(in crate::bridge) use serve::ConsoleService;
pub use serve::{decode_figures, ConsoleFiguresError, MAX_FIGURES_LEN};

/// The identity allowed to watch and control; see [`super::OPERATOR`].
pub use super::OPERATOR;

/// How often the figures are published: 20 times a second, a display's
/// rate, whatever the executives' periods.
pub const DISPLAY_PERIOD: std::time::Duration = std::time::Duration::from_millis(50);

/// The buffer name refused controls are counted under in
/// [`Bridge::refusals`](super::Bridge::refusals).
pub const CONTROL: &str = "_console/control";

/// The most cycles one control may ask to step (run N).
pub const MAX_STEPS: u64 = 1_000_000;

/// The key the figures of process `process` of system `system` are
/// published on: `rcs/SYSTEM/_console/PROCESS/figures`.
pub fn figures_key(system: &str, process: &str) -> String {
    format!("rcs/{system}/_console/{process}/figures")
}

/// The key process `process` takes executive controls on:
/// `rcs/SYSTEM/_console/PROCESS/control`.
pub fn control_key(system: &str, process: &str) -> String {
    format!("rcs/{system}/_console/{process}/control")
}

/// The longest control sample a process accepts: the wire header, an
/// executive name of up to 255 bytes, and the action.
pub const CONTROL_MAX_LEN: usize = super::wire::MAX_HEADER + super::wire::MAX_NAME + 32;

/// One process's figures at one moment: what a console shows of it.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ProcessFigures {
    /// Its executives, in the order the program set them up.
    pub executives: Vec<ExecutiveFigures>,
    /// The roots whose commands this process takes from the operator, with
    /// the schema hash of each root's command buffer (what a console must
    /// send, see [`command`]).
    pub roots: Vec<RootCommand>,
}

/// A root the operator may command in this process.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct RootCommand {
    /// The root controller's name.
    pub root: String,
    /// [`Schema::SCHEMA`] of its `CommandBuffer<Command>`.
    pub schema: u64,
}

/// One executive's figures.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ExecutiveFigures {
    /// Its name (the CPU's).
    pub name: String,
    /// Its heartbeat period, ns.
    pub period_ns: u64,
    /// Cycles run.
    pub cycle: u64,
    /// Paused by an operator.
    pub paused: bool,
    /// Single steps asked for and not yet run.
    pub pending_steps: u64,
    /// Cycles that overran the period.
    pub overruns: u64,
    /// Heartbeats missed.
    pub missed: u64,
    /// Last / longest whole cycle, ns.
    pub cycle_last_ns: u64,
    /// Longest whole cycle, ns.
    pub cycle_max_ns: u64,
    /// How late the last heartbeat woke, ns.
    pub lateness_last_ns: u64,
    /// The latest a heartbeat woke, ns.
    pub lateness_max_ns: u64,
    /// Its controllers in execution order.
    pub controllers: Vec<ControllerFiguresWire>,
}

/// One controller's figures, as they travel.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ControllerFiguresWire {
    /// Its name.
    pub name: String,
    /// Whether it runs plans.
    pub has_plans: bool,
    /// The verb it works on.
    pub verb: u16,
    /// Its plan's current state.
    pub state: u16,
    /// Its status.
    pub status: u16,
    /// Its error code.
    pub error: u16,
    /// `(verb, row, cycle)` of the row it fired last.
    pub last_fired: Option<(u16, u16, u64)>,
    /// Execution time in the last cycle, ns.
    pub exec_last_ns: u64,
    /// Longest execution time, ns.
    pub exec_max_ns: u64,
    /// Cycles in which it alone overran.
    pub overruns: u64,
    /// Panics caught.
    pub panics: u64,
    /// Its status buffer's generation (0: never written; also 0 when it
    /// has none).
    pub status_generation: u64,
    /// The writer's cycle at that write.
    pub status_writer_cycle: u64,
    /// Whether it has a status buffer at all.
    pub has_status: bool,
    /// Hit counts since the figures began, per verb, per row.
    pub hits: Vec<Vec<u64>>,
}

/// What an operator asks of an executive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ExecutiveAction {
    /// Stop running cycles (the heartbeat keeps ticking).
    Pause,
    /// Pause, then run this many more cycles (1..=[`MAX_STEPS`]).
    Step(u64),
    /// Run freely again.
    Resume,
}

/// An executive control: which executive, and what to do.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ExecutiveControl {
    /// The executive's name.
    pub executive: String,
    /// The action.
    pub action: ExecutiveAction,
}

impl Schema for ProcessFigures {
    const SCHEMA: u64 = combine(
        "ProcessFigures{executives:[ExecutiveFigures{name,period_ns,cycle,paused,pending_steps,overruns,missed,cycle_last_ns,cycle_max_ns,lateness_last_ns,lateness_max_ns,controllers:[{name,has_plans,verb,state,status,error,last_fired,exec_last_ns,exec_max_ns,overruns,panics,status_generation,status_writer_cycle,has_status,hits}]}],roots:[{root,schema}]}",
        &[],
    );
}

impl Schema for ExecutiveControl {
    const SCHEMA: u64 = combine(
        "ExecutiveControl{executive:str,action:Pause|Step(u64)|Resume}",
        &[],
    );
}

/// Encode `value` (of schema `schema`) as a sample of writer `writer`,
/// instance `instance`, with these stamps: the bridge's wire format, for a
/// console's controls and tests.
pub fn encode_sample<T: Serialize>(
    schema: u64,
    writer: &str,
    instance: u64,
    generation: u64,
    writer_cycle: u64,
    value: &T,
) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    super::wire::encode(
        &mut out,
        schema,
        writer,
        instance,
        &crate::gm::Stamped {
            value,
            generation,
            writer_cycle,
        },
    )
    .map_err(|e| e.to_string())?;
    Ok(out)
}

/// A random instance number for a console's session (as a bridge draws one).
pub fn random_instance() -> u64 {
    super::random_instance()
}

#[cfg(test)]
mod tests;
