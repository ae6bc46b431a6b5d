//! # rcs-runtime
//!
//! The runtime under RCS controllers built with `rcsc`: the controller
//! template and main program template of the NIST RCS methodology (§3.8,
//! §5.3–5.5, Appendices A–B) rebuilt for Rust. Generated controllers, the
//! plan interpreter and hand-written modules (simulators, sensor drivers,
//! operator interfaces) all run on it. `docs/semantics.md` is the
//! normative description of a cycle; this crate implements its runtime part
//! once.
//!
//! | module | what it holds |
//! |---|---|
//! | [`gm`] | Global Memory: named `Copy` buffers, one [`Writer`], many [`Reader`]s, generation and cycle stamps |
//! | [`handshake`] | [`CommandBuffer`], [`StatusBuffer`], serials, [`SubordinateLink`] / [`Subordinate`] (a supervisor's view of a subordinate) |
//! | [`plan`] | [`Bookkeeping`]: new-command detection, state, status, counters, fired row, per-verb durations |
//! | [`exec`] | [`Controller`], [`Executive`] (the main program), [`Heartbeat`], pause/step/go through [`ExecutiveHandle`] |
//! | `clock` | the executive's per-controller timing from the TSC (`quanta`), falling back to the OS clock |
//! | [`math`] | the float built-in functions of the language (`sqrt`, `min`, …), shared by generated code and the interpreter |
//! | [`builtin`] | the built-in statuses and error codes as typed enums, and the name lookups generated controllers share |
//! | [`operator`] | [`Operator`]: command a root controller, read status |
//! | [`trace`] | optional trace of every controller's cycle: JSON lines, or MCAP (feature `mcap`) |
//! | [`schema`] | [`Schema`]: a stable hash of a buffer type's structure |
//! | [`serde_array`] | serde for arrays of any length (serde itself stops at 32), for generated types |
//! | [`signal`] | [`CycleSignal`]: an executive wakes a thread off the cycle path (the bridge's export) |
//! | `bridge` | (feature `zenoh`) Global Memory across processes over Zenoh |
//! | `acl` | (features `zenoh`, `certs`) identities for the bridge: mutual TLS, the opt-out, development certificates |
//! | `seqlock` | the only `unsafe` code: the sequence lock behind Global Memory |
//!
//! ## Costs
//!
//! After setup, a cycle takes no locks, makes no heap allocation and has no
//! panicking operation: reads and writes of Global Memory are sequence-lock
//! copies, the bookkeeping works on small integers with saturating and
//! wrapping arithmetic, and statistics are fixed-size. The trace sink is the
//! exception, by design: it formats JSON (see [`trace`]).
//!
//! ## A hand-written controller in the template's shape
//!
//! A turbine controller with two verbs. Each cycle it pre-processes (copies
//! its inputs in once), decides (the new-command check, then the first
//! matching row of the active plan), and post-processes (publishes its
//! status, accounts the cycle) — the shape of Appendix A.
//!
//! ```
//! use rcs_runtime::{
//!     Bookkeeping, Command, CommandBuffer, Controller, CycleContext, ErrorCode, Executive,
//!     ExecutiveConfig, GlobalMemory, Operator, Reader, Status, StatusBuffer, Target, VerbId,
//!     Writer,
//! };
//! use std::time::Duration;
//!
//! /// The turbine's command verbs with their parameters.
//! #[derive(Clone, Copy, Debug, Default, PartialEq)]
//! enum TbCommand {
//!     #[default]
//!     Init,
//!     Spin { rpm: f64 },
//! }
//!
//! impl Command for TbCommand {
//!     fn verb(&self) -> VerbId {
//!         match self {
//!             TbCommand::Init => 0,
//!             TbCommand::Spin { .. } => 1,
//!         }
//!     }
//! }
//!
//! const OVERSPEED: ErrorCode = ErrorCode::custom(0);
//! const AT_SPEED: Status = Status::custom(0);
//!
//! struct Turbine {
//!     cmd_in: Reader<CommandBuffer<TbCommand>>,
//!     status_out: Writer<StatusBuffer>,
//!     rpm_in: Reader<f64>,    // written by a sensor driver
//!     drive_out: Writer<f64>, // read by the actuator
//!     bk: Bookkeeping,
//!     // local copies, refreshed in pre-processing
//!     cmd: CommandBuffer<TbCommand>,
//!     rpm: f64,
//!     drive: f64,
//! }
//!
//! impl Turbine {
//!     fn pre_process(&mut self) {
//!         self.cmd = self.cmd_in.read().value;
//!         self.rpm = self.rpm_in.read().value;
//!     }
//!
//!     fn decide(&mut self, ctx: &CycleContext) {
//!         self.bk.begin_cycle(ctx.tick(), &self.cmd, true);
//!         if !self.bk.is_active() {
//!             return;
//!         }
//!         let new = self.bk.new_command();
//!         let state = self.bk.state();
//!         match self.cmd.command {
//!             TbCommand::Init => {
//!                 // E0: *0 when new_command -> Done { drive = 0 }
//!                 if new {
//!                     self.drive = 0.0;
//!                     self.bk.fire(0, Target::Done);
//!                 }
//!             }
//!             TbCommand::Spin { rpm } => {
//!                 if new {
//!                     // E0: *0 when new_command -> S1 { drive = rpm }
//!                     self.drive = rpm;
//!                     self.bk.fire(0, Target::State(1));
//!                 } else if state == 1 && self.rpm > 2.0 * rpm {
//!                     // E1: S1 when rpm > 2 * cmd.rpm -> Error(OVERSPEED)
//!                     self.bk.fire(1, Target::Error(OVERSPEED));
//!                 } else if state == 1 && (self.rpm - rpm).abs() < 1.0 {
//!                     // E2: S1 when rpm ≈ cmd.rpm -> same { report AT_SPEED }
//!                     self.bk.report(AT_SPEED);
//!                     self.bk.fire(2, Target::Same);
//!                 }
//!             }
//!         }
//!     }
//!
//!     fn post_process(&mut self, ctx: &CycleContext) {
//!         self.drive_out.write(self.drive, ctx.cycle);
//!         self.status_out.write(self.bk.status_buffer(), ctx.cycle);
//!         self.bk.end_cycle();
//!     }
//! }
//!
//! impl Controller for Turbine {
//!     fn name(&self) -> &str {
//!         "TB"
//!     }
//!     fn cycle(&mut self, ctx: &CycleContext) {
//!         self.pre_process();
//!         self.decide(ctx);
//!         self.post_process(ctx);
//!     }
//!     fn bookkeeping(&self) -> Option<&Bookkeeping> {
//!         Some(&self.bk)
//!     }
//! }
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // Setup: Global Memory, handles, the executive. Allocation is fine here.
//! let gm = GlobalMemory::new();
//! gm.declare_controller::<TbCommand>("TB")?;
//! gm.declare::<f64>("tb.rpm")?;
//! gm.declare::<f64>("tb.drive")?;
//! let turbine = Turbine {
//!     cmd_in: gm.command_reader("TB")?,
//!     status_out: gm.status_writer("TB")?,
//!     rpm_in: gm.reader("tb.rpm")?,
//!     drive_out: gm.writer("tb.drive")?,
//!     bk: Bookkeeping::new(2),
//!     cmd: CommandBuffer::default(),
//!     rpm: 0.0,
//!     drive: 0.0,
//! };
//! let mut sensor = gm.writer::<f64>("tb.rpm")?;
//! let mut operator = Operator::<TbCommand>::connect(&gm, "TB")?;
//! let mut cpu = Executive::new(ExecutiveConfig::new("main", Duration::from_millis(10)))?;
//! cpu.add(Box::new(turbine))?;
//!
//! // Run: command, cycle, watch the status through the handshake.
//! operator.command(TbCommand::Spin { rpm: 100.0 });
//! cpu.step()?;
//! assert_eq!(operator.view().status, Status::EXECUTING);
//! sensor.write(99.5, 1);
//! cpu.step()?;
//! assert_eq!(operator.view().status, AT_SPEED);
//! sensor.write(250.0, 2);
//! cpu.step()?;
//! assert_eq!(operator.outcome(), Some((Status::ERROR, OVERSPEED)));
//! assert_eq!(cpu.cycle(), 3);
//! # Ok(())
//! # }
//! ```
//!
//! A controller with subordinates keeps a [`Subordinate`] per subordinate:
//! `read()` in pre-processing gives the handshake view (`done()`,
//! `stale_cycles`…), `send(cmd)` in a job allocates the next serial, and
//! `flush(cycle)` in post-processing writes the command buffer. An
//! interpreter that knows buffers only at run time uses the underlying
//! [`SubordinateLink`] and [`Bookkeeping::begin_cycle_raw`] on plain ids.

#![warn(missing_docs)]

#[cfg(any(feature = "zenoh", feature = "certs"))]
pub mod acl;
#[cfg(feature = "zenoh")]
pub mod bridge;
pub mod builtin;
mod clock;
pub mod driver;
pub mod epoch;
pub mod error;
pub mod exec;
pub mod fault;
#[cfg(feature = "foxglove")]
pub mod foxglove;
pub mod gm;
pub mod handshake;
pub mod heartbeat;
pub mod index;
pub mod math;
pub mod operator;
pub mod plan;
pub mod schema;
mod seqlock;
pub mod serde_array;
pub mod setup;
pub mod signal;
pub mod trace;
pub mod watchdog;

#[cfg(any(feature = "zenoh", feature = "certs"))]
pub use acl::{Security, TlsFiles};
#[cfg(feature = "zenoh")]
pub use bridge::{Bridge, BridgeConfig, BridgeError};
pub use epoch::fresh_epoch;
pub use error::SetupError;
pub use exec::{
    Controller, ControllerFigures, ControllerMonitor, ControllerStats, CycleContext, Executive,
    ExecutiveConfig, ExecutiveHandle, ExecutiveMonitor, ExecutiveStats, Heartbeat, Wait,
};
pub use fault::{ControllerPanic, CycleFault};
pub use gm::{
    command_buffer_name, status_buffer_name, status_fields_buffer_name, BufferData, GlobalMemory,
    Reader, Stamped, Writer,
};
pub use handshake::{
    next_serial, Command, CommandBuffer, ErrorCode, RowId, StateId, Status, StatusBuffer,
    Subordinate, SubordinateLink, SubordinateView, VerbId, S0,
};
pub use operator::{read_status, Operator};
pub use plan::{Bookkeeping, NewCommand, SampleStats, Target, Tick, VerbStats};
pub use schema::Schema;
/// serde, for the `#[serde(crate = "rcs_runtime::serde")]` of generated
/// types of multi-process plan sets (their crates need not depend on serde).
#[doc(hidden)]
pub use serde;
pub use setup::{BufferDecl, Ports, Setup};
pub use signal::CycleSignal;
pub use trace::{
    read_trace, read_trace_bytes, TraceDetail, TraceError, TraceHeader, TraceReadError,
    TraceRecord, TraceSink, TRACE_VERSION,
};
pub use watchdog::BufferWatch;

/// Include the Rust code `rcsc` generated for a plan set from a build script.
///
/// `include_plans!("submarine")` includes the module that
/// `rcs_codegen::Config::compile` wrote under `$OUT_DIR/rcs/` for the plan
/// set whose system (the manifest's `system:`, or the folder's name) is
/// `submarine`. Use it at module level, once per plan set. A name the build
/// script did not compile is a compile error that lists the names it did.
///
/// ```ignore
/// // build.rs (with `rcs-codegen` in [build-dependencies])
/// fn main() -> Result<(), Box<dyn std::error::Error>> {
///     rcs_codegen::Config::new().compile("plans")?; // every plan set under plans/
///     Ok(())
/// }
///
/// // src/lib.rs
/// rcs_runtime::include_plans!("submarine");
/// ```
#[macro_export]
macro_rules! include_plans {
    // `tt`, not `literal`: a captured `literal` fragment is opaque and would
    // match no arm of `__rcsc_plan_set!`.
    ($name:tt) => {
        // `Config::compile` writes this file: one `__rcsc_plan_set!` arm per
        // plan set it compiled, and a `compile_error!` for any other name.
        include!(concat!(env!("OUT_DIR"), "/rcs/include.rs"));
        __rcsc_plan_set!($name);
    };
}
