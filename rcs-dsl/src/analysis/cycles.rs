//! Stage 3a, over several cycles: what one plan does on consecutive
//! cycles, built from the one-cycle questions of [`PlanAnalysis`]. Two
//! findings come out of it, each with the way there from the entry and the
//! inputs that make it happen: a **livelock** (rows that move between
//! states on every cycle under inputs held constant) and a **command
//! storm** (a row that sends to a subordinate again on the next cycle,
//! while the subordinate is still executing). The checks `livelock` and
//! `command_every_cycle` (`checks/loops.rs`) report them; `tests/loops.rs`
//! replays them on the interpreter — one computation for both.
//!
//! ## Walks from the entry
//!
//! A walk starts with the new command (`S0`, `new_command`, both counters
//! 0) and takes, on each cycle, a row that the analysis shows can fire
//! there (a concrete witness, never "unknown"), with the counters the walk
//! implies: `plan_cycles` is the walk's length, `state_cycles` restarts at
//! 1 on the first cycle in a new state and grows by one on a stay. The
//! command's parameters and the vars no job assigns keep one value along
//! the walk; a subordinate the walk has not commanded yet shows
//! `NOT_READY`, one it has commanded never does; each subordinate writes
//! its status on every cycle (`stale_cycles` 0). Plans whose conditions
//! read vars or buffers that jobs assign are not walked: their values
//! depend on the jobs, which the analysis does not follow.

use super::terms::Leaf;
use super::{covers, Answer, LeafId, PlanAnalysis, Witness};
use crate::ir::{Controller, CtrlId, Job, Plan, Row, StateId, StatusId, Target};
use rcs_runtime::driver::Value;

/// How many cycles a walk takes at most, and how many places it keeps per
/// cycle: plans are small, and past these the answer is "nothing found".
const MAX_DEPTH: usize = 16;
const MAX_WIDTH: usize = 64;
/// How many cycles of states the livelock search looks at per plan.
const MAX_LOOPS: usize = 64;

/// Inputs of a cycle: leaves with their values.
pub type Inputs = Vec<(Leaf, Value)>;

/// One cycle of a walk: the row that fires, the state it fires in, and the
/// inputs of that cycle (the leaves the question read, with their values).
#[derive(Clone, Debug)]
pub struct Step {
    pub row: usize,
    pub state: StateId,
    pub inputs: Vec<(Leaf, Value)>,
}

/// Rows that move the plan round a cycle of states, one per cycle, while
/// the inputs stay the same.
#[derive(Clone, Debug)]
pub struct Livelock {
    /// The rows of the cycle with the state each fires in, from the state
    /// the walk reaches first.
    pub cycle: Vec<(usize, StateId)>,
    /// A row of a state of the cycle that would fire, with the held inputs,
    /// had the plan stayed there: the loop keeps it from ever firing.
    pub defeated: (usize, StateId),
    /// The inputs held during the loop (counters and `new_command` aside).
    pub held: Vec<(Leaf, Value)>,
    /// The same, as the language writes them, for those the rows read.
    pub shown: Vec<(String, String)>,
    /// The command's parameters (those the conditions read).
    pub params: Vec<(Leaf, Value)>,
    /// The way from the entry to the first state of `cycle`.
    pub path: Vec<Step>,
}

/// A row that sends a command on consecutive cycles while the subordinate
/// shows `EXECUTING`.
#[derive(Clone, Debug)]
pub struct CommandStorm {
    pub row: usize,
    pub sub: CtrlId,
    /// The way from the entry; its last step is the row's first send.
    pub path: Vec<Step>,
    /// The state the row fires in again, twice, under `repeat`.
    pub state: StateId,
    /// The inputs of the two repeats (`sub`'s status `EXECUTING`).
    pub repeat: Vec<(Leaf, Value)>,
    pub shown: Vec<(String, String)>,
    pub params: Vec<(Leaf, Value)>,
}

/// Where a walk stands at the start of a cycle.
#[derive(Clone)]
struct Place {
    state: StateId,
    state_cycles: u32,
    plan_cycles: u32,
    /// Parameters fixed by the walk so far.
    pinned: Vec<(LeafId, Value)>,
    /// Subordinates commanded so far, in order.
    sent: Vec<CtrlId>,
    path: Vec<Step>,
}

/// The plan and what stays fixed over every walk of it.
struct Walker<'a, 'ir> {
    plan: &'a Plan,
    an: &'a PlanAnalysis<'ir>,
    /// Per subordinate whose status the conditions read: its leaf.
    statuses: Vec<(CtrlId, LeafId)>,
    /// Leaves pinned on every cycle: vars no job assigns, `stale_cycles` 0.
    constant: Vec<(LeafId, Value)>,
    counters: [Option<LeafId>; 3],
}

impl<'a, 'ir> Walker<'a, 'ir> {
    /// `None` when the conditions read something jobs change.
    fn new(ctrl: &Controller, plan: &'a Plan, an: &'a PlanAnalysis<'ir>) -> Option<Self> {
        let constant_vars = an.constant_vars();
        let mut statuses = Vec::new();
        let mut constant = constant_vars.clone();
        for (id, (leaf, _)) in an.terms().leaves.iter().enumerate() {
            match leaf {
                Leaf::Var(..) if !constant_vars.iter().any(|(l, _)| *l == id) => return None,
                Leaf::Buffer(b, _) if ctrl.writes.contains(b) => return None,
                Leaf::SubStatus(x) => statuses.push((*x, id)),
                Leaf::SubStale(_) => constant.push((id, Value::Int(0))),
                _ => {}
            }
        }
        let find = |l: Leaf| an.terms().find(&l);
        let counters = [
            find(Leaf::NewCommand),
            find(Leaf::StateCycles),
            find(Leaf::PlanCycles),
        ];
        Some(Walker {
            plan,
            an,
            statuses,
            constant,
            counters,
        })
    }

    /// The leaves pinned on a cycle: the counters, the constants, the
    /// walk's parameters and the subordinates not commanded yet.
    fn pins(&self, state_cycles: u32, plan_cycles: u32, at: &Place) -> Vec<(LeafId, Value)> {
        let mut pins = self.counter_pins(state_cycles, plan_cycles);
        pins.extend(self.constant.iter().cloned());
        pins.extend(at.pinned.iter().cloned());
        for (x, leaf) in &self.statuses {
            if !at.sent.contains(x) {
                pins.push((*leaf, Value::Status(StatusId::NOT_READY.0 as u16)));
            }
        }
        pins
    }

    fn counter_pins(&self, state_cycles: u32, plan_cycles: u32) -> Vec<(LeafId, Value)> {
        let values = [
            Value::Bool(plan_cycles == 0),
            Value::Int(state_cycles as i128),
            Value::Int(plan_cycles as i128),
        ];
        self.counters
            .iter()
            .zip(values)
            .filter_map(|(l, v)| l.map(|l| (l, v)))
            .collect()
    }

    /// A witness that `row` fires in `state` with `pins`, in which no
    /// subordinate in `sent` shows `NOT_READY` (it has answered, or the
    /// handshake shows it `EXECUTING`).
    fn fire(
        &self,
        row: usize,
        state: StateId,
        pins: &[(LeafId, Value)],
        sent: &[CtrlId],
    ) -> Option<Witness> {
        let mut pins = pins.to_vec();
        let mut w = can(self.an.can_fire_in_given(row, state, &pins))?;
        for (_, leaf) in self.statuses.iter().filter(|(x, _)| sent.contains(x)) {
            if value_of(self.an, &w.inputs, *leaf) != Some(&not_ready()) {
                continue;
            }
            let answered = self.an.cell_values(*leaf).iter().find_map(|v| {
                if *v == not_ready() {
                    return None;
                }
                let mut tried = pins.clone();
                tried.push((*leaf, v.clone()));
                can(self.an.can_fire_in_given(row, state, &tried)).map(|w| (tried, w))
            })?;
            (pins, w) = answered;
        }
        Some(w)
    }

    /// Every place walks from the entry reach, by cycle, a few per cycle.
    fn walk(&self, pinned: Vec<(LeafId, Value)>) -> Vec<Place> {
        let mut layer = vec![Place {
            state: StateId::S0,
            state_cycles: 0,
            plan_cycles: 0,
            pinned,
            sent: Vec::new(),
            path: Vec::new(),
        }];
        let mut all = layer.clone();
        let depth = (self.plan.states.len() + 2).min(MAX_DEPTH);
        for _ in 0..depth {
            let mut next: Vec<Place> = Vec::new();
            for at in &layer {
                for (i, row) in self.plan.rows.iter().enumerate() {
                    if next.len() >= MAX_WIDTH {
                        break;
                    }
                    if !covers(&row.from, at.state) || self.an.never_fires_in(i, at.state) {
                        continue;
                    }
                    let Some(state) = target_state(row, at.state) else {
                        continue;
                    };
                    let pins = self.pins(at.state_cycles, at.plan_cycles, at);
                    let Some(w) = self.fire(i, at.state, &pins, &at.sent) else {
                        continue;
                    };
                    let mut to = at.clone();
                    to.state = state;
                    to.state_cycles = if state == at.state {
                        at.state_cycles.saturating_add(1)
                    } else {
                        1
                    };
                    to.plan_cycles += 1;
                    for l in self.an.command_leaves() {
                        if let (Some(v), false) = (
                            value_of(self.an, &w.inputs, l),
                            to.pinned.iter().any(|(p, _)| *p == l),
                        ) {
                            to.pinned.push((l, v.clone()));
                        }
                    }
                    for x in sends(row) {
                        if !to.sent.contains(&x) {
                            to.sent.push(x);
                        }
                    }
                    to.path.push(Step {
                        row: i,
                        state: at.state,
                        inputs: w.inputs,
                    });
                    let same = |p: &Place| {
                        p.state == to.state
                            && p.state_cycles == to.state_cycles
                            && p.sent == to.sent
                            && p.path.last().map(|s| s.row) == Some(i)
                    };
                    if !next.iter().any(same) {
                        next.push(to);
                    }
                }
            }
            all.extend(next.iter().cloned());
            layer = next;
        }
        all
    }

    /// The leaves of `pinned` as leaves, for the caller to replay.
    fn params(&self, pinned: &[(LeafId, Value)]) -> Vec<(Leaf, Value)> {
        pinned
            .iter()
            .map(|(l, v)| (self.an.terms().leaves[*l].0.clone(), v.clone()))
            .collect()
    }
}

/// The livelocks of one plan, each reachable from the entry.
pub fn livelocks(ctrl: &Controller, plan: &Plan, an: &PlanAnalysis) -> Vec<Livelock> {
    let Some(walker) = Walker::new(ctrl, plan, an) else {
        return Vec::new();
    };
    // `plan_cycles` keeps growing round the loop: the rows must fire for
    // every value, which its cells decide, unless an opaque atom reads it.
    let plan_cycles = walker.counters[2];
    let terms = an.terms();
    if terms
        .atoms
        .iter()
        .any(|a| !a.exact && plan_cycles.is_some_and(|pc| a.leaves.contains(&pc)))
    {
        return Vec::new();
    }
    let plan_cycle_values: Vec<u32> = match plan_cycles {
        Some(pc) => {
            let mut vs: Vec<u32> = an
                .cell_values(pc)
                .iter()
                .filter_map(|v| match v {
                    Value::Int(i) => Some((*i).clamp(1, u32::MAX as i128) as u32),
                    _ => None,
                })
                .collect();
            vs.sort_unstable();
            vs.dedup();
            vs
        }
        None => vec![1],
    };
    let mut found = Vec::new();
    for cycle in state_cycles_of(plan, an) {
        // Sending to a subordinate whose status the rows read changes what
        // they read (the handshake shows it EXECUTING): not constant.
        if cycle.iter().any(|(r, _)| {
            sends(&plan.rows[*r]).any(|x| walker.statuses.iter().any(|(s, _)| *s == x))
        }) {
            continue;
        }
        let Some(first) = plan_cycle_values.first() else {
            continue;
        };
        let mut pins = walker.counter_pins(1, *first);
        pins.extend(walker.constant.iter().cloned());
        let Some(w) = can(an.can_fire_all_given(&cycle, &pins)) else {
            continue;
        };
        let held: Vec<(Leaf, Value)> = w
            .inputs
            .iter()
            .filter(|(l, _)| !is_counter(l))
            .cloned()
            .collect();
        let held_pins: Vec<(LeafId, Value)> = held
            .iter()
            .filter_map(|(l, v)| terms.find(l).map(|id| (id, v.clone())))
            .collect();
        let holds_for = |pc: u32| {
            cycle.iter().all(|&(r, s)| {
                let mut pins = walker.counter_pins(1, pc);
                pins.extend(held_pins.iter().cloned());
                can(an.can_fire_in_given(r, s, &pins)).is_some()
            })
        };
        if !plan_cycle_values.iter().all(|pc| holds_for(*pc)) {
            continue;
        }
        // A loop is a fault when it keeps another row from firing: one that
        // would fire, with the same inputs, had the plan stayed in the
        // state (a timeout). The inputs that row reads and the loop does
        // not are held too.
        let Some((defeated, extra)) = defeated_row(an, plan, &cycle, &held_pins) else {
            continue;
        };
        let mut held = held;
        for (l, v) in extra.into_iter().filter(|(l, _)| !is_counter(l)) {
            if terms
                .find(&l)
                .is_some_and(|id| value_of(an, &held, id).is_none())
            {
                held.push((l, v));
            }
        }
        // Reach the loop with the same parameters, on a first cycle in one
        // of its states, having commanded exactly the subordinates that the
        // held statuses say have answered.
        let params: Vec<(LeafId, Value)> = an
            .command_leaves()
            .into_iter()
            .filter_map(|l| value_of(an, &held, l).map(|v| (l, v.clone())))
            .collect();
        let consistent = |at: &Place| {
            walker
                .statuses
                .iter()
                .all(|(x, leaf)| match value_of(an, &held, *leaf) {
                    None => true,
                    Some(v) => (*v == not_ready()) != at.sent.contains(x),
                })
        };
        let entry = walker.walk(params).into_iter().find(|at| {
            at.state_cycles == 1 && cycle.iter().any(|(_, s)| *s == at.state) && consistent(at)
        });
        let Some(at) = entry else { continue };
        let start = cycle.iter().position(|(_, s)| *s == at.state).unwrap_or(0);
        let mut cycle = cycle;
        cycle.rotate_left(start);
        let shown = w
            .shown
            .iter()
            .filter(|(n, _)| !matches!(n.as_str(), "new_command" | "state_cycles" | "plan_cycles"))
            .cloned()
            .collect();
        found.push(Livelock {
            defeated,
            cycle,
            held,
            shown,
            params: walker.params(&at.pinned),
            path: at.path,
        });
    }
    found
}

/// The command storms of one plan: per row and subordinate, the first one
/// a walk from the entry finds.
pub fn command_storms(ctrl: &Controller, plan: &Plan, an: &PlanAnalysis) -> Vec<CommandStorm> {
    let candidates: Vec<usize> = (0..plan.rows.len())
        .filter(|&i| sends(&plan.rows[i]).next().is_some())
        .collect();
    if candidates.is_empty() {
        return Vec::new();
    }
    let Some(walker) = Walker::new(ctrl, plan, an) else {
        return Vec::new();
    };
    let mut found: Vec<CommandStorm> = Vec::new();
    for at in walker.walk(Vec::new()) {
        let Some(last) = at.path.last() else { continue };
        let (row, r) = (last.row, &plan.rows[last.row]);
        if !candidates.contains(&row) || !covers(&r.from, at.state) {
            continue;
        }
        for x in sends(r) {
            if found.iter().any(|f| f.row == row && f.sub == x) {
                continue;
            }
            if let Some(storm) = storm_after(&walker, &at, row, x) {
                found.push(storm);
            }
        }
    }
    found.sort_by_key(|f| (f.row, f.sub));
    found
}

/// Whether `row`, which just sent to `x` and left the walk at `at`, fires
/// again at `at` and on the cycle after, under one set of inputs in which
/// `x` shows `EXECUTING`.
fn storm_after(walker: &Walker, at: &Place, row: usize, x: CtrlId) -> Option<CommandStorm> {
    let an = walker.an;
    let executing = Value::Status(StatusId::EXECUTING.0 as u16);
    let mut pins = walker.pins(at.state_cycles, at.plan_cycles, at);
    let x_leaf = walker
        .statuses
        .iter()
        .find(|(s, _)| *s == x)
        .map(|(_, l)| *l);
    if let Some(l) = x_leaf {
        pins.push((l, executing.clone()));
    }
    let w = walker.fire(row, at.state, &pins, &at.sent)?;
    let state = target_state(&walker.plan.rows[row], at.state)?;
    if state != at.state {
        // The row moved the plan on: the next firing is in another state,
        // which the walk from there covers.
        return None;
    }
    let repeat: Vec<(Leaf, Value)> = w
        .inputs
        .iter()
        .filter(|(l, _)| !is_counter(l))
        .cloned()
        .collect();
    let mut again = walker.counter_pins(at.state_cycles.saturating_add(1), at.plan_cycles + 1);
    again.extend(
        repeat
            .iter()
            .filter_map(|(l, v)| an.terms().find(l).map(|id| (id, v.clone()))),
    );
    can(an.can_fire_in_given(row, state, &again))?;
    let mut shown: Vec<(String, String)> = w
        .shown
        .iter()
        .filter(|(n, _)| !matches!(n.as_str(), "new_command" | "state_cycles" | "plan_cycles"))
        .cloned()
        .collect();
    let x_name = an.leaf_name(&Leaf::SubStatus(x));
    if !shown.iter().any(|(n, _)| *n == x_name) {
        shown.push((x_name, "EXECUTING".into()));
    }
    Some(CommandStorm {
        row,
        sub: x,
        path: at.path.clone(),
        state,
        repeat,
        shown,
        params: walker.params(&at.pinned),
    })
}

/// The first row, in a state of `cycle`, other than the cycle's row there,
/// that can fire in that state with `held` pinned and the counters free,
/// with the inputs of such a cycle.
fn defeated_row(
    an: &PlanAnalysis,
    plan: &Plan,
    cycle: &[(usize, StateId)],
    held: &[(LeafId, Value)],
) -> Option<((usize, StateId), Inputs)> {
    let new_command = an.terms().find(&Leaf::NewCommand);
    for &(looping, state) in cycle {
        for (i, row) in plan.rows.iter().enumerate() {
            if i == looping || !covers(&row.from, state) {
                continue;
            }
            let mut pins = held.to_vec();
            pins.extend(new_command.map(|l| (l, Value::Bool(false))));
            if let Some(w) = can(an.can_fire_in_given(i, state, &pins)) {
                return Some(((i, state), w.inputs));
            }
        }
    }
    None
}

/// The cycles of states that rows moving to another state form, each once
/// (from its lowest state), as (row, state it fires in).
fn state_cycles_of(plan: &Plan, an: &PlanAnalysis) -> Vec<Vec<(usize, StateId)>> {
    let n = plan.states.len();
    let mut edges: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    for (i, row) in plan.rows.iter().enumerate() {
        let Target::State(t) = row.to else { continue };
        for (s, out) in edges.iter_mut().enumerate() {
            let state = StateId(s as u32);
            if s != t.index() && covers(&row.from, state) && !an.never_fires_in(i, state) {
                out.push((i, t.index()));
            }
        }
    }
    let mut cycles = Vec::new();
    for start in 0..n {
        let mut path: Vec<(usize, StateId)> = Vec::new();
        extend_cycles(&edges, start, start, &mut path, &mut cycles);
    }
    cycles
}

fn extend_cycles(
    edges: &[Vec<(usize, usize)>],
    start: usize,
    at: usize,
    path: &mut Vec<(usize, StateId)>,
    cycles: &mut Vec<Vec<(usize, StateId)>>,
) {
    for &(row, to) in &edges[at] {
        if cycles.len() >= MAX_LOOPS {
            return;
        }
        path.push((row, StateId(at as u32)));
        if to == start {
            cycles.push(path.clone());
        } else if to > start && !path.iter().any(|(_, s)| s.index() == to) {
            extend_cycles(edges, start, to, path, cycles);
        }
        path.pop();
    }
}

/// The state a row leaves the plan in, fired in `from`; `None` for `Done`
/// and `Error`.
fn target_state(row: &Row, from: StateId) -> Option<StateId> {
    match row.to {
        Target::State(t) => Some(t),
        Target::Same => Some(from),
        Target::Done | Target::Error(_) => None,
    }
}

/// The subordinates a row sends to, in order.
fn sends(row: &Row) -> impl Iterator<Item = CtrlId> + '_ {
    row.jobs.iter().filter_map(|j| match j {
        Job::Send { sub, .. } => Some(*sub),
        _ => None,
    })
}

fn is_counter(leaf: &Leaf) -> bool {
    matches!(
        leaf,
        Leaf::NewCommand | Leaf::StateCycles | Leaf::PlanCycles
    )
}

fn not_ready() -> Value {
    Value::Status(StatusId::NOT_READY.0 as u16)
}

fn can(a: Answer) -> Option<Witness> {
    match a {
        Answer::Can(w) => Some(w),
        Answer::Never | Answer::Unknown => None,
    }
}

/// The value of leaf `id` among `inputs`.
fn value_of<'v>(an: &PlanAnalysis, inputs: &'v [(Leaf, Value)], id: LeafId) -> Option<&'v Value> {
    inputs
        .iter()
        .find(|(l, _)| an.terms().find(l) == Some(id))
        .map(|(_, v)| v)
}
