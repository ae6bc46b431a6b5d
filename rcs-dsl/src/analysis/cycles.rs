//! Stage 3a, over several cycles: what one plan does on consecutive
//! cycles, on walks from its entry (`walk.rs`). Two findings come out of
//! it, each with the way there from the entry and the inputs that make it
//! happen: a **livelock** (rows that move between states on every cycle
//! under inputs held constant) and a **command storm** (a row that sends
//! to a subordinate again on the next cycle, while the subordinate is
//! still executing). The checks `livelock` and `command_every_cycle`
//! (`checks/loops.rs`) report them; `tests/loops.rs` replays them on the
//! interpreter — one computation for both.

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

/// The livelocks of one plan, each reachable from the entry.
pub fn livelocks(ctrl: &Controller, plan: &Plan, an: &PlanAnalysis) -> Vec<Livelock> {
    if !an.analysed_over_cycles() {
        return Vec::new();
    }
    // No ring of states among the rows that can fire: nothing to walk.
    let rings = state_cycles_of(plan, an);
    if rings.is_empty() {
        return Vec::new();
    }
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
    for cycle in rings {
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
        let mut held = Held::of(an, &w);
        // A leaf the first witness left open may matter at a later value
        // of `plan_cycles`: hold the value the rows need there too (the
        // rows fired before whatever its value, so they still do).
        for pc in &plan_cycle_values {
            for &(r, s) in &cycle {
                let mut pins = walker.counter_pins(1, *pc);
                pins.extend(held.pins.iter().cloned());
                if let Some(w) = can(an.can_fire_in_given(r, s, &pins)) {
                    held.extend(an, &w);
                }
            }
        }
        let Held {
            inputs: held,
            pins: held_pins,
            shown,
        } = held;
        let holds_for = |pc: u32| {
            cycle.iter().all(|&(r, s)| {
                let mut pins = walker.counter_pins(1, pc);
                pins.extend(held_pins.iter().cloned());
                fires_on(an, r, s, &pins)
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
        let entry = walker.first(params, &|at| {
            at.state_cycles == 1 && cycle.iter().any(|(_, s)| *s == at.state) && consistent(at)
        });
        let Some(at) = entry else { continue };
        let start = cycle.iter().position(|(_, s)| *s == at.state).unwrap_or(0);
        let mut cycle = cycle;
        cycle.rotate_left(start);
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
