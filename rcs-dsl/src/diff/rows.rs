//! The rows of one plan on both sides: each row as plain text (a
//! [`RowView`]), the matching of old rows to new ones, and what changed in
//! each matched pair.
//!
//! ## Matching
//!
//! Passes, each over the rows the earlier ones left unmatched, in row order:
//!
//! 1. the same label (`E3`) and the same content: the row is unchanged;
//! 2. the same content under another label: the rows were renumbered (a
//!    row inserted or removed above shifts every later `EN`);
//! 3. the same label, another content: the row changed;
//! 4. the same state pattern and condition under another label: the row
//!    was renumbered and its target or jobs changed;
//! 5. the same state pattern, target and jobs under another label: the
//!    row was renumbered and its condition changed.
//!
//! A renumbered row is reported even when nothing else changed: scenarios
//! and coverage name rows by their `EN`.
//!
//! The content of a row is its state pattern (a state's name, or `*`), its
//! condition, its target and its jobs, as the pretty-printer writes them.
//! Rows left over were removed (old) or added (new).

use super::{precedence, PlanDiff, Presence};
use crate::ir::{Controller, From, Ir, Plan, Row};
use crate::pretty::Printer;
use serde::Serialize;
use std::collections::{BTreeMap, VecDeque};

/// One row, as both renderers and the matching see it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct RowView {
    /// `E3` (the `otherwise` row too).
    pub label: String,
    pub position: u32,
    /// The state pattern: a state's name, `*` for a don't-care row, a set
    /// `A | B`, or `* except A | B`.
    pub from: String,
    /// The condition (`otherwise` for the otherwise row).
    pub condition: String,
    /// `S2`, `same`, `Done`, `Error` or `Error(NAME)`.
    pub target: String,
    pub jobs: Vec<String>,
    pub otherwise: bool,
    /// 1-based line in its file.
    pub line: u32,
    pub file: String,
    /// The `rows` block the row was placed from by `use`, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub block: Option<String>,
}

impl RowView {
    pub fn of(ir: &Ir, p: &Printer, r: &Row) -> RowView {
        RowView {
            label: r.display_name(),
            position: r.position,
            from: match &r.from {
                From::DontCare(_) => "*".to_string(),
                From::State(s) => p.state(*s),
                From::States(set) => p.states(set),
                From::Except(_, out) => format!("* except {}", p.states(out)),
            },
            condition: p.condition(r),
            target: p.target(r),
            jobs: r.jobs.iter().map(|j| p.job(j)).collect(),
            otherwise: r.is_otherwise(),
            line: r.line,
            file: ir.files[r.span.file.0 as usize].clone(),
            block: r.shared.as_ref().map(|s| s.block.clone()),
        }
    }

    /// Whether the row's pattern is written with `*` (`*`, `* except …`).
    fn starred(&self) -> bool {
        self.from.starts_with('*')
    }

    /// The graph nodes the row leaves from: its state, each state of its
    /// set, or its own `*N` (an `except` row too).
    pub fn from_nodes(&self) -> Vec<String> {
        if self.starred() {
            vec![format!("*{}", self.position)]
        } else {
            self.from.split(" | ").map(str::to_string).collect()
        }
    }

    /// The state pattern by meaning: a set's or an `except` list's states
    /// in name order, so that `B | A` is no change from `A | B`.
    pub fn pattern(&self) -> String {
        let (head, list) = match self.from.strip_prefix("* except ") {
            Some(out) => ("* except ", out),
            None => ("", self.from.as_str()),
        };
        let mut names: Vec<&str> = list.split(" | ").collect();
        names.sort_unstable();
        format!("{head}{}", names.join(" | "))
    }

    /// Whether the row applies in the state named `state`.
    pub fn covers_name(&self, state: &str) -> bool {
        match self.from.strip_prefix("* except ") {
            Some(out) => !out.split(" | ").any(|s| s == state),
            None => self.from == "*" || self.from.split(" | ").any(|s| s == state),
        }
    }

    /// The graph node the row goes to when it leaves from node `from`.
    pub fn to_node(&self, from: &str) -> String {
        match self.target.as_str() {
            "same" => from.to_string(),
            t if t.starts_with("Error") => "Error".to_string(),
            t => t.to_string(),
        }
    }

    /// `E3: S1 when cond -> S2 { jobs }` (`E10 otherwise -> same`), one line.
    pub fn text(&self) -> String {
        let sep = if self.otherwise { " " } else { ": " };
        format!("{}{sep}{}", self.label, self.content())
    }

    /// The row without its label: `S1 when cond -> S2 { jobs }`
    /// (`otherwise -> same`).
    pub fn content(&self) -> String {
        let mut s = if self.otherwise {
            "otherwise".to_string()
        } else {
            format!("{} when {}", self.from, self.condition)
        };
        s.push_str(&format!(" -> {}", self.target));
        if !self.jobs.is_empty() {
            s.push_str(&format!(" {{ {} }}", self.jobs.join("; ")));
        }
        s
    }
}

/// What happened to one row.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RowChange {
    Same,
    Added,
    Removed,
    /// Its content changed: the parts named (`from`, `condition`,
    /// `target`, `jobs`).
    Changed(Vec<&'static str>),
}

/// One row of either side, with its counterpart.
#[derive(Clone, Debug, Serialize)]
pub struct RowDiff {
    pub old: Option<RowView>,
    pub new: Option<RowView>,
    pub change: RowChange,
}

impl RowDiff {
    /// Its label now (or before, when removed).
    pub fn label(&self) -> &str {
        self.new
            .as_ref()
            .or(self.old.as_ref())
            .map_or("", |v| &v.label)
    }

    /// The `rows` block of the row (on the side it is on, new first).
    pub fn block(&self) -> Option<&str> {
        self.new
            .as_ref()
            .or(self.old.as_ref())
            .and_then(|v| v.block.as_deref())
    }

    /// Its content changed, or it was added or removed.
    pub fn is_change(&self) -> bool {
        self.change != RowChange::Same
    }

    /// Both sides, with labels that differ: `E3` became `E4`.
    pub fn renumbered(&self) -> bool {
        matches!((&self.old, &self.new), (Some(o), Some(n)) if o.label != n.label)
    }
}

type Side<'a> = (&'a Ir, &'a Controller, &'a Plan);

fn views(side: Option<Side>) -> Vec<RowView> {
    let Some((ir, c, plan)) = side else {
        return Vec::new();
    };
    let p = Printer::new(ir, c, Some(plan));
    plan.rows.iter().map(|r| RowView::of(ir, &p, r)).collect()
}

/// The pairs (old index, new index) of matched rows, in old order. Each
/// pass indexes the new rows left by its key, so matching stays
/// `n log n` on large plans.
pub(crate) fn match_rows(old: &[RowView], new: &[RowView]) -> Vec<(usize, usize)> {
    type Key = fn(&RowView) -> String;
    let passes: [Key; 5] = [
        |v| format!("{}\u{0}{}", v.label, v.content()),
        |v| v.content(),
        |v| v.label.clone(),
        |v| format!("{}\u{0}{}", v.pattern(), v.condition),
        |v| {
            format!(
                "{}\u{0}{}\u{0}{}",
                v.pattern(),
                v.target,
                v.jobs.join("\u{0}")
            )
        },
    ];
    let mut old_of: Vec<Option<usize>> = vec![None; new.len()];
    let mut new_of: Vec<Option<usize>> = vec![None; old.len()];
    for key in passes {
        let mut free: BTreeMap<String, VecDeque<usize>> = BTreeMap::new();
        for (j, n) in new.iter().enumerate().filter(|(j, _)| old_of[*j].is_none()) {
            free.entry(key(n)).or_default().push_back(j);
        }
        for (i, o) in old.iter().enumerate() {
            if new_of[i].is_some() {
                continue;
            }
            if let Some(j) = free.get_mut(&key(o)).and_then(VecDeque::pop_front) {
                new_of[i] = Some(j);
                old_of[j] = Some(i);
            }
        }
    }
    new_of
        .iter()
        .enumerate()
        .filter_map(|(i, j)| j.map(|j| (i, j)))
        .collect()
}

fn change(o: &RowView, n: &RowView) -> RowChange {
    let mut parts = Vec::new();
    if o.pattern() != n.pattern() {
        parts.push("from");
    }
    if o.condition != n.condition {
        parts.push("condition");
    }
    if o.target != n.target {
        parts.push("target");
    }
    if o.jobs != n.jobs {
        parts.push("jobs");
    }
    if parts.is_empty() {
        RowChange::Same
    } else {
        RowChange::Changed(parts)
    }
}

/// The diff of one plan; either side may be missing (an added or removed
/// plan, all of whose rows are then added or removed).
pub(crate) fn diff_plan(old: Option<Side>, new: Option<Side>) -> PlanDiff {
    let (ctrl, verb) = match old.or(new) {
        Some((_, c, p)) => (c.name.clone(), c.commands[p.verb.index()].name.clone()),
        None => (String::new(), String::new()),
    };
    let presence = match (old.is_some(), new.is_some()) {
        (true, true) => Presence::Both,
        (true, false) => Presence::Removed,
        _ => Presence::Added,
    };
    let (ov, nv) = (views(old), views(new));
    let pairs = match_rows(&ov, &nv);
    let mut rows: Vec<RowDiff> = Vec::new();
    // New rows in order; each removed row goes before the first new row
    // whose old counterpart came after it (`removed` stays sorted).
    let mut old_of: Vec<Option<usize>> = vec![None; nv.len()];
    let mut matched = vec![false; ov.len()];
    for &(a, b) in &pairs {
        old_of[b] = Some(a);
        matched[a] = true;
    }
    let mut removed: std::collections::VecDeque<usize> =
        (0..ov.len()).filter(|i| !matched[*i]).collect();
    for (j, n) in nv.iter().enumerate() {
        if let Some(a) = old_of[j] {
            while let Some(i) = removed.front().copied().filter(|&i| i < a) {
                removed.pop_front();
                rows.push(removed_row(&ov[i]));
            }
        }
        rows.push(match old_of[j] {
            Some(a) => RowDiff {
                old: Some(ov[a].clone()),
                new: Some(n.clone()),
                change: change(&ov[a], n),
            },
            None => RowDiff {
                old: None,
                new: Some(n.clone()),
                change: RowChange::Added,
            },
        });
    }
    for i in removed {
        rows.push(removed_row(&ov[i]));
    }
    let states = |side: Option<Side>| -> Vec<String> {
        side.map(|(_, _, p)| p.states.iter().map(|s| s.name.clone()).collect())
            .unwrap_or_default()
    };
    let (os, ns) = (states(old), states(new));
    let moves = match (old, new) {
        (Some(_), Some(n)) => precedence::moves(n, &ov, &nv, &pairs),
        _ => Vec::new(),
    };
    PlanDiff {
        controller: ctrl,
        verb,
        presence,
        states_added: ns.iter().filter(|s| !os.contains(s)).cloned().collect(),
        states_removed: os.iter().filter(|s| !ns.contains(s)).cloned().collect(),
        rows,
        moves,
    }
}

fn removed_row(v: &RowView) -> RowDiff {
    RowDiff {
        old: Some(v.clone()),
        new: None,
        change: RowChange::Removed,
    }
}
