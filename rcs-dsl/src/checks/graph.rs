//! The plan graph (states as nodes, rows as edges) on petgraph, and the
//! checks that walk it: `unreachable_state`, `dead_end_state`, `no_done`.
//!
//! The graph starts at `S0` and holds only rows that can fire: a row is an
//! edge from each state in which the analysis of conditions cannot rule out
//! that it fires (so a row testing `new_command` leaves `S0` only, a row
//! that earlier rows always take first adds no edge, and a shadowed exit
//! no longer hides a dead end); `same` never leaves a state.

use super::Sink;
use crate::analysis::terms::Leaf;
use crate::analysis::PlanAnalysis;
use crate::diagnostic::Diagnostic;
use crate::ir::{Controller, Ir, Plan, StateId, Target};
use crate::lint::Lint;
use petgraph::graph::{DiGraph, NodeIndex};
use petgraph::visit::{Bfs, Walker};

/// What the graph says about one plan.
pub(crate) struct Analysis {
    /// Per state: reachable from `S0`.
    pub reachable: Vec<bool>,
    /// Per state: some row leads from it to another node.
    pub leaves: Vec<bool>,
    /// `Done` or `Error` is reachable from `S0`.
    pub ends: bool,
    /// Per row: proved unable to match by its own `from` and condition.
    pub never_matches: Vec<bool>,
    /// A row that can fire leads back to `S0` from another reachable
    /// state, and no row can leave `S0` then: every exit of `S0` needs
    /// the new command, which only the entry has.
    pub s0_dead_on_return: bool,
}

pub(crate) fn analyse(p: &Plan, conditions: &PlanAnalysis) -> Analysis {
    if !conditions.analysed() {
        return structural(p);
    }
    let n = p.states.len();
    let mut g: DiGraph<(), ()> = DiGraph::with_capacity(n + 2, p.rows.len() * 2);
    for _ in 0..n + 2 {
        g.add_node(());
    }
    let (done, error) = (NodeIndex::new(n), NodeIndex::new(n + 1));
    let never_matches: Vec<bool> = (0..p.rows.len())
        .map(|i| conditions.never_matches(i))
        .collect();
    for (i, (row, never)) in p.rows.iter().zip(&never_matches).enumerate() {
        if *never {
            continue;
        }
        let to = match row.to {
            Target::Same => continue,
            Target::State(s) => NodeIndex::new(s.index()),
            Target::Done => done,
            Target::Error(_) | Target::ErrorOf(_) => error,
        };
        // An edge from each state the row can fire in: a row that earlier
        // rows always take first there (or that needs `new_command`
        // outside S0) adds none.
        for f in 0..n {
            let state = StateId(f as u32);
            if NodeIndex::new(f) != to && !conditions.never_fires_in(i, state) {
                g.add_edge(NodeIndex::new(f), to, ());
            }
        }
    }
    let mut reachable = vec![false; n + 2];
    for node in Bfs::new(&g, NodeIndex::new(0)).iter(&g) {
        reachable[node.index()] = true;
    }
    let ends = reachable[n] || reachable[n + 1];
    let leaves = (0..n)
        .map(|s| g.neighbors(NodeIndex::new(s)).next().is_some())
        .collect();
    reachable.truncate(n);
    let s0_dead_on_return = returns_to_s0(p, conditions, &reachable, &never_matches)
        && !leaves_s0_without_command(p, conditions, &never_matches);
    Analysis {
        reachable,
        leaves,
        ends,
        never_matches,
        s0_dead_on_return,
    }
}

/// The graph of a plan too large to analyse, from its rows' state patterns
/// alone: every row may fire wherever its pattern allows. A `*` row is one
/// edge from a node every state leads to, so the graph stays linear in the
/// rows however many states there are.
fn structural(p: &Plan) -> Analysis {
    let n = p.states.len();
    let (done, error, any) = (n, n + 1, n + 2);
    let mut g: DiGraph<(), ()> = DiGraph::with_capacity(n + 3, p.rows.len() + n);
    for _ in 0..n + 3 {
        g.add_node(());
    }
    // Per state: a row of its own leads elsewhere. Targets of `*` rows.
    let mut own_exit = vec![false; n];
    let mut star_targets: Vec<usize> = Vec::new();
    for row in &p.rows {
        let to = match row.to {
            Target::Same => continue,
            Target::State(s) => s.index(),
            Target::Done => done,
            Target::Error(_) | Target::ErrorOf(_) => error,
        };
        if let crate::ir::From::DontCare(_) = row.from {
            if !star_targets.contains(&to) {
                star_targets.push(to);
                g.add_edge(NodeIndex::new(any), NodeIndex::new(to), ());
            }
            continue;
        }
        // One state, a set, or `except`: an edge from each state covered.
        for s in row.states_covered(p).filter(|s| s.index() != to) {
            own_exit[s.index()] = true;
            g.add_edge(NodeIndex::new(s.index()), NodeIndex::new(to), ());
        }
    }
    if !star_targets.is_empty() {
        for s in 0..n {
            g.add_edge(NodeIndex::new(s), NodeIndex::new(any), ());
        }
    }
    let mut reachable = vec![false; n + 3];
    for node in Bfs::new(&g, NodeIndex::new(0)).iter(&g) {
        reachable[node.index()] = true;
    }
    let ends = reachable[done] || reachable[error];
    let leaves = (0..n)
        .map(|s| own_exit[s] || star_targets.iter().any(|&t| t != s))
        .collect();
    reachable.truncate(n);
    Analysis {
        reachable,
        leaves,
        ends,
        never_matches: vec![false; p.rows.len()],
        s0_dead_on_return: false,
    }
}

/// Whether a row that can fire leads to `S0` from another reachable state.
fn returns_to_s0(
    p: &Plan,
    conditions: &PlanAnalysis,
    reachable: &[bool],
    never_matches: &[bool],
) -> bool {
    p.rows.iter().enumerate().any(|(i, row)| {
        row.to == Target::State(StateId::S0)
            && !never_matches[i]
            && (1..p.states.len())
                .any(|f| reachable[f] && !conditions.never_fires_in(i, StateId(f as u32)))
    })
}

/// Whether some row can leave `S0` on a cycle without a new command.
fn leaves_s0_without_command(p: &Plan, conditions: &PlanAnalysis, never_matches: &[bool]) -> bool {
    let Some(nc) = conditions.terms().find(&Leaf::NewCommand) else {
        return true;
    };
    let no_command = [(nc, rcs_runtime::driver::Value::Bool(false))];
    p.rows.iter().enumerate().any(|(i, row)| {
        !never_matches[i]
            && !matches!(row.to, Target::Same | Target::State(StateId::S0))
            && !conditions
                .can_fire_in_given(i, StateId::S0, &no_command)
                .is_never()
    })
}

pub(crate) fn check_unreachable_states(c: &Controller, p: &Plan, a: &Analysis, sink: &mut Sink) {
    for (i, s) in p.states.iter().enumerate().skip(1) {
        if a.reachable[i] {
            continue;
        }
        let Some(span) = s.span else { continue };
        sink.lint(
            Some(c),
            Some(p),
            Diagnostic::lint(
                Lint::UnreachableState,
                format!(
                    "state `{}` of plan `{}` is never reached",
                    s.name,
                    c.plan_title(p)
                ),
                span,
                "no path from the entry leads here",
            )
            .with_help("add a row whose target is this state, or remove its rows"),
        );
    }
}

impl Analysis {
    /// Whether `dead_end_state` reports state `i`: reached, and only a new
    /// command leaves it (`S0` of a plan without entry rows is
    /// `entry_missing`'s).
    pub fn is_dead_end(&self, p: &Plan, i: usize) -> bool {
        let dead = !self.leaves[i] || (i == 0 && self.s0_dead_on_return);
        dead && self.reachable[i]
            && (i != 0 || p.rows.iter().any(|r| r.is_entry))
            && !super::report::reported_hold(p, i)
    }
}

pub(crate) fn check_dead_ends(c: &Controller, p: &Plan, a: &Analysis, sink: &mut Sink) {
    for (i, s) in p.states.iter().enumerate() {
        if !a.is_dead_end(p, i) {
            continue;
        }
        let span = s.span.unwrap_or(p.header);
        sink.lint(
            Some(c),
            Some(p),
            Diagnostic::lint(
                Lint::DeadEndState,
                format!("state `{}` of plan `{}` has no way out", s.name, c.plan_title(p)),
                span,
                if a.leaves[i] {
                    "rows lead back here, and only a new command leaves"
                } else {
                    "no row leaves this state"
                },
            )
            .with_note("only a new command can end the plan here")
            .with_help("add a row from this state to another state, `Done` or `Error(…)`; a continuous plan can `#[allow(dead_end_state)]`"),
        );
    }
}

pub(crate) fn check_no_done(ir: &Ir, c: &Controller, p: &Plan, a: &Analysis, sink: &mut Sink) {
    if a.ends || super::report::reports_any_outcome(p, &a.never_matches) {
        return;
    }
    let _ = ir;
    sink.lint(
        Some(c),
        Some(p),
        Diagnostic::lint(
            Lint::NoDone,
            format!(
                "plan `{}` of `{}` never reaches `Done` or `Error`",
                c.plan_title(p),
                c.name
            ),
            p.header,
            "this plan never ends",
        )
        .with_help("the supervisor never sees DONE; a continuous plan can `#[allow(no_done)]`"),
    );
}
