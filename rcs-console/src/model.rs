//! The console's model: plain data a [`Source`](crate::Source) fills in
//! once per refresh, and the names the [`Catalog`] gives the numbers.
//!
//! A [`Snapshot`] is what the running system says at one moment (ids and
//! counters only; the remote source builds it from what processes publish);
//! [`Model`] keeps the latest one with the catalog and the hit counts seen
//! at attach, so that the view shows hits *since attach*.

use crate::catalog::{Catalog, ControllerInfo, PlanTable};
use rcs_runtime::{ErrorCode, RowId, StateId, Status, VerbId};

/// One CPU (executive) at one moment.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct CpuSnapshot {
    /// The executive's name.
    pub name: String,
    /// Its heartbeat period, ns.
    pub period_ns: u64,
    /// Cycles run.
    pub cycle: u64,
    /// Paused by an operator.
    pub paused: bool,
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
    /// How long its process has not been heard from, ms, once that is
    /// long enough to be news (a remote source; `None` in-process).
    pub silent_ms: Option<u64>,
}

/// One controller at one moment.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ControllerSnapshot {
    /// Its name.
    pub name: String,
    /// The CPU that runs it.
    pub cpu: String,
    /// Whether it runs plans (a simulator or driver does not: its verb,
    /// state, status and error mean nothing).
    pub has_plans: bool,
    /// The verb it works on.
    pub verb: VerbId,
    /// Its plan's current state.
    pub state: StateId,
    /// Its status.
    pub status: Status,
    /// Its error code.
    pub error: ErrorCode,
    /// Its CPU's cycles since it last wrote its status (`None`: unknown).
    pub stale_cycles: Option<u64>,
    /// Its execution time in the last cycle, ns.
    pub exec_last_ns: u64,
    /// Its longest, ns.
    pub exec_max_ns: u64,
    /// Cycles in which it alone overran the period.
    pub overruns: u64,
    /// Panics caught in its cycle.
    pub panics: u64,
    /// `(verb, row, cycle)` of the row it fired last.
    pub last_fired: Option<(VerbId, RowId, u64)>,
    /// Hit counts per verb, per row (cumulative, as the source counts).
    pub hits: Vec<Vec<u64>>,
}

/// The whole system at one moment.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Snapshot {
    /// The CPUs.
    pub cpus: Vec<CpuSnapshot>,
    /// The controllers.
    pub controllers: Vec<ControllerSnapshot>,
}

/// What the view shows: the catalog, the latest snapshot, the hit counts at
/// attach.
#[derive(Debug, Clone, Default)]
pub struct Model {
    /// The plan set.
    pub catalog: Catalog,
    /// The latest snapshot.
    pub now: Snapshot,
    /// Hit counts of the first snapshot, per controller name.
    baseline: Vec<(String, Vec<Vec<u64>>)>,
}

/// A row of the selected controller's plan table, ready to draw.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlanRowView {
    /// Label, from, condition, to.
    pub text: crate::catalog::RowText,
    /// Hits since attach.
    pub hits: u64,
    /// Whether it fired last.
    pub last: bool,
    /// Whether its from-pattern names the current state by name.
    pub from_current: bool,
}

impl Model {
    /// A model of `catalog` with nothing seen yet.
    pub fn new(catalog: Catalog) -> Self {
        Self {
            catalog,
            now: Snapshot::default(),
            baseline: Vec::new(),
        }
    }

    /// Take in a new snapshot (the first one sets the hit-count baseline).
    pub fn update(&mut self, snapshot: Snapshot) {
        for c in &snapshot.controllers {
            if !self.baseline.iter().any(|(n, _)| *n == c.name) {
                self.baseline.push((c.name.clone(), c.hits.clone()));
            }
        }
        self.now = snapshot;
    }

    /// The controller called `name` in the latest snapshot.
    pub fn controller(&self, name: &str) -> Option<&ControllerSnapshot> {
        self.now.controllers.iter().find(|c| c.name == name)
    }

    /// The CPU called `name`.
    pub fn cpu(&self, name: &str) -> Option<&CpuSnapshot> {
        self.now.cpus.iter().find(|c| c.name == name)
    }

    /// Controller names in tree order (roots first, each followed by its
    /// subordinates, depth first) with their depth; controllers the snapshot
    /// has but the catalog lacks come last at depth 0.
    pub fn tree(&self) -> Vec<(usize, String)> {
        let mut out = Vec::new();
        fn walk(cat: &Catalog, c: &ControllerInfo, depth: usize, out: &mut Vec<(usize, String)>) {
            if out.iter().any(|(_, n)| *n == c.name) || depth > 64 {
                return;
            }
            out.push((depth, c.name.clone()));
            for s in &c.subordinates {
                if let Some(sub) = cat.controller(s) {
                    walk(cat, sub, depth + 1, out);
                }
            }
        }
        for root in self.catalog.roots() {
            walk(&self.catalog, root, 0, &mut out);
        }
        for c in &self.now.controllers {
            if !out.iter().any(|(_, n)| *n == c.name) {
                out.push((0, c.name.clone()));
            }
        }
        out
    }

    /// The verb name, state name, status name and error name of controller
    /// `name` now (`-` where unknown).
    pub fn names(&self, name: &str) -> (String, String, String, String) {
        let info = self.catalog.controller(name);
        let Some(c) = self.controller(name) else {
            return ("-".into(), "-".into(), "?".into(), "-".into());
        };
        let verb = info.and_then(|i| i.verbs.get(usize::from(c.verb)));
        let verb_name = verb.map_or_else(|| format!("verb {}", c.verb), |v| v.name.clone());
        let state = verb
            .and_then(|v| v.plan.as_ref())
            .and_then(|p| p.states.get(usize::from(c.state)))
            .cloned()
            .unwrap_or_else(|| format!("S{}", c.state));
        let (status, error) = match info {
            Some(i) => (i.status_name(c.status), i.error_name(c.error)),
            None => (format!("status {}", c.status.0), format!("{}", c.error.0)),
        };
        if !c.has_plans {
            return ("-".into(), "-".into(), "-".into(), "-".into());
        }
        if c.status == Status::NOT_READY {
            return ("-".into(), "-".into(), status, error);
        }
        (verb_name, state, status, error)
    }

    /// The active plan of controller `name`: the verb's name, its table and
    /// each row ready to draw (`None` before its first command).
    pub fn plan_rows(&self, name: &str) -> Option<(String, &PlanTable, Vec<PlanRowView>)> {
        let c = self
            .controller(name)
            .filter(|c| c.has_plans && c.status != Status::NOT_READY)?;
        let verb = self
            .catalog
            .controller(name)?
            .verbs
            .get(usize::from(c.verb))?;
        let plan = verb.plan.as_ref()?;
        let base = self
            .baseline
            .iter()
            .find(|(n, _)| n == name)
            .and_then(|(_, h)| h.get(usize::from(c.verb)));
        let hits = c.hits.get(usize::from(c.verb));
        let state = plan.states.get(usize::from(c.state));
        let rows = plan
            .rows
            .iter()
            .enumerate()
            .map(|(i, text)| {
                let now = hits.and_then(|h| h.get(i)).copied().unwrap_or(0);
                let then = base.and_then(|h| h.get(i)).copied().unwrap_or(0);
                PlanRowView {
                    text: text.clone(),
                    hits: now.saturating_sub(then),
                    last: c
                        .last_fired
                        .is_some_and(|(v, r, _)| v == c.verb && usize::from(r) == i),
                    from_current: state.is_some_and(|s| {
                        text.from.split(['|', ' ']).any(|part| part == s.as_str())
                    }),
                }
            })
            .collect();
        Some((verb.name.clone(), plan, rows))
    }
}
