//! Stage 3a, over several cycles: what one plan does on consecutive
//! cycles, on walks from its entry (`walk.rs`). Two findings come out of
//! it, each with the way there from the entry and the inputs that make it
//! happen: a **livelock** (rows that move between states on every cycle
//! under inputs held constant) and a **command storm** (a row that sends
//! to a subordinate again on the next cycle, while the subordinate is
//! still executing). The checks `livelock` and `command_every_cycle`
//! (`checks/loops.rs`) report them; `tests/loops.rs` replays them on the
//! interpreter — one computation for both.

use super::rings;
use super::run::{self, Expect, Firing, Run};
use super::terms::Leaf;
use super::walk::{
    can, fires_on, is_counter, not_ready, sends, target_state, value_of, Held, Place, Walker,
};
pub use super::walk::{Inputs, Step};
use super::{covers, LeafId, PlanAnalysis};
use crate::ir::{Controller, CtrlId, Plan, StateId, StatusId, Target};
use rcs_runtime::driver::Value;

/// How many cycles of states the livelock search looks at per plan.
const MAX_LOOPS: usize = 64;

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
    /// The way from the entry to the first state of `cycle`, as a walk
    /// (empty for a ring reached by a run: a plan whose conditions read
    /// vars that jobs change).
    pub path: Vec<Step>,
    /// The run, replayed on the interpreter: the way to the ring, then
    /// three times round. Always there for a ring through a subordinate
    /// or reached by a run.
    pub run: Option<Run>,
    /// The subordinates the ring commands and reads the status of: each
    /// shows `EXECUTING` on the cycle after each command.
    pub through: Vec<CtrlId>,
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

/// The livelocks of one plan, each reachable from the entry. A ring
/// through a subordinate the rows poll and command, or in a plan whose
/// conditions read vars that jobs change (`rings.rs`), is found only with
/// its run replayed on the interpreter.
pub fn livelocks(ctrl: &Controller, plan: &Plan, an: &PlanAnalysis) -> Vec<Livelock> {
    if !an.analysed_over_cycles() {
        return Vec::new();
    }
    // No ring of states among the rows that can fire: nothing to walk.
    let rings = state_cycles_of(plan, an);
    if rings.is_empty() {
        return Vec::new();
    }
    // Conditions that read vars jobs change: no walk, a replayed run.
    let (walker, walks) = match Walker::new(ctrl, plan, an) {
        Some(w) => (w, true),
        None => (Walker::lenient(ctrl, plan, an), false),
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
    let fresh = rings::Fresh::new(an);
    let mut paths = rings::Paths::default();
    let mut found = Vec::new();
    for cycle in rings {
        // Sending to a subordinate whose status the rows read changes what
        // they read: only a send after which the handshake surely shows
        // it EXECUTING is modelled.
        let Some(through) = rings::through(&walker, plan, ctrl, &cycle, &fresh) else {
            continue;
        };
        let lock = if walks {
            walked_ring(&walker, plan, cycle, &plan_cycle_values, &through)
        } else if through.is_empty() {
            path_ring(&walker, ctrl, &cycle, &plan_cycle_values, &mut paths)
        } else {
            None
        };
        found.extend(lock);
    }
    found
}

/// A ring reached by a walk from the entry (the plan's conditions read no
/// var a job changes).
fn walked_ring(
    walker: &Walker,
    plan: &Plan,
    cycle: Vec<(usize, StateId)>,
    plan_cycle_values: &[u32],
    through: &[(CtrlId, LeafId)],
) -> Option<Livelock> {
    let an = walker.an;
    let terms = an.terms();
    let Held {
        inputs: held,
        pins: held_pins,
        shown,
    } = rings::ring_inputs(walker, &cycle, &walker.constant, plan_cycle_values, through)?;
    // Through a subordinate: each row fires whatever it shows, or just
    // after a row that commands it (it then surely shows EXECUTING).
    let mut all_pins = walker.constant.clone();
    all_pins.extend(held_pins.iter().cloned());
    let robust = rings::robust(walker, &cycle, &all_pins, through, plan_cycle_values);
    if !rings::certain_round(plan, &cycle, &robust, through) {
        return None;
    }
    // A loop is a fault when it keeps another row from firing: one that
    // would fire, with the same inputs, had the plan stayed in the state
    // (a timeout). The inputs that row reads and the loop does not are
    // held too.
    let (defeated, extra) = defeated_row(an, plan, &cycle, &held_pins)?;
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
    // held statuses say have answered; through a subordinate, on a
    // position whose row fires whatever it shows, or just after a send.
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
    let enters = |at: &Place| {
        let Some(k) = cycle.iter().position(|(_, s)| *s == at.state) else {
            return false;
        };
        let just_sent = at.path.last().and_then(|s| s.row).is_some_and(|r| {
            through
                .iter()
                .all(|(x, _)| sends(&plan.rows[r]).any(|y| y == *x))
        });
        at.state_cycles == 1 && consistent(at) && (robust[k] || just_sent)
    };
    let at = walker.first(params, &enters)?;
    let start = cycle.iter().position(|(_, s)| *s == at.state).unwrap_or(0);
    let mut cycle = cycle;
    cycle.rotate_left(start);
    let params = walker.params(&at.pinned);
    let (first_state, rows) = (cycle[0].1, ring_firings(plan, &cycle));
    let run = rows.and_then(|rows| {
        let cycles = 3 * rows.len() as u32;
        an.finding_run(
            &params,
            first_state,
            &held,
            cycles,
            Expect::Repeats { rows },
        )
    });
    // A ring through a subordinate is a finding only with its run.
    if !through.is_empty() && run.is_none() {
        return None;
    }
    Some(Livelock {
        defeated,
        cycle,
        held,
        shown,
        params,
        path: at.path,
        run,
        through: through.iter().map(|(x, _)| *x).collect(),
    })
}

/// A ring in a plan whose conditions read vars that jobs change: reached
/// by a replayed run, reported only with its run round the ring replayed.
fn path_ring(
    walker: &Walker,
    ctrl: &Controller,
    cycle: &[(usize, StateId)],
    plan_cycle_values: &[u32],
    paths: &mut rings::Paths,
) -> Option<Livelock> {
    let an = walker.an;
    let rings::PathRing {
        cycle,
        held,
        base,
        prefix,
    } = rings::path_ring(walker, ctrl, cycle, plan_cycle_values, paths)?;
    let mut pins = base.clone();
    pins.extend(held.pins.iter().cloned());
    let (defeated, extra) = defeated_row(an, walker.plan, &cycle, &pins)?;
    let Held {
        inputs: mut held,
        shown,
        ..
    } = held;
    for (l, v) in extra.into_iter().filter(|(l, _)| !is_counter(l)) {
        let settable = matches!(l, Leaf::Buffer(..) | Leaf::Call(..) | Leaf::SubStatus(_));
        if settable
            && an
                .terms()
                .find(&l)
                .is_some_and(|id| value_of(an, &held, id).is_none())
        {
            held.push((l, v));
        }
    }
    let run = rings::ring_run(an, &prefix, &cycle, &held)?;
    let params = walker.params(
        &base
            .iter()
            .filter(|(l, _)| an.command_leaves().contains(l))
            .cloned()
            .collect::<Vec<_>>(),
    );
    Some(Livelock {
        defeated,
        cycle,
        held,
        shown,
        params,
        path: Vec::new(),
        run: Some(run),
        through: Vec::new(),
    })
}

/// The rows of a ring as a run names them, with the state each leaves the
/// plan in.
fn ring_firings(plan: &Plan, cycle: &[(usize, StateId)]) -> Option<Vec<Firing>> {
    cycle
        .iter()
        .map(|&(r, _)| match plan.rows[r].to {
            Target::State(to) => Some(Firing {
                row: run::row_name(&plan.rows[r]),
                state: plan.states.get(to.index())?.name.clone(),
            }),
            _ => None,
        })
        .collect()
}

/// The command storms of one plan: per row and subordinate, the first one
/// a walk from the entry finds.
pub fn command_storms(ctrl: &Controller, plan: &Plan, an: &PlanAnalysis) -> Vec<CommandStorm> {
    if !an.analysed_over_cycles() {
        return Vec::new();
    }
    // A row can send on two cycles in a row only if it leaves the plan in
    // a state it covers (`same`, its own state, or any state for a `*`
    // row) and is not an entry row: for the others no walk is needed.
    let candidates: Vec<usize> = (0..plan.rows.len())
        .filter(|&i| {
            let r = &plan.rows[i];
            let stays = match r.to {
                Target::Same => true,
                Target::State(t) => covers(&r.from, t),
                Target::Done | Target::Error(_) | Target::ErrorOf(_) => false,
            };
            // An entry row fires only on the command's first cycle.
            stays && !r.is_entry && sends(r).next().is_some()
        })
        .collect();
    if candidates.is_empty() {
        return Vec::new();
    }
    let Some(walker) = Walker::new(ctrl, plan, an) else {
        return Vec::new();
    };
    let mut found: Vec<CommandStorm> = Vec::new();
    for at in walker.walk(Vec::new()) {
        let Some(row) = at.path.last().and_then(|s| s.row) else {
            continue;
        };
        let r = &plan.rows[row];
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
    // The same inputs on the next cycle, with the counters one on; a leaf
    // the first witness left open is held at what the second one needs.
    let mut held = Held::of(an, &w);
    let counters = [
        (at.state_cycles, at.plan_cycles),
        (at.state_cycles.saturating_add(1), at.plan_cycles + 1),
    ];
    let mut again = walker.counter_pins(counters[1].0, counters[1].1);
    again.extend(held.pins.iter().cloned());
    held.extend(an, &can(an.can_fire_in_given(row, state, &again))?);
    let answered = walker.statuses.iter().all(|(y, leaf)| {
        !at.sent.contains(y) || value_of(an, &held.inputs, *leaf) != Some(&not_ready())
    });
    let repeats = counters.iter().all(|&(sc, pc)| {
        let mut pins = walker.counter_pins(sc, pc);
        pins.extend(held.pins.iter().cloned());
        fires_on(an, row, state, &pins)
    });
    if !answered || !repeats {
        return None;
    }
    let Held {
        inputs: repeat,
        shown: held_shown,
        ..
    } = held;
    // The counters the row reads, as on the first repeat: they say when.
    let mut shown: Vec<(String, String)> = w
        .shown
        .iter()
        .filter(|(n, _)| matches!(n.as_str(), "state_cycles" | "plan_cycles"))
        .cloned()
        .collect();
    shown.extend(held_shown);
    // Parameters the walk left open and the repeats read: the command
    // carries them from the start (the walk did not depend on them).
    let mut params = walker.params(&at.pinned);
    for (leaf, v) in &repeat {
        let is_new = !params
            .iter()
            .any(|(p, _)| an.terms().find(p) == an.terms().find(leaf));
        if matches!(leaf, Leaf::Param(..)) && is_new {
            params.push((leaf.clone(), v.clone()));
        }
    }
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
        params,
    })
}

/// The first row, in a state of `cycle`, other than the cycle's rows,
/// that can fire in that state with `held` pinned and the counters free,
/// with the inputs of such a cycle.
fn defeated_row(
    an: &PlanAnalysis,
    plan: &Plan,
    cycle: &[(usize, StateId)],
    held: &[(LeafId, Value)],
) -> Option<((usize, StateId), Inputs)> {
    let new_command = an.terms().find(&Leaf::NewCommand);
    for &(_, state) in cycle {
        for (i, row) in plan.rows.iter().enumerate() {
            // A row of the ring fires in its own state: not a row kept out.
            if cycle.iter().any(|(r, _)| *r == i) || !covers(&row.from, state) {
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
