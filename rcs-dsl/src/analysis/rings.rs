//! Stage 3a, over several cycles: what the livelock search of
//! [`super::cycles`] decides about one ring of states beyond a walk from
//! the entry.
//!
//! - **The held inputs** ([`ring_inputs`]): one set of inputs under which
//!   every row of the ring fires, in its state, on the first cycle there,
//!   whatever `plan_cycles` is by then.
//! - **A ring through a subordinate** ([`through`]): a row of the ring
//!   sends X a command and the rows read X's status. What X shows is then
//!   certain on one cycle only: the cycle after a send, when X runs at most
//!   once between two cycles of its supervisor (the same CPU, or a slower
//!   one) and X's plan for that verb cannot answer on a command's first
//!   cycle ([`Fresh`]) — X is `EXECUTING` there (or, not run yet, seen
//!   `EXECUTING` through the handshake). On every other cycle of the ring
//!   X may show anything but `NOT_READY`, so the row firing there must
//!   fire whatever X shows. A subordinate that can answer at once, or runs
//!   faster than its supervisor, is not modelled: no finding.
//! - **A ring in a plan whose conditions read vars that jobs change**
//!   ([`path_ring`]): the walker does not follow such plans, so the ring is
//!   reached by a replayed run from the entry (`path.rs`), whose end gives
//!   the vars their values; the ring keeps them if neither its rows' jobs
//!   nor `pre`/`post` assign a var (or `writes` buffer) that a row of its
//!   states reads. Where one does (a counter the ring steps and reads), the
//!   values change round the ring and nothing is said.
//!
//! A finding of either new kind is made only with its run replayed on the
//! interpreter ([`super::cycles::livelocks`]).

use super::run::{Expect, Firing, Run};
use super::terms::Leaf;
use super::walk::{can, fires_on, is_counter, not_ready, sends, value_of, Held, Walker};
use super::{covers, LeafId, PlanAnalysis, Witness};
use crate::ir::{
    CommandId, Condition, Controller, CtrlId, Expr, ExprKind, Ir, Job, PlaceRoot, Plan, StateId,
    StatusId, Target,
};
use rcs_runtime::driver::{Driven as _, Value};
use std::cell::RefCell;

/// Whether a command to a subordinate surely shows it `EXECUTING` on the
/// supervisor's next cycle, per (subordinate, verb), worked out once.
pub(super) struct Fresh<'ir> {
    ir: &'ir Ir,
    sup: Option<CtrlId>,
    known: RefCell<Vec<((CtrlId, CommandId), bool)>>,
}

impl<'ir> Fresh<'ir> {
    pub(super) fn new(an: &PlanAnalysis<'ir>) -> Fresh<'ir> {
        Fresh {
            ir: an.ir,
            sup: an.ctrl_id(),
            known: RefCell::new(Vec::new()),
        }
    }

    fn shows_executing(&self, x: CtrlId, verb: CommandId) -> bool {
        if let Some((_, v)) = self.known.borrow().iter().find(|(k, _)| *k == (x, verb)) {
            return *v;
        }
        let v = self
            .sup
            .is_some_and(|sup| shows_executing_after_send(self.ir, sup, x, verb));
        self.known.borrow_mut().push(((x, verb), v));
        v
    }
}

/// Whether `x`, sent `verb` by `sup`, surely shows `EXECUTING` to `sup` on
/// `sup`'s next cycle: `x` runs at most once between two cycles of `sup`,
/// and its plan for `verb` cannot answer on its first cycle (no `accept
/// when`, no index by a value, no report in `pre`/`post`, and no row that
/// can fire in `S0` ends the plan or reports).
pub fn shows_executing_after_send(ir: &Ir, sup: CtrlId, x: CtrlId, verb: CommandId) -> bool {
    let cpu = |c: CtrlId| ir.schedule.iter().find(|cpu| cpu.order.contains(&c));
    let once = match (cpu(sup), cpu(x)) {
        (Some(a), Some(b)) => std::ptr::eq(a, b) || b.period_ns > a.period_ns,
        _ => false,
    };
    let xc = ir.controller(x);
    let Some(command) = xc.commands.get(verb.index()) else {
        return false;
    };
    let Some(pid) = command.plan else {
        return false; // UNKNOWN_COMMAND at once
    };
    if !once || command.accept.is_some() {
        return false;
    }
    let every_cycle: Vec<&Job> = xc.every_cycle_jobs().collect();
    if every_cycle
        .iter()
        .any(|j| matches!(j, Job::Report { .. }) || j.indexes_by_value())
    {
        return false;
    }
    let plan = &xc.plans[pid.index()];
    let an = PlanAnalysis::new(ir, xc, plan);
    if !an.analysed_over_cycles() {
        return false;
    }
    !plan.rows.iter().enumerate().any(|(i, r)| {
        let answers = !matches!(r.to, Target::State(_) | Target::Same)
            || r.jobs.iter().any(|j| matches!(j, Job::Report { .. }));
        answers && covers(&r.from, StateId::S0) && !an.never_fires_in(i, StateId::S0)
    })
}

/// The subordinates a ring goes through: those its rows send to whose
/// status the conditions read, with their status leaf (one at most).
/// `None` when they are not modelled: a send [`Fresh`] cannot vouch for,
/// every-cycle jobs that command one, conditions that read its
/// `stale_cycles`, status fields or error code, or two subordinates.
pub(super) fn through(
    walker: &Walker,
    plan: &Plan,
    ctrl: &Controller,
    cycle: &[(usize, StateId)],
    fresh: &Fresh,
) -> Option<Vec<(CtrlId, LeafId)>> {
    let mut out: Vec<(CtrlId, LeafId)> = Vec::new();
    for &(r, _) in cycle {
        for j in &plan.rows[r].jobs {
            let Some((x, _)) = j.sends_to() else { continue };
            let Some(&(_, leaf)) = walker.statuses.iter().find(|(s, _)| *s == x) else {
                continue;
            };
            if !matches!(j, Job::Send { .. })
                || !j
                    .commands_sent()
                    .iter()
                    .all(|v| fresh.shows_executing(x, *v))
            {
                return None;
            }
            if !out.iter().any(|(y, _)| *y == x) {
                out.push((x, leaf));
            }
        }
    }
    if out.is_empty() {
        return Some(out);
    }
    // Two or more: what each shows on the cycles between would have to be
    // taken together; not modelled.
    if out.len() > 1 {
        return None;
    }
    // Every-cycle jobs that command it too: not modelled.
    let every_cycle_sends = ctrl.every_cycle_jobs().any(|j| {
        j.sends_to()
            .is_some_and(|(x, _)| out.iter().any(|(y, _)| *y == x))
    });
    let other_reads = walker.an.terms().leaves.iter().any(|(l, _)| match l {
        Leaf::SubStale(x) | Leaf::SubErrorCode(x) | Leaf::SubField(x, ..) => {
            out.iter().any(|(y, _)| y == x)
        }
        _ => false,
    });
    (!every_cycle_sends && !other_reads).then_some(out)
}

/// Whether `row` fires in `state` with `pins`, whatever `leaf` (a
/// subordinate's status) shows but `NOT_READY`, for every value of
/// `plan_cycles` in `pcs`.
fn fires_whatever(
    walker: &Walker,
    (row, state): (usize, StateId),
    pins: &[(LeafId, Value)],
    leaf: LeafId,
    pcs: &[u32],
) -> bool {
    let an = walker.an;
    an.cell_values(leaf)
        .iter()
        .filter(|v| **v != not_ready())
        .all(|v| {
            pcs.iter().all(|pc| {
                let mut p = walker.counter_pins(1, *pc);
                p.extend(pins.iter().filter(|(l, _)| *l != leaf).cloned());
                p.push((leaf, v.clone()));
                fires_on(an, row, state, &p)
            })
        })
}

/// What each position of a ring through subordinates needs of the cycle
/// before it: per position, whether its row fires whatever every
/// subordinate of `through` shows (then any cycle before will do).
pub(super) fn robust(
    walker: &Walker,
    cycle: &[(usize, StateId)],
    pins: &[(LeafId, Value)],
    through: &[(CtrlId, LeafId)],
    pcs: &[u32],
) -> Vec<bool> {
    cycle
        .iter()
        .map(|&firing| {
            through
                .iter()
                .all(|&(_, leaf)| fires_whatever(walker, firing, pins, leaf, pcs))
        })
        .collect()
}

/// Whether every position of the ring is certain: its row fires whatever
/// the subordinates show, or the row before it (the cycle before) sends
/// to each of them.
pub(super) fn certain_round(
    plan: &Plan,
    cycle: &[(usize, StateId)],
    robust: &[bool],
    through: &[(CtrlId, LeafId)],
) -> bool {
    let n = cycle.len();
    (0..n).all(|k| {
        let before = cycle[(k + n - 1) % n].0;
        robust[k]
            || through
                .iter()
                .all(|(x, _)| sends(&plan.rows[before]).any(|y| y == *x))
    })
}

/// The inputs held round `cycle`: every row fires in its state on the
/// first cycle there with them and `base` pinned, for each value of
/// `plan_cycles` in `pcs`; the subordinates of `through` show `EXECUTING`.
pub(super) fn ring_inputs(
    walker: &Walker,
    cycle: &[(usize, StateId)],
    base: &[(LeafId, Value)],
    pcs: &[u32],
    through: &[(CtrlId, LeafId)],
) -> Option<Held> {
    let an = walker.an;
    let executing = Value::Status(StatusId::EXECUTING.0 as u16);
    let first = pcs.first()?;
    let mut base = base.to_vec();
    for &(_, leaf) in through {
        base.retain(|(l, _)| *l != leaf);
        base.push((leaf, executing.clone()));
    }
    let mut pins = walker.counter_pins(1, *first);
    pins.extend(base.iter().cloned());
    let w = can(an.can_fire_all_given(cycle, &pins))?;
    let mut held = Held::of(an, &w);
    // A leaf the first witness left open may matter at a later value of
    // `plan_cycles`: hold the value the rows need there too.
    for pc in pcs {
        for &(r, s) in cycle {
            let mut pins = walker.counter_pins(1, *pc);
            pins.extend(base.iter().cloned());
            pins.extend(held.pins.iter().cloned());
            if let Some(w) = can(an.can_fire_in_given(r, s, &pins)) {
                held.extend(an, &w);
            }
        }
    }
    // The subordinates' status is part of the run even where no row read
    // it: the replay gives it.
    for &(x, leaf) in through {
        if !held.pins.iter().any(|(l, _)| *l == leaf) {
            held.pins.push((leaf, executing.clone()));
            held.inputs.push((Leaf::SubStatus(x), executing.clone()));
        }
    }
    let holds_for = |pc: u32| {
        cycle.iter().all(|&(r, s)| {
            let mut pins = walker.counter_pins(1, pc);
            pins.extend(base.iter().cloned());
            pins.extend(held.pins.iter().cloned());
            fires_on(an, r, s, &pins)
        })
    };
    pcs.iter().all(|pc| holds_for(*pc)).then_some(held)
}

/// Vars and `writes` buffers that the ring's rows' jobs or `pre`/`post`
/// assign and a row covering a state of the ring reads: values that may
/// change round the ring. Whether there are any.
fn ring_changes_what_it_reads(ctrl: &Controller, plan: &Plan, cycle: &[(usize, StateId)]) -> bool {
    let mut assigned: Vec<PlaceRoot> = Vec::new();
    let jobs = cycle
        .iter()
        .flat_map(|(r, _)| &plan.rows[*r].jobs)
        .chain(ctrl.every_cycle_jobs());
    for j in jobs {
        if let Job::Assign { place, .. } = j {
            assigned.push(place.root);
        }
    }
    if assigned.is_empty() {
        return false;
    }
    plan.rows
        .iter()
        .filter(|r| cycle.iter().any(|(_, s)| covers(&r.from, *s)))
        .any(|r| {
            let Condition::When(c) = &r.cond else {
                return false;
            };
            reads_any(c, &assigned)
        })
}

fn reads_any(e: &Expr, roots: &[PlaceRoot]) -> bool {
    let mut found = false;
    e.visit(&mut |x| match x.kind {
        ExprKind::Var(v) => found |= roots.contains(&PlaceRoot::Var(v)),
        ExprKind::Buffer(b) => found |= roots.contains(&PlaceRoot::Buffer(b)),
        _ => {}
    });
    found
}

/// A ring found by [`path_ring`]: its rows from the state the run reaches,
/// the inputs held, what else the run leaves pinned, and the run there.
pub(super) struct PathRing {
    pub(super) cycle: Vec<(usize, StateId)>,
    pub(super) held: Held,
    /// Vars, `writes` buffers, parameters and `NOT_READY` subordinates as
    /// the run leaves them (they stay so round the ring).
    pub(super) base: Vec<(LeafId, Value)>,
    pub(super) prefix: Run,
}

/// A ring of a plan whose conditions read vars that jobs change, reached
/// by a replayed run from the entry, with the vars as the run leaves them
/// (which the ring keeps). `None` when the ring changes what its rows
/// read, no run reaches it, or no inputs held make it go round.
pub(super) fn path_ring(
    walker: &Walker,
    ctrl: &Controller,
    cycle: &[(usize, StateId)],
    pcs: &[u32],
    paths: &mut Paths,
) -> Option<PathRing> {
    let (an, plan) = (walker.an, walker.plan);
    if ring_changes_what_it_reads(ctrl, plan, cycle) {
        return None;
    }
    // The command's parameters: those of a witness with the vars free.
    let first = pcs.first()?;
    let mut pins = walker.counter_pins(1, *first);
    pins.extend(walker.constant.iter().cloned());
    let w = can(an.can_fire_all_given(cycle, &pins))?;
    let params: Vec<(LeafId, Value)> = an
        .command_leaves()
        .into_iter()
        .filter_map(|l| value_of(an, &w.inputs, l).map(|v| (l, v.clone())))
        .collect();
    // The vars the ring reads may take their values from parameters the
    // rows do not read (`fast = cmd.fast` on entry): other values of each
    // parameter are tried too, a few.
    let mut tries = vec![params.clone()];
    for l in an.command_leaves().into_iter().take(MAX_PARAMS_TRIED) {
        for v in an.cell_values(l).iter().take(MAX_VALUES_TRIED) {
            let mut given: Vec<(LeafId, Value)> =
                params.iter().filter(|(p, _)| *p != l).cloned().collect();
            given.push((l, v.clone()));
            if !tries.contains(&given) {
                tries.push(given);
            }
        }
    }
    tries.iter().find_map(|given| {
        let found = paths.given(an, given)?;
        path_ring_given(walker, cycle, pcs, found)
    })
}

/// How many parameters, and values of each, [`path_ring`] tries.
const MAX_PARAMS_TRIED: usize = 4;
const MAX_VALUES_TRIED: usize = 4;

/// How many path searches (each replays runs on the interpreter) the
/// rings of one plan may ask for: past it, nothing more is said.
const MAX_PATH_SEARCHES: usize = 8;

/// The runs to each state of one plan, per set of parameters pinned,
/// searched once and shared by its rings, within [`MAX_PATH_SEARCHES`].
#[derive(Default)]
pub(super) struct Paths {
    searched: Vec<Searched>,
}

/// The parameters pinned, and per state the run found to it.
type Searched = (Vec<(LeafId, Value)>, Vec<Option<Run>>);

impl Paths {
    fn given(&mut self, an: &PlanAnalysis, params: &[(LeafId, Value)]) -> Option<&[Option<Run>]> {
        let at = match self.searched.iter().position(|(p, _)| p == params) {
            Some(i) => i,
            None if self.searched.len() < MAX_PATH_SEARCHES => {
                self.searched
                    .push((params.to_vec(), an.paths_given(params)));
                self.searched.len() - 1
            }
            None => return None,
        };
        Some(&self.searched[at].1)
    }
}

/// [`path_ring`] with the runs to each state for one set of parameters.
fn path_ring_given(
    walker: &Walker,
    cycle: &[(usize, StateId)],
    pcs: &[u32],
    paths: &[Option<Run>],
) -> Option<PathRing> {
    let an = walker.an;
    let ctrl_id = an.ctrl_id()?;
    for k in 0..cycle.len() {
        let state = cycle[k].1;
        let Some(Some(prefix)) = paths.get(state.index()) else {
            continue;
        };
        if prefix.steps.is_empty() {
            continue;
        }
        let mut ring = cycle.to_vec();
        ring.rotate_left(k);
        // What the run leaves: vars, `writes`, parameters; a subordinate
        // it has not commanded shows `NOT_READY`, one it has never does.
        let Some(after) = an.pins_after(prefix, 0) else {
            continue;
        };
        let mut base: Vec<(LeafId, Value)> = after
            .into_iter()
            .filter(|(l, _)| !is_counter(&an.terms().leaves[*l].0))
            .collect();
        let Ok(mut driven) = super::run::replay_on(an.ir, ctrl_id, prefix) else {
            continue;
        };
        let mut commanded = Vec::new();
        for (x, leaf) in &walker.statuses {
            let name = &an.ir.controller(*x).name;
            if driven.last_sent(name).unwrap_or(0) == 0 {
                base.push((*leaf, not_ready()));
            } else {
                commanded.push(*leaf);
            }
        }
        let Some(held) = ring_inputs(walker, &ring, &base, pcs, &[]) else {
            continue;
        };
        if commanded
            .iter()
            .any(|l| held.pins.iter().any(|(p, v)| p == l && *v == not_ready()))
        {
            continue;
        }
        return Some(PathRing {
            cycle: ring,
            held,
            base,
            prefix: prefix.clone(),
        });
    }
    None
}

/// The run of a ring: `prefix`, then `held` for three rounds, one row of
/// `cycle` per cycle, replayed on the interpreter. `None` when a scenario
/// cannot give the inputs or the replay does not go round.
pub(super) fn ring_run(
    an: &PlanAnalysis,
    prefix: &Run,
    cycle: &[(usize, StateId)],
    held: &[(Leaf, Value)],
) -> Option<Run> {
    let plan = an.plan;
    let rows: Vec<Firing> = cycle
        .iter()
        .map(|&(r, _)| match plan.rows[r].to {
            Target::State(to) => Some(Firing {
                row: super::run::row_name(&plan.rows[r]),
                state: plan.states.get(to.index())?.name.clone(),
            }),
            _ => None,
        })
        .collect::<Option<_>>()?;
    let witness = Witness {
        state: cycle.first()?.1,
        inputs: held.to_vec(),
        shown: Vec::new(),
    };
    let cycles = 3 * rows.len() as u32;
    an.extend(prefix, &witness, cycles, Expect::Repeats { rows })
}
