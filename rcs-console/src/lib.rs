//! # rcs-console: watch and act on a running RCS hierarchy (issue 31)
//!
//! A terminal UI (ratatui + crossterm) that shows, live, every controller's
//! verb, state, status, error code, staleness and timing as a tree
//! coloured by status, each CPU's cycle count, heartbeat lateness and mode,
//! and the selected controller's active plan with the row fired last and
//! each row's hit count since attach. The operator pauses, single-steps,
//! runs N cycles of and resumes an executive, and commands a root with
//! parameters checked against their types first.
//!
//! It sits between the runtime and the programs: a hand-written program
//! (the submarine example's `--console`) builds an [`InProcess`] source from
//! its executives' monitors ([`rcs_runtime::Executive::attach_monitor`])
//! and calls [`run`]; `rcsc console` uses the [`Catalog`]. It is a crate of
//! its own rather than a module of `rcsc` because the examples need it and
//! `rcsc` is a binary (and heavy): both depend on this one instead.
//!
//! - [`catalog`]: the plan set's names, parameter types and plan tables;
//! - [`model`]: plain-data snapshots and the model the view draws;
//! - [`source`]: the [`Source`] trait and the in-process attachment;
//! - [`record`]: recording a session to a trace (MCAP or JSON lines);
//! - `remote` (feature `zenoh`): the console as a process of its own,
//!   attached over the Zenoh transport of a distributed plan set;
//! - [`app`]: keys and prompts; [`view`]: drawing; `term`: the terminal.
//!
//! The console never blocks or slows a control cycle: it reads atomics and
//! seqlocked status buffers, and takes no lock an executive takes.

pub mod app;
pub mod catalog;
pub mod model;
pub mod record;
#[cfg(feature = "zenoh")]
pub mod remote;
pub mod source;
mod term;
pub mod view;

pub use app::App;
pub use catalog::{ArgValue, Catalog};
pub use model::{Model, Snapshot};
pub use record::Recording;
pub use source::{Commander, InProcess, Source};
pub use term::run;

#[cfg(test)]
mod tests;
