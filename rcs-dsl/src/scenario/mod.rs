//! Scenarios (`*.scenario.yaml`, TOOLING.md and docs/scenarios.md): a
//! controller driven alone through written steps — the scenario plays its
//! supervisor, its subordinates, its `reads` buffers and its hooks — with
//! expectations checked after each step. This sits after the checks, on
//! a clean IR: [`read`] reads a scenario (through [`crate::yaml`]) and
//! resolves every name against the IR, [`run`] drives it on any backend
//! behind [`rcs_runtime::driver::Driven`] (the reference interpreter or
//! the generated code), [`report`] compares what a step left with what it
//! expects, and [`values`] reads and prints values as the language writes
//! them.

mod read;
mod report;
mod run;
mod script;
mod system;
mod system_read;
mod values;

pub use read::{parse, parse_any, AnyScenario};
pub use run::{run, run_observed, run_on};
pub(crate) use script::run_script_observed;
pub use script::{run_script, ControllerExpect, SystemScript, SystemStep};
pub use system::{run_system, run_system_on, schedule, state_name, SystemOutcome, SystemScenario};
pub(crate) use system_read::roots_of;
pub(crate) use values::{merge, value};

use crate::interp::Value;
use crate::ir::{CommandId, CtrlId, HookId, RowId, StateId};
use serde_json::Value as Json;
use std::collections::{BTreeMap, BTreeSet};

/// The most cycles one step may run. A step's cost is constant in memory
/// (the rows fired are kept run-length encoded), so the bound is about
/// time: ten million cycles of a small plan take seconds on the
/// interpreter.
pub const MAX_CYCLES: u64 = 10_000_000;

/// A problem with a scenario file (not a failed expectation): where and what.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioError {
    pub line: usize,
    pub message: String,
}

pub(crate) fn err(line: usize, message: impl Into<String>) -> ScenarioError {
    ScenarioError {
        line,
        message: message.into(),
    }
}

/// How a subordinate's status buffer looks to the controller.
#[derive(Clone, Debug, PartialEq)]
struct SubSetting {
    status: u16,
    /// The error code shown with `status: ERROR` (0: none).
    error: u16,
    /// `X: REFUSED`: the latest command sent is answered as refused.
    refused: bool,
    echo: Echo,
    silent: bool,
    /// Status fields the subordinate publishes from this step on, by name.
    fields: Vec<(String, Value)>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Echo {
    Current,
    Previous,
    Literal(u32),
}

/// What a step expects after its last cycle.
#[derive(Clone, Debug, Default)]
struct Expect {
    /// `Some(None)`: no row fired; otherwise a name of the row (`E3`, or
    /// an alias: `#3`, `*3`, `otherwise`).
    fired: Option<Option<String>>,
    state: Option<String>,
    status: Option<u16>,
    /// `Some(None)`: no error.
    error: Option<Option<u16>>,
    /// `answered: N`: the serial the answer (status and error) is about.
    answered: Option<u32>,
    sent: Option<Vec<(CtrlId, CommandId, Vec<Value>)>>,
    /// `vars:` and `status_fields:` (a status field is a var the
    /// controller publishes), by var index.
    vars: Vec<(usize, Value)>,
    /// Subset match: only the fields named are compared.
    writes: Vec<(usize, Json)>,
    /// Calls of each hook named, over all the step's cycles.
    hooks_called: Vec<(HookId, Called)>,
}

/// What `hooks_called` expects of one hook over a step.
#[derive(Clone, Debug)]
enum Called {
    /// This many calls.
    Times(u64),
    /// These calls, in order: each call's arguments by parameter position
    /// (`None`: a parameter the expectation leaves out).
    With(Vec<Vec<Option<Value>>>),
}

struct Step {
    line: usize,
    command: Option<(CommandId, Vec<Value>)>,
    reads: Vec<(usize, Json)>,
    hooks: Vec<(HookId, Value)>,
    subs: Vec<(usize, SubSetting)>,
    /// `silent: [B, …]`: `reads` buffers (by index) held unwritten from
    /// this step's first cycle until a later step's `reads:` writes them.
    silent: Vec<usize>,
    /// `initial:` only: vars and `writes` buffers (merged into zero).
    vars: Vec<(usize, Value)>,
    writes: Vec<(usize, Json)>,
    cycles: u64,
    expect: Expect,
}

/// A scenario resolved against a controller of the IR.
pub struct Scenario {
    pub name: String,
    pub controller: CtrlId,
    initial: Step,
    steps: Vec<Step>,
}

/// One scenario's outcome.
#[derive(Debug)]
pub struct Outcome {
    pub name: String,
    /// `None`: passed. Otherwise the line of the failing step and the report.
    pub failure: Option<(usize, String)>,
    /// Rows fired, by name (`E3`; `-` for none), run-length encoded: each
    /// entry is a name and how many consecutive cycles fired it.
    pub fired: Vec<(String, u64)>,
    /// Rows fired as (verb, row), for coverage; a plan's rows under its
    /// first verb ([`Plan::verb`](crate::ir::Plan::verb)).
    pub rows: BTreeSet<(CommandId, RowId)>,
    /// How many cycles fired each (verb, row): coverage with hit counts.
    pub hits: BTreeMap<(CommandId, RowId), u64>,
    /// How many cycles ended in each (verb, state): the time spent there.
    pub states: BTreeMap<(CommandId, StateId), u64>,
}

impl Outcome {
    /// The rows fired, one name per cycle (expanded: for short runs).
    pub fn fired_per_cycle(&self) -> impl Iterator<Item = &str> {
        self.fired
            .iter()
            .flat_map(|(name, n)| std::iter::repeat_n(name.as_str(), *n as usize))
    }

    /// How many cycles ran.
    pub fn cycles(&self) -> u64 {
        self.fired.iter().map(|(_, n)| n).sum()
    }
}
