//! The IR: the single, fully resolved input of every back end (Rust code,
//! graphs, tables) and of the interpreter. Produced by `lower`, read (never
//! changed) by `checks`.
//!
//! Plain data: entities live in `Vec`s and refer to each other by typed ids
//! (`CtrlId`, `PlanId`, `StateId`, `RowId`, …) that index those `Vec`s.
//! Every list is in a deterministic order: files sorted by path, then source
//! order. Spans sit beside the data for diagnostics and row comments.
//!
//! This module holds the whole ([`Ir`]) and its schedule ([`Cpu`]); the parts
//! sit in submodules, all re-exported here so every user names them
//! `ir::X`: `ids` the typed indices, `types` enums, buffers and the
//! resolved types, `controller` a controller and its declarations,
//! `plan` plans and their rows, `job` what rows and `pre`/`post` do,
//! `expr` typed expressions.

mod controller;
mod expr;
mod ids;
mod job;
mod plan;
mod types;

pub use controller::*;
pub use expr::*;
pub use ids::*;
pub use job::*;
pub use plan::*;
pub use types::*;

use serde::Serialize;

/// A validated plan set.
#[derive(Clone, Debug, Serialize)]
pub struct Ir {
    /// Name of the generated system module.
    pub system: String,
    /// Source files relative to the plan set's root, in `FileId` order
    /// (never absolute, so generated outputs do not depend on where the set lives).
    pub files: Vec<String>,
    pub limits: Limits,
    pub enums: Vec<EnumDef>,
    pub buffer_types: Vec<BufferType>,
    /// Global Memory instances. Invariant: at most one writer each.
    pub buffers: Vec<Buffer>,
    pub controllers: Vec<Controller>,
    /// The executives. Invariant: every controller appears exactly once.
    pub schedule: Vec<Cpu>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Limits {
    pub max_rules_per_plan: u32,
    pub max_subordinates: u32,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_rules_per_plan: 10,
            max_subordinates: 9,
        }
    }
}

/// One executive ("CPU"): its period and its controllers in run order.
#[derive(Clone, Debug, Serialize)]
pub struct Cpu {
    pub name: String,
    pub period_ns: u64,
    pub order: Vec<CtrlId>,
    /// The manifest's `process:`; `None` is the default process, named
    /// after the system ([`Ir::process_of`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub process: Option<String>,
    /// External inputs written by hand-written code in this CPU's process
    /// (the manifest's `inputs:`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub inputs: Vec<BufferId>,
    /// Whether the manifest gives this CPU's period (else it is the
    /// documented default, [`crate::manifest::DEFAULT_PERIOD_NS`]).
    #[serde(skip)]
    pub period_given: bool,
}

impl Ir {
    /// The process CPU `cpu` runs in: its `process:`, or the system's name.
    pub fn process_of<'a>(&'a self, cpu: &'a Cpu) -> &'a str {
        cpu.process.as_deref().unwrap_or(&self.system)
    }

    pub fn controller(&self, id: CtrlId) -> &Controller {
        &self.controllers[id.index()]
    }

    pub fn controller_by_name(&self, name: &str) -> Option<CtrlId> {
        self.controllers
            .iter()
            .position(|c| c.name == name)
            .map(|i| CtrlId(i as u32))
    }
}
