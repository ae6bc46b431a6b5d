//! Stage 3a, over several cycles: walks of one plan from its entry, cycle
//! by cycle, along rows the one-cycle questions of [`PlanAnalysis`] show
//! can fire. [`super::cycles`] builds its findings on them.
//!
//! A walk starts with the new command (`S0`, `new_command`, both counters
//! 0) and takes, on each cycle, a row that the analysis shows can fire
//! there, or a wait (a cycle on which no row matches) — each shown by a
//! concrete witness, never "unknown" — with the counters the walk implies:
//! `plan_cycles` is the walk's length, `state_cycles` restarts at 1 on the
//! first cycle in a new state and grows by one on a stay. The
//! command's parameters and the vars no job assigns keep one value along
//! the walk; a subordinate the walk has not commanded yet shows
//! `NOT_READY`, one it has commanded never does; each subordinate writes
//! its status on every cycle (`stale_cycles` 0). Plans whose conditions
//! read vars or buffers that jobs assign are not walked: their values
//! depend on the jobs, which the analysis does not follow.

use super::terms::Leaf;
use super::{covers, Answer, LeafId, PlanAnalysis, Witness};
use crate::ir::{Controller, CtrlId, Plan, Row, StateId, StatusId, Target};
use rcs_runtime::driver::Value;

/// How many cycles a walk takes at most, and how many places it keeps per
/// cycle: plans are small, and past these the answer is "nothing found".
const MAX_DEPTH: usize = 24;
const MAX_WIDTH: usize = 64;

/// Inputs of a cycle: leaves with their values.
pub type Inputs = Vec<(Leaf, Value)>;

/// A witness's inputs without the counters and `new_command`: what stays
/// the same from one cycle to the next.
pub(super) struct Held {
    pub inputs: Inputs,
    /// The same, by leaf id, to pin them.
    pub pins: Vec<(LeafId, Value)>,
    /// Those the question read, as the language writes them.
    pub shown: Vec<(String, String)>,
}

impl Held {
    pub(super) fn of(an: &PlanAnalysis, w: &Witness) -> Held {
        let inputs: Inputs = w
            .inputs
            .iter()
            .filter(|(l, _)| !is_counter(l))
            .cloned()
            .collect();
        let pins = inputs
            .iter()
            .filter_map(|(l, v)| an.terms().find(l).map(|id| (id, v.clone())))
            .collect();
        let shown = w
            .shown
            .iter()
            .filter(|(n, _)| !matches!(n.as_str(), "new_command" | "state_cycles" | "plan_cycles"))
            .cloned()
            .collect();
        Held {
            inputs,
            pins,
            shown,
        }
    }

    /// Add the inputs of `w` that are not held yet.
    pub(super) fn extend(&mut self, an: &PlanAnalysis, w: &Witness) {
        let more = Held::of(an, w);
        for (leaf, v) in more.inputs {
            let Some(id) = an.terms().find(&leaf) else {
                continue;
            };
            if !self.pins.iter().any(|(p, _)| *p == id) {
                self.pins.push((id, v.clone()));
                self.inputs.push((leaf, v));
            }
        }
        for (name, v) in more.shown {
            if !self.shown.iter().any(|(n, _)| *n == name) {
                self.shown.push((name, v));
            }
        }
    }
}

/// One cycle of a walk: the row that fires (`None`: none does, the plan
/// waits), the state it fires in, and the inputs of that cycle (the leaves
/// the question read, with their values).
#[derive(Clone, Debug)]
pub struct Step {
    pub row: Option<usize>,
    pub state: StateId,
    pub inputs: Vec<(Leaf, Value)>,
}

/// Where a walk stands at the start of a cycle.
#[derive(Clone)]
pub(super) struct Place {
    pub(super) state: StateId,
    pub(super) state_cycles: u32,
    pub(super) plan_cycles: u32,
    /// Parameters fixed by the walk so far.
    pub(super) pinned: Vec<(LeafId, Value)>,
    /// Subordinates commanded so far, in order.
    pub(super) sent: Vec<CtrlId>,
    pub(super) path: Vec<Step>,
}

/// The plan and what stays fixed over every walk of it.
pub(super) struct Walker<'a, 'ir> {
    pub(super) plan: &'a Plan,
    pub(super) an: &'a PlanAnalysis<'ir>,
    /// Per subordinate whose status the conditions read: its leaf.
    pub(super) statuses: Vec<(CtrlId, LeafId)>,
    /// Leaves pinned on every cycle: vars no job assigns, `stale_cycles` 0.
    pub(super) constant: Vec<(LeafId, Value)>,
    pub(super) counters: [Option<LeafId>; 3],
}

impl<'a, 'ir> Walker<'a, 'ir> {
    /// `None` when the conditions read something jobs change.
    pub(super) fn new(
        ctrl: &Controller,
        plan: &'a Plan,
        an: &'a PlanAnalysis<'ir>,
    ) -> Option<Self> {
        let (walker, constant) = Self::build(ctrl, plan, an);
        constant.then_some(walker)
    }

    /// [`new`](Self::new) for a plan whose conditions read vars or `writes`
    /// buffers that jobs change: those are left out of
    /// [`constant`](Self::constant), for the caller to pin from a run
    /// (`rings.rs`). Not for walks: [`step`](Self::step) would leave them
    /// free.
    pub(super) fn lenient(ctrl: &Controller, plan: &'a Plan, an: &'a PlanAnalysis<'ir>) -> Self {
        Self::build(ctrl, plan, an).0
    }

    /// The walker, and whether every var and buffer the conditions read
    /// keeps one value over a command (no job assigns it).
    fn build(ctrl: &Controller, plan: &'a Plan, an: &'a PlanAnalysis<'ir>) -> (Self, bool) {
        let mut all_constant = true;
        let constant_vars = an.constant_vars();
        let mut statuses = Vec::new();
        let mut constant = constant_vars.clone();
        for (id, (leaf, _)) in an.terms().leaves.iter().enumerate() {
            match leaf {
                Leaf::Var(..) if !constant_vars.iter().any(|(l, _)| *l == id) => {
                    all_constant = false
                }
                Leaf::Buffer(b, _) if ctrl.writes.contains(b) => all_constant = false,
                Leaf::SubStatus(x) => statuses.push((*x, id)),
                // Every status and `reads` buffer is written each cycle
                // in the runs the walk builds: never stale.
                Leaf::SubStale(_) | Leaf::BufStale(_) => constant.push((id, Value::Int(0))),
                _ => {}
            }
        }
        let find = |l: Leaf| an.terms().find(&l);
        let counters = [
            find(Leaf::NewCommand),
            find(Leaf::StateCycles),
            find(Leaf::PlanCycles),
        ];
        let walker = Walker {
            plan,
            an,
            statuses,
            constant,
            counters,
        };
        (walker, all_constant)
    }

    /// The leaves pinned on a cycle: the counters, the constants, the
    /// walk's parameters and the subordinates not commanded yet.
    pub(super) fn pins(
        &self,
        state_cycles: u32,
        plan_cycles: u32,
        at: &Place,
    ) -> Vec<(LeafId, Value)> {
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

    pub(super) fn counter_pins(&self, state_cycles: u32, plan_cycles: u32) -> Vec<(LeafId, Value)> {
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
    pub(super) fn fire(
        &self,
        row: usize,
        state: StateId,
        pins: &[(LeafId, Value)],
        sent: &[CtrlId],
    ) -> Option<Witness> {
        self.answered(pins, sent, |pins| {
            self.an.can_fire_in_given(row, state, pins)
        })
    }

    /// A witness of `ask` with `pins`, in which no subordinate in `sent`
    /// shows `NOT_READY`: each one that does is tried at its other values.
    fn answered(
        &self,
        pins: &[(LeafId, Value)],
        sent: &[CtrlId],
        ask: impl Fn(&[(LeafId, Value)]) -> Answer,
    ) -> Option<Witness> {
        let mut pins = pins.to_vec();
        let mut w = can(ask(&pins))?;
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
                can(ask(&tried)).map(|w| (tried, w))
            })?;
            (pins, w) = answered;
        }
        Some(w)
    }

    /// Every place walks from the entry reach, by cycle, a few per cycle.
    pub(super) fn walk(&self, pinned: Vec<(LeafId, Value)>) -> Vec<Place> {
        self.walk_until(pinned, &|_| false).0
    }

    /// The first place of [`walk`](Self::walk)'s, in its order, that
    /// `stop` accepts, without walking further than it.
    pub(super) fn first(
        &self,
        pinned: Vec<(LeafId, Value)>,
        stop: &dyn Fn(&Place) -> bool,
    ) -> Option<Place> {
        self.walk_until(pinned, stop).1
    }

    /// The places of a walk, layer by layer, up to the first that `stop`
    /// accepts (returned beside them).
    fn walk_until(
        &self,
        pinned: Vec<(LeafId, Value)>,
        stop: &dyn Fn(&Place) -> bool,
    ) -> (Vec<Place>, Option<Place>) {
        let mut layer = vec![Place {
            state: StateId::S0,
            state_cycles: 0,
            plan_cycles: 0,
            pinned,
            sent: Vec::new(),
            path: Vec::new(),
        }];
        if stop(&layer[0]) {
            return (Vec::new(), layer.pop());
        }
        let mut all = layer.clone();
        for _ in 0..self.depth() {
            let mut next: Vec<Place> = Vec::new();
            for at in &layer {
                let moves = (0..self.plan.rows.len()).map(Some).chain([None]);
                for row in moves {
                    if next.len() >= MAX_WIDTH {
                        break;
                    }
                    let Some(to) = self.step(at, row) else {
                        continue;
                    };
                    let same = |p: &Place| {
                        p.state == to.state
                            && p.state_cycles == to.state_cycles
                            && p.sent == to.sent
                            && p.path.last().map(|s| s.row) == Some(row)
                    };
                    if !next.iter().any(same) {
                        if stop(&to) {
                            return (all, Some(to));
                        }
                        next.push(to);
                    }
                }
            }
            all.extend(next.iter().cloned());
            layer = next;
        }
        (all, None)
    }

    /// How many cycles walks take: enough to visit every state and to wait
    /// past the largest `state_cycles` constant, within [`MAX_DEPTH`].
    fn depth(&self) -> usize {
        let longest_wait = self.counters[1].map_or(0, |sc| {
            self.an
                .cell_values(sc)
                .iter()
                .filter_map(|v| match v {
                    Value::Int(i) => usize::try_from(*i).ok(),
                    _ => None,
                })
                .max()
                .unwrap_or(0)
        });
        (self.plan.states.len() + 2)
            .saturating_add(longest_wait)
            .min(MAX_DEPTH)
    }

    /// Where one cycle from `at` leads: row `row` fires, or (`None`) no
    /// row does and the plan waits. `None` when the analysis cannot show
    /// it happening.
    fn step(&self, at: &Place, row: Option<usize>) -> Option<Place> {
        let pins = self.pins(at.state_cycles, at.plan_cycles, at);
        let (state, w) = match row {
            Some(i) => {
                let r = &self.plan.rows[i];
                if !covers(&r.from, at.state) || self.an.never_fires_in(i, at.state) {
                    return None;
                }
                let state = target_state(r, at.state)?;
                (state, self.fire(i, at.state, &pins, &at.sent)?)
            }
            None => {
                let idle = |pins: &[(LeafId, Value)]| self.an.can_idle_given(at.state, pins);
                (at.state, self.answered(&pins, &at.sent, idle)?)
            }
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
        if let Some(i) = row {
            for x in sends(&self.plan.rows[i]) {
                if !to.sent.contains(&x) {
                    to.sent.push(x);
                }
            }
        }
        to.path.push(Step {
            row,
            state: at.state,
            inputs: w.inputs,
        });
        Some(to)
    }

    /// The leaves of `pinned` as leaves, for the caller to replay.
    pub(super) fn params(&self, pinned: &[(LeafId, Value)]) -> Vec<(Leaf, Value)> {
        pinned
            .iter()
            .map(|(l, v)| (self.an.terms().leaves[*l].0.clone(), v.clone()))
            .collect()
    }
}

/// The state a row leaves the plan in, fired in `from`; `None` for `Done`
/// and `Error`.
pub(super) fn target_state(row: &Row, from: StateId) -> Option<StateId> {
    match row.to {
        Target::State(t) => Some(t),
        Target::Same => Some(from),
        Target::Done | Target::Error(_) | Target::ErrorOf(_) => None,
    }
}

/// The subordinates a row sends to, in order.
pub(super) fn sends(row: &Row) -> impl Iterator<Item = CtrlId> + '_ {
    row.jobs
        .iter()
        .filter_map(|j| j.sends_to().map(|(sub, _)| sub))
}

pub(super) fn is_counter(leaf: &Leaf) -> bool {
    matches!(
        leaf,
        Leaf::NewCommand | Leaf::StateCycles | Leaf::PlanCycles
    )
}

pub(super) fn not_ready() -> Value {
    Value::Status(StatusId::NOT_READY.0 as u16)
}

pub(super) fn can(a: Answer) -> Option<Witness> {
    match a {
        Answer::Can(w) => Some(w),
        Answer::Never | Answer::Unknown => None,
    }
}

/// The value of leaf `id` among `inputs`.
pub(super) fn value_of<'v>(
    an: &PlanAnalysis,
    inputs: &'v [(Leaf, Value)],
    id: LeafId,
) -> Option<&'v Value> {
    inputs
        .iter()
        .find(|(l, _)| an.terms().find(l) == Some(id))
        .map(|(_, v)| v)
}

/// Whether `row` fires in `state` on the `pins` alone: a witness that
/// needs no other input. A held set of inputs that leaves some leaf open
/// must not lean on a value the search would pick for it.
pub(super) fn fires_on(
    an: &PlanAnalysis,
    row: usize,
    state: StateId,
    pins: &[(LeafId, Value)],
) -> bool {
    can(an.can_fire_in_given(row, state, pins)).is_some_and(|w| {
        w.inputs.iter().all(|(l, _)| {
            is_counter(l)
                || an
                    .terms()
                    .find(l)
                    .is_some_and(|id| pins.iter().any(|(p, _)| *p == id))
        })
    })
}
