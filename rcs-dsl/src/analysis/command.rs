//! Stage 3a, over a whole command: what the values that stay fixed while a
//! command runs decide. The questions of [`super`] are about one cycle;
//! these follow a command from its first cycle through the plan graph,
//! once for each *case* of the values fixed for the command, and answer
//! the checks `unreachable_row` (a state entered only with values that make
//! a row false) and `incomplete_state` (a state where, with some values, no
//! row can ever fire again).
//!
//! ## Cases
//!
//! The command's parameters keep their values until the next command, and
//! a var no job assigns always holds its initialiser. A case pins one
//! representative per cell of each parameter the conditions read
//! ([`PlanAnalysis::cell_values`]), so the cases together stand for every
//! command. With more than [`MAX_CASES`] cases nothing is said.
//!
//! ## Two walks per case
//!
//! The nodes are the plan's states, with `S0` twice: on the command's
//! first cycle (`new_command` true) and on any later cycle (false).
//!
//! - The **may** walk keeps every row the proof cannot rule out (an
//!   unknown answer included): a state it does not reach is never reached
//!   with that case. `unreachable_row` stands on it.
//! - The **sure** walk keeps only rows shown to fire by a witness whose
//!   inputs the world sets freely on any cycle (buffers it reads, hook
//!   results, subordinate statuses). A row whose firing also depends on a
//!   var that jobs change, on a `writes` buffer or on a cycle counter is
//!   not followed: whether those hold the witness's values when the plan
//!   gets there is not known. Each state it reaches has a path, a list of
//!   cycles that lead there, which a test replays on the interpreter.
//!   `incomplete_state` stands on it: a hang is reported only in a state
//!   the plan surely reaches with the hanging values.

use super::search::{Mode, Outcome, Search};
use super::terms::{Formula, Leaf, LeafId};
use super::{covers, PlanAnalysis, Witness};
use crate::ir::{From, StateId, Target};
use rcs_runtime::driver::Value;

/// The most cases (combinations of cells of the command's parameters)
/// tried; past it, the command analysis says nothing.
pub const MAX_CASES: usize = 128;

/// The most questions (cases × states × rows) one walk of all cases may
/// ask; past it, nothing is said either, so that a large plan stays quick.
pub const MAX_QUESTIONS: usize = 20_000;

/// Values pinned for a whole command: leaf, value.
pub type Case = Vec<(LeafId, Value)>;

/// One cycle on the way from a command's arrival to a state.
#[derive(Clone, Debug)]
pub enum Step {
    /// Row `row` fires, given the witness's inputs.
    Fire { row: usize, witness: Witness },
    /// The command's first cycle, in which no row can match: the plan stays
    /// in `S0`.
    Idle,
}

/// A state in which the plan hangs: with `command`'s values no row of it
/// can ever fire again, whatever every other input does.
#[derive(Clone, Debug)]
pub struct Hang {
    pub state: StateId,
    /// One value per parameter the conditions read.
    pub command: Case,
    /// `command` and the vars no job assigns: everything the proof pins.
    pub given: Case,
    /// The cycles from the command's arrival into `state`, with these values.
    pub path: Vec<Step>,
    /// Every case with which the plan surely reaches `state` and hangs
    /// there, `command` first.
    pub cases: Vec<Case>,
    /// No row on any case's path reads a parameter through an opaque
    /// atom, so each case's path holds for every value of its cells (else
    /// only for the representative values themselves).
    pub path_by_cells: bool,
}

/// A row that can match on its own but not with any command values its
/// state is entered with.
#[derive(Clone, Debug)]
pub struct EntryBound {
    pub row: usize,
    pub state: StateId,
    /// The cases with which `state` may be reached (all make `row` false).
    pub cases: Vec<Case>,
    /// The rows that may enter `state` in those cases.
    pub entries: Vec<usize>,
}

/// The outcome of one walk with one case.
struct Walk {
    /// Per node: maybe reached.
    may: Vec<bool>,
    /// Per node: the rows that may enter it.
    into: Vec<Vec<usize>>,
    /// Per node: a sure path to it (empty unless asked for).
    paths: Vec<Option<Vec<Step>>>,
}

/// A row that may fire from one node into another, as the may walk found
/// it.
struct Edge {
    from: usize,
    row: usize,
    to: usize,
    /// The proof found an assignment (not merely ran out of budget).
    found: bool,
}

impl PlanAnalysis<'_> {
    /// Row `row`'s condition as a formula (`None` for `otherwise`).
    pub fn condition(&self, row: usize) -> Option<&Formula> {
        self.conds.get(row)?.as_deref()
    }

    /// The cases of the values fixed for a command: every combination of
    /// one cell per parameter the conditions read. `None` when there are
    /// too many (cases, or questions to ask about them), or a parameter
    /// has no cells (not a scalar).
    pub fn command_cases(&self) -> Option<Vec<Case>> {
        let leaves = self.command_leaves();
        let mut cases: Vec<Case> = vec![Vec::new()];
        for &l in &leaves {
            // Plain numbers first, so that the first case that shows
            // something reads well: NaN and the infinities last.
            let mut values = self.cell_values(l).to_vec();
            values.sort_by_key(|v| match v {
                Value::Float(x) if x.is_nan() => 2,
                Value::Float(x) if x.is_infinite() => 1,
                _ => 0,
            });
            if values.is_empty() || cases.len() * values.len() > MAX_CASES {
                return None;
            }
            cases = cases
                .into_iter()
                .flat_map(|c| {
                    let values = &values;
                    values.iter().map(move |v| {
                        let mut c = c.clone();
                        c.push((l, v.clone()));
                        c
                    })
                })
                .collect();
        }
        let questions = cases.len() * (self.plan.states.len() + 1) * self.plan.rows.len();
        (questions <= MAX_QUESTIONS).then_some(cases)
    }

    /// Every state in which the plan hangs for some case, with the first
    /// such case (in case order) and a sure path to it.
    ///
    /// A state in which no row can match on any cycle whatever the command
    /// is left out: with no row that can match at all it is
    /// `dead_end_state`'s (or for `S0`, `entry_missing`'s) finding, and a
    /// var no job assigns that blocks every command there is more often a
    /// stand-in for an input not written yet than a gap in the table. For
    /// `S0` "any cycle" includes the first, so a row back to `S0`, whose
    /// entry rows need a new command, is still reported.
    pub fn hangs(&self) -> Vec<Hang> {
        if !self.analysed_over_cycles() {
            return Vec::new();
        }
        let constants = self.constant_vars();
        let n = self.plan.states.len();
        // The usual plan has, in each state, a row that does not depend on
        // the command's values at all (a timeout, an emergency stop, a wait
        // on an input) and that can match: it can whatever those values
        // are, so no state can hang, and the walks need not be taken.
        let mut fixed: Vec<LeafId> = self.command_leaves();
        fixed.extend(constants.iter().map(|(l, _)| *l));
        if (0..n).all(|s| self.may_match_whatever(StateId(s as u32), &fixed)) {
            return Vec::new();
        }
        let Some(cases) = self.command_cases() else {
            return Vec::new();
        };
        let mut found: Vec<Option<Hang>> = vec![None; n + 1];
        // Per state: no row covering it can match whatever the command.
        let mut dead: Vec<Option<bool>> = vec![None; n];
        for case in cases {
            // A command with these values is refused on arrival whatever
            // else holds (`accept when`): the plan never runs with them.
            if self.always_refused(&case) {
                continue;
            }
            let mut given = case.clone();
            given.extend(constants.iter().cloned());
            let walk = self.walk(&given, true);
            // Node 0 is the first cycle: a hang is a cycle after it.
            for (node, path) in walk.paths.iter().enumerate().skip(1) {
                let Some(path) = path else {
                    continue;
                };
                let state = node_state(node, n);
                let dead = *dead[state.index()]
                    .get_or_insert_with(|| self.nothing_matches_given(state, &constants));
                if dead {
                    continue;
                }
                if !self.nothing_matches_given(state, &self.pinned(node, n, &given)) {
                    continue;
                }
                let hang = found[node].get_or_insert_with(|| Hang {
                    state,
                    command: case.clone(),
                    given: given.clone(),
                    path: path.clone(),
                    cases: Vec::new(),
                    path_by_cells: true,
                });
                hang.cases.push(case.clone());
                hang.path_by_cells &= self.path_by_cells(path, n);
            }
        }
        // S0 on a later cycle is reported as S0 (first, as states are).
        let mut out: Vec<Hang> = Vec::new();
        if let Some(h) = found[n].take() {
            out.push(h);
        }
        out.extend(found.into_iter().take(n).flatten());
        out
    }

    /// The rows from a state other than `S0` that can match by their own
    /// condition but not with any case the state may be reached with.
    /// Only the command's parameters are pinned (every answer a proof).
    pub fn entry_bound_rows(&self) -> Vec<EntryBound> {
        if !self.analysed_over_cycles() {
            return Vec::new();
        }
        let params = self.command_leaves();
        // Only a row that compares a parameter exactly can be made false
        // by the values its state is entered with (for a proof, an opaque
        // atom is a free boolean whatever the parameter). Only a row of one
        // state is judged: a set or `except` row would have to be false in
        // each of its states, and leaving it out claims nothing.
        let candidates = self.plan.rows.iter().enumerate().any(|(i, row)| {
            matches!(row.from, From::State(s) if s != StateId::S0) && !self.free_of(i, &params)
        });
        if params.is_empty() || !candidates {
            return Vec::new();
        }
        let Some(cases) = self.command_cases() else {
            return Vec::new();
        };
        let walks: Vec<Walk> = cases.iter().map(|c| self.walk(c, false)).collect();
        let mut out = Vec::new();
        for (i, row) in self.plan.rows.iter().enumerate() {
            let (From::State(s), Some(cond)) = (&row.from, &self.conds[i]) else {
                continue;
            };
            if *s == StateId::S0 || self.never_matches(i) {
                continue;
            }
            let reaching: Vec<usize> = (0..cases.len())
                .filter(|&k| walks[k].may[s.index()])
                .collect();
            if reaching.is_empty() {
                continue;
            }
            let false_in_all = reaching.iter().all(|&k| {
                let mut fixed = self.fixed(*s);
                fixed.extend(cases[k].iter().cloned());
                let f = Formula::Shared(cond.clone());
                matches!(self.prove(&f, &fixed), Outcome::None)
            });
            if !false_in_all {
                continue;
            }
            let mut entries: Vec<usize> = reaching
                .iter()
                .flat_map(|&k| walks[k].into[s.index()].iter().copied())
                .collect();
            entries.sort_unstable();
            entries.dedup();
            out.push(EntryBound {
                row: i,
                state: *s,
                cases: reaching.iter().map(|&k| cases[k].clone()).collect(),
                entries,
            });
        }
        out
    }

    /// Whether no exact atom of row `row`'s condition reads one of
    /// `leaves` (pinning them then changes nothing a proof sees).
    fn free_of(&self, row: usize, leaves: &[LeafId]) -> bool {
        let Some(cond) = &self.conds[row] else {
            return true;
        };
        let mut free = true;
        cond.visit_atoms(&mut |a| {
            let atom = &self.terms.atoms[a];
            free &= !(atom.exact && atom.leaves.iter().any(|l| leaves.contains(l)));
        });
        free
    }

    /// Whether, on any cycle after the command's first, some row covering
    /// `state` may match whatever values `fixed` hold: an `otherwise` row,
    /// or a row free of them that the proof cannot rule out.
    fn may_match_whatever(&self, state: StateId, fixed: &[LeafId]) -> bool {
        let later = [(self.new_command, Value::Bool(false))];
        self.plan.rows.iter().enumerate().any(|(i, row)| {
            covers(&row.from, state)
                && self.free_of(i, fixed)
                && match &self.conds[i] {
                    None => true,
                    // Without `new_command` in it, the condition is judged
                    // as the graph already judged it (a proof remembered).
                    Some(_) if self.free_of(i, &[self.new_command]) => !self.never_matches(i),
                    Some(c) => {
                        let f = Formula::Shared(c.clone());
                        !matches!(self.prove(&f, &later), Outcome::None)
                    }
                }
        })
    }

    /// The leaves pinned on node `node`'s cycles: `given`, and
    /// `new_command` (true only on the command's first cycle).
    fn pinned(&self, node: usize, n: usize, given: &Case) -> Case {
        let mut pinned = self.fixed(node_state(node, n));
        pinned.extend(given.iter().cloned());
        if node == 0 {
            pinned.push((self.new_command, Value::Bool(true)));
        } else if node == n {
            pinned.push((self.new_command, Value::Bool(false)));
        }
        pinned
    }

    /// Walk the plan graph from the command's first cycle with `given`
    /// pinned: the may walk, then (if `sure`) the sure walk along it.
    fn walk(&self, given: &Case, sure: bool) -> Walk {
        let n = self.plan.states.len();
        let mut may = vec![false; n + 1];
        let mut into: Vec<Vec<usize>> = vec![Vec::new(); n + 1];
        let mut edges: Vec<Edge> = Vec::new();
        // S0 on a later cycle: kept as maybe reached whatever happens (a
        // `-> S0` row, or a first cycle in which nothing fires).
        may[0] = true;
        may[n] = true;
        let mut queue = std::collections::VecDeque::from([0, n]);
        while let Some(node) = queue.pop_front() {
            let state = node_state(node, n);
            let pinned = self.pinned(node, n, given);
            for (r, row) in self.plan.rows.iter().enumerate() {
                let Some(to) = target_node(node, n, row.to) else {
                    continue;
                };
                let Some(f) = self.fires(r, state) else {
                    continue;
                };
                let found = match self.prove(&f, &pinned) {
                    Outcome::None => continue,
                    Outcome::Found(_) => true,
                    Outcome::Unknown => false,
                };
                if !into[to].contains(&r) {
                    into[to].push(r);
                }
                edges.push(Edge {
                    from: node,
                    row: r,
                    to,
                    found,
                });
                if !may[to] {
                    may[to] = true;
                    queue.push_back(to);
                }
            }
        }
        let paths = if sure {
            self.sure_paths(given, &edges)
        } else {
            Vec::new()
        };
        Walk { may, into, paths }
    }

    /// The sure walk over the may walk's edges: breadth first, so each path
    /// is a shortest one.
    fn sure_paths(&self, given: &Case, edges: &[Edge]) -> Vec<Option<Vec<Step>>> {
        let n = self.plan.states.len();
        let mut paths: Vec<Option<Vec<Step>>> = vec![None; n + 1];
        paths[0] = Some(Vec::new());
        let mut queue = std::collections::VecDeque::from([0]);
        // A first cycle in which no row can match leaves the plan in S0.
        let first = self.pinned(0, n, given);
        if !self.plan.rows.iter().any(|r| r.is_otherwise()) {
            let any = Formula::Or(
                self.conds
                    .iter()
                    .zip(&self.plan.rows)
                    .filter(|(_, r)| covers(&r.from, StateId::S0))
                    .filter_map(|(c, _)| c.clone().map(Formula::Shared))
                    .collect(),
            );
            if matches!(self.prove(&any, &first), Outcome::None) {
                paths[n] = Some(vec![Step::Idle]);
                queue.push_back(n);
            }
        }
        let candidates = self.candidates();
        while let Some(node) = queue.pop_front() {
            let state = node_state(node, n);
            let pinned = self.pinned(node, n, given);
            for e in edges.iter().filter(|e| e.from == node && e.found) {
                if paths[e.to].is_some() {
                    continue;
                }
                let Some(f) = self.fires(e.row, state) else {
                    continue;
                };
                if self.reads_unsure(&f, given) {
                    continue;
                }
                let search = Search::new(&self.terms, Mode::Witness, candidates, &[], &pinned);
                let Outcome::Found(values) = search.run(&f) else {
                    continue;
                };
                let witness = self.witness(&f, state, values);
                let mut path = paths[node].clone().unwrap_or_default();
                path.push(Step::Fire {
                    row: e.row,
                    witness,
                });
                paths[e.to] = Some(path);
                queue.push_back(e.to);
            }
        }
        paths
    }

    /// Whether no row on `path` reads a command parameter through an
    /// opaque atom (one the proof cannot split into cells).
    fn path_by_cells(&self, path: &[Step], n: usize) -> bool {
        let mut by_cells = true;
        let mut node = 0;
        for step in path {
            let Step::Fire { row, .. } = step else {
                node = n;
                continue;
            };
            if let Some(f) = self.fires(*row, node_state(node, n)) {
                f.visit_atoms(&mut |a| {
                    let atom = &self.terms.atoms[a];
                    by_cells &= atom.exact
                        || !atom
                            .leaves
                            .iter()
                            .any(|&l| matches!(self.terms.leaves[l].0, Leaf::Param(..)));
                });
            }
            node = target_node(node, n, self.plan.rows[*row].to).unwrap_or(node);
        }
        by_cells
    }

    /// Whether `f` reads an input the world does not set freely on any
    /// cycle: a var jobs may change (not pinned in `given`), a `writes`
    /// buffer, a cycle counter or a subordinate's `stale_cycles`.
    fn reads_unsure(&self, f: &Formula, given: &Case) -> bool {
        let mut unsure = false;
        f.visit_atoms(&mut |a| {
            for &l in &self.terms.atoms[a].leaves {
                unsure |= match &self.terms.leaves[l].0 {
                    Leaf::Var(..) => !given.iter().any(|(g, _)| *g == l),
                    Leaf::Buffer(b, _) => self.ctrl.writes.contains(b),
                    Leaf::StateCycles
                    | Leaf::PlanCycles
                    | Leaf::SubStale(_)
                    | Leaf::SubErrorCode(_)
                    | Leaf::BufStale(_) => true,
                    Leaf::NewCommand
                    | Leaf::Param(..)
                    | Leaf::Call(..)
                    | Leaf::SubStatus(_)
                    | Leaf::SubField(..) => false,
                };
            }
        });
        unsure
    }
}

/// The state of node `node` (node `n` is `S0` after the first cycle).
fn node_state(node: usize, n: usize) -> StateId {
    if node >= n {
        StateId::S0
    } else {
        StateId(node as u32)
    }
}

/// The node a row leads to from `node`; `None` for `Done`, `Error` and a
/// row that stays in the same node.
fn target_node(node: usize, n: usize, to: Target) -> Option<usize> {
    let to = match to {
        Target::State(s) if s == StateId::S0 => n,
        Target::State(s) => s.index(),
        // `same` on the first cycle: S0 again, on a later cycle.
        Target::Same if node == 0 => n,
        Target::Same | Target::Done | Target::Error(_) | Target::ErrorOf(_) => return None,
    };
    (to != node).then_some(to)
}
