//! Stage 4 (a reader of two IRs): the semantic diff of two versions of a
//! plan set, for `rcsc diff`. Pure and read-only: two checked IRs (and the
//! findings `check` gave each) in, a plain-data [`PlanSetDiff`] out; the
//! back ends (`rcs-codegen`'s `diff` renderers) turn it into text,
//! markdown or diff-coloured graphs.
//!
//! What is compared, and how:
//!
//! - Systems are paired by name (a single plan set on each side is paired
//!   whatever its name); controllers by name; plans by verb; states by name.
//! - Everything is compared **by meaning after normalising**: conditions,
//!   targets and jobs as the pretty-printer writes them from the IR (so
//!   whitespace, comments, line breaks and redundant parentheses never show
//!   as a change); declarations (commands, statuses, errors, vars, hooks,
//!   buffers, subordinates, buffer types, enums) as one-line signatures.
//! - Rows are matched in [`rows`]: by label first (`E3` on both sides, the
//!   same content), then by content when the labels were renumbered (a row
//!   inserted above shifts every later `EN`), then by label again (the same
//!   `EN` with a different content is a changed row); what is left was
//!   added or removed.
//! - A matched pair of rows whose order flipped and whose conditions can
//!   both hold in a state both cover is **moved in precedence**
//!   ([`precedence`]); the analysis says whether that changes which row
//!   fires for some input (with the input), or is left undecided.
//! - Findings (`rcsc check` warnings) are compared by code, the
//!   controller, plan and row they sit on, and their message: never by
//!   line, so a finding moved by an edit above it is the same finding
//!   ([`findings`]).

mod decls;
pub mod findings;
pub mod precedence;
pub mod rows;

use crate::ir::Ir;
use crate::Diagnostic;
use serde::Serialize;

pub use findings::Finding;
pub use precedence::{Effect, Move};
pub use rows::{RowChange, RowDiff, RowView};

/// One side of a diff: a checked plan set.
pub struct Side<'a> {
    pub ir: &'a Ir,
    /// What `check` reported for it (warnings: the side has no error).
    pub diagnostics: &'a [Diagnostic],
}

/// What changed between two versions of one or more plan sets.
#[derive(Clone, Debug, Default, Serialize)]
pub struct PlanSetDiff {
    pub systems: Vec<SystemDiff>,
}

impl PlanSetDiff {
    /// No change at all (the exit status 0 of `rcsc diff`).
    pub fn is_empty(&self) -> bool {
        self.systems.iter().all(SystemDiff::is_empty)
    }
}

/// Whether an entity is on one side only, or on both.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Presence {
    Added,
    Removed,
    Both,
}

/// A declaration that differs: `old`/`new` are its one-line signatures
/// (`None` on the side it is missing from).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ItemChange {
    /// `command`, `status`, `buffer`, `hook`, `subordinate`, …
    pub kind: &'static str,
    pub name: String,
    pub old: Option<String>,
    pub new: Option<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct SystemDiff {
    pub name: String,
    pub presence: Presence,
    /// Enums, buffer types and buffers.
    pub items: Vec<ItemChange>,
    /// Only the controllers with a change.
    pub controllers: Vec<ControllerDiff>,
    /// Findings the change introduced.
    pub findings_introduced: Vec<Finding>,
    /// Findings the change removed.
    pub findings_removed: Vec<Finding>,
}

impl SystemDiff {
    pub fn is_empty(&self) -> bool {
        self.presence == Presence::Both
            && self.items.is_empty()
            && self.controllers.is_empty()
            && self.findings_introduced.is_empty()
            && self.findings_removed.is_empty()
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct ControllerDiff {
    pub name: String,
    pub presence: Presence,
    /// Commands, statuses, errors, vars, hooks, buffers read and written,
    /// subordinates.
    pub items: Vec<ItemChange>,
    /// Only the plans with a change.
    pub plans: Vec<PlanDiff>,
    /// Shared-row blocks with a change, each once (their rows also stay
    /// in each plan's `rows`, for the graphs).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub blocks: Vec<BlockDiff>,
}

/// A change to a `rows` block, reported once with the plans it lands in.
#[derive(Clone, Debug, Serialize)]
pub struct BlockDiff {
    pub name: String,
    /// Where its changed rows are, per plan: `LOAD E1, E2`.
    pub plans: Vec<String>,
    /// The block's changed rows, as the first plan that uses it sees them.
    pub rows: Vec<RowDiff>,
}

impl PlanDiff {
    /// Whether anything changed other than rows of a `rows` block (which
    /// the block's entry reports once).
    pub fn changed_outside_blocks(&self) -> bool {
        self.presence != Presence::Both
            || !self.states_added.is_empty()
            || !self.states_removed.is_empty()
            || !self.moves.is_empty()
            || self
                .rows
                .iter()
                .any(|r| r.block().is_none() && (r.is_change() || r.renumbered()))
    }
}

/// The changed blocks of a controller's plan diffs.
fn block_diffs(plans: &[PlanDiff]) -> Vec<BlockDiff> {
    let mut blocks: Vec<BlockDiff> = Vec::new();
    for p in plans.iter().filter(|p| p.presence == Presence::Both) {
        let mut here: Vec<(&str, Vec<&RowDiff>)> = Vec::new();
        for r in p.rows.iter().filter(|r| r.is_change()) {
            let Some(b) = r.block() else { continue };
            match here.iter_mut().find(|(n, _)| *n == b) {
                Some((_, rows)) => rows.push(r),
                None => here.push((b, vec![r])),
            }
        }
        for (name, rows) in here {
            let labels: Vec<&str> = rows.iter().map(|r| r.label()).collect();
            let place = format!("{} {}", p.verb, labels.join(", "));
            match blocks.iter_mut().find(|b| b.name == name) {
                Some(b) => b.plans.push(place),
                None => blocks.push(BlockDiff {
                    name: name.to_string(),
                    plans: vec![place],
                    rows: rows.into_iter().cloned().collect(),
                }),
            }
        }
    }
    blocks
}

/// What changed in one plan: a plain-data picture of both versions, enough
/// for the renderers to draw it without the IRs.
#[derive(Clone, Debug, Serialize)]
pub struct PlanDiff {
    pub controller: String,
    pub verb: String,
    pub presence: Presence,
    pub states_added: Vec<String>,
    pub states_removed: Vec<String>,
    /// Every row of both versions, new precedence order, a removed row
    /// where it stood before.
    pub rows: Vec<RowDiff>,
    pub moves: Vec<Move>,
}

impl PlanDiff {
    /// `CTRL.VERB`.
    pub fn name(&self) -> String {
        format!("{}.{}", self.controller, self.verb)
    }

    pub fn is_empty(&self) -> bool {
        self.presence == Presence::Both
            && self.states_added.is_empty()
            && self.states_removed.is_empty()
            && self.moves.is_empty()
            && self
                .rows
                .iter()
                .all(|r| r.change == RowChange::Same && !r.renumbered())
    }
}

/// Check a plan set for a diff: its IR and every diagnostic. A side whose
/// checks fail (a row made shadowed is an error by default) is still
/// diffed — its IR lowered without the checks, their errors kept as
/// findings; `None` only when it does not parse or lower.
pub fn check_side(set: &crate::PlanSet, options: &crate::Options) -> (Option<Ir>, Vec<Diagnostic>) {
    let checked = crate::check(set, options);
    let ir = checked.ir.or_else(|| crate::lower_unchecked(set));
    (ir, checked.diagnostics)
}

/// Diff every system of `old` against the one of the same name in `new`.
pub fn diff(old: &[Side], new: &[Side]) -> PlanSetDiff {
    let mut systems = Vec::new();
    if let ([o], [n]) = (old, new) {
        systems.push(diff_system(o, n));
        systems.retain(|s| !s.is_empty());
        return PlanSetDiff { systems };
    }
    for o in old {
        match new.iter().find(|n| n.ir.system == o.ir.system) {
            Some(n) => systems.push(diff_system(o, n)),
            None => systems.push(one_sided(o, Presence::Removed)),
        }
    }
    for n in new {
        if !old.iter().any(|o| o.ir.system == n.ir.system) {
            systems.push(one_sided(n, Presence::Added));
        }
    }
    systems.retain(|s| !s.is_empty());
    PlanSetDiff { systems }
}

fn one_sided(side: &Side, presence: Presence) -> SystemDiff {
    SystemDiff {
        name: side.ir.system.clone(),
        presence,
        items: Vec::new(),
        controllers: Vec::new(),
        findings_introduced: Vec::new(),
        findings_removed: Vec::new(),
    }
}

fn diff_system(old: &Side, new: &Side) -> SystemDiff {
    let mut controllers = Vec::new();
    for oc in &old.ir.controllers {
        match new.ir.controllers.iter().find(|c| c.name == oc.name) {
            Some(nc) => {
                let items = decls::controller_items(old.ir, oc, new.ir, nc);
                let mut plans = Vec::new();
                for cmd in oc.commands.iter().chain(&nc.commands) {
                    if plans.iter().any(|p: &PlanDiff| p.verb == cmd.name) {
                        continue;
                    }
                    let op = oc.plan_of(&cmd.name).map(|p| (old.ir, oc, p));
                    let np = nc.plan_of(&cmd.name).map(|p| (new.ir, nc, p));
                    plans.push(rows::diff_plan(op, np));
                }
                plans.retain(|p| !p.is_empty());
                if !items.is_empty() || !plans.is_empty() {
                    controllers.push(ControllerDiff {
                        name: oc.name.clone(),
                        presence: Presence::Both,
                        items,
                        blocks: block_diffs(&plans),
                        plans,
                    });
                }
            }
            None => controllers.push(one_sided_controller(old.ir, oc, Presence::Removed)),
        }
    }
    for nc in &new.ir.controllers {
        if !old.ir.controllers.iter().any(|c| c.name == nc.name) {
            controllers.push(one_sided_controller(new.ir, nc, Presence::Added));
        }
    }
    let (findings_introduced, findings_removed) = findings::diff_findings(old, new);
    SystemDiff {
        name: new.ir.system.clone(),
        presence: Presence::Both,
        items: decls::system_items(old.ir, new.ir),
        controllers,
        findings_introduced,
        findings_removed,
    }
}

/// A controller on one side only: its plans drawn all added (or removed).
fn one_sided_controller(ir: &Ir, c: &crate::ir::Controller, presence: Presence) -> ControllerDiff {
    let plans = c
        .commands
        .iter()
        .filter_map(|cmd| c.plan_of(&cmd.name))
        .map(|p| match presence {
            Presence::Removed => rows::diff_plan(Some((ir, c, p)), None),
            _ => rows::diff_plan(None, Some((ir, c, p))),
        })
        .collect();
    ControllerDiff {
        name: c.name.clone(),
        presence,
        items: Vec::new(),
        plans,
        blocks: Vec::new(),
    }
}

#[cfg(test)]
mod tests;
