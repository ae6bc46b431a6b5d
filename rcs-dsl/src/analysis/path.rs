//! Stage 3a, after the analysis: from witnesses to [`Run`]s. A witness is
//! one cycle's inputs; a run needs the cycles before it too. This module
//! searches, breadth first, for rows that lead from `S0` to each state of
//! a plan, asking the analysis for a witness of each row firing with the
//! leaves a scenario cannot set pinned to what the path so far produced
//! (`new_command`, the counters, the command's parameters once chosen,
//! vars, `writes` buffers), and replays every candidate on the
//! interpreter before offering it: a path that does not happen there is
//! not offered.
//!
//! A row that needs a counter (`state_cycles > 5`) is reached by waiting:
//! its witness's inputs held for the cycles before, in which no row may
//! fire (the replay checks it; if another row fires, that wait is not
//! offered). A row that needs a var to change (`count >= 3`) is reached
//! by firing rows that stay in the state and change vars, up to
//! 32 times, before trying again.

use super::run::{json_of, replay_on, Expect, Run, RunStep};
use super::terms::{Leaf, LeafId, Step};
use super::{Answer, PlanAnalysis, Witness};
use crate::interp;
use crate::ir::{CtrlId, StateId, Target, Type};
use rcs_runtime::driver::Value;
use std::collections::BTreeMap;

/// The longest wait for a counter a path takes, in cycles.
const MAX_WAIT: u32 = 1000;

/// How many times a path fires rows that stay in a state to change vars.
const MAX_LOOPS: usize = 32;

impl PlanAnalysis<'_> {
    /// The id of the controller whose plan this is.
    pub fn ctrl_id(&self) -> Option<CtrlId> {
        self.ir
            .controllers
            .iter()
            .position(|c| std::ptr::eq(c, self.ctrl))
            .map(|i| CtrlId(i as u32))
    }

    /// The run before anything happens: the plan's command, no step yet
    /// (its parameters are chosen by the first step).
    pub fn empty_run(&self) -> Run {
        Run {
            controller: self.ctrl.name.clone(),
            command: self.ctrl.commands[self.plan.verb.index()].name.clone(),
            params: BTreeMap::new(),
            steps: Vec::new(),
        }
    }

    /// Per state, a run from a fresh controller whose last step leaves the
    /// plan there (`S0`: the empty run); `None` where no path was found.
    pub fn paths(&self) -> Vec<Option<Run>> {
        self.paths_given(&[])
    }

    /// [`paths`](Self::paths) with some leaves pinned on every step (the
    /// command's parameters, for a finding that holds for some of them).
    pub fn paths_given(&self, given: &[(LeafId, Value)]) -> Vec<Option<Run>> {
        let mut paths: Vec<Option<Run>> = vec![None; self.plan.states.len()];
        if paths.is_empty() {
            return paths;
        }
        paths[0] = Some(self.empty_run());
        let mut queue = std::collections::VecDeque::from([StateId::S0]);
        while let Some(at) = queue.pop_front() {
            let Some(mut prefix) = paths[at.index()].clone() else {
                continue;
            };
            // Rows that stay in `at` and change vars can open the way out
            // (`count += 1` until `count >= 3`): fire one, then try again.
            for _ in 0..=MAX_LOOPS {
                let Some(scene) = self.scene(&prefix) else {
                    break;
                };
                for (r, row) in self.plan.rows.iter().enumerate() {
                    let Target::State(to) = row.to else { continue };
                    if paths.get(to.index()).is_none_or(|p| p.is_some()) {
                        continue;
                    }
                    if let Some(run) = self.fire_after(&prefix, &scene, r, at, to, given) {
                        paths[to.index()] = Some(run);
                        queue.push_back(to);
                    }
                }
                let open = self.plan.rows.iter().any(|row| {
                    matches!(row.to, Target::State(to) if paths.get(to.index()).is_some_and(|p| p.is_none()))
                });
                match self.loop_once(&prefix, &scene, at, given) {
                    Some(longer) if open => prefix = longer,
                    _ => break,
                }
            }
        }
        paths
    }

    /// `prefix`, then row `r` firing from `at` into `to` (`at` itself when
    /// the row stays or ends the plan), after a wait for a counter if it
    /// needs one; replayed. `None` when no such run is found.
    pub fn fire_from(&self, prefix: &Run, r: usize, at: StateId, to: StateId) -> Option<Run> {
        self.fire_from_given(prefix, r, at, to, &[])
    }

    /// [`fire_from`](Self::fire_from) with some leaves pinned (the
    /// command's parameters at the values a supervisor sends).
    pub fn fire_from_given(
        &self,
        prefix: &Run,
        r: usize,
        at: StateId,
        to: StateId,
        given: &[(LeafId, Value)],
    ) -> Option<Run> {
        let scene = self.scene(prefix)?;
        self.fire_after(prefix, &scene, r, at, to, given)
    }

    /// `prefix`, then row `r` firing from `at` into `to` on the very next
    /// cycle, with no wait; replayed. With the inputs of that cycle.
    pub fn fire_at_once(
        &self,
        prefix: &Run,
        r: usize,
        at: StateId,
        to: StateId,
    ) -> Option<(Run, Witness)> {
        let scene = self.scene(prefix)?;
        let pins = self.pins(&scene, prefix, 0);
        let Answer::Can(w) = self.can_fire_in_given(r, at, &pins) else {
            return None;
        };
        let expect = Expect::Fires {
            row: super::run::row_name(&self.plan.rows[r]),
            state: self.plan.states.get(to.index())?.name.clone(),
        };
        let run = self.extend(prefix, &w, 1, expect)?;
        Some((run, w))
    }

    /// `prefix`, then row `r` firing from `at` into `to` (after a wait for a
    /// counter if it needs one).
    fn fire_after(
        &self,
        prefix: &Run,
        scene: &Scene,
        r: usize,
        at: StateId,
        to: StateId,
        given: &[(LeafId, Value)],
    ) -> Option<Run> {
        let expect = Expect::Fires {
            row: super::run::row_name(&self.plan.rows[r]),
            state: self.plan.states.get(to.index())?.name.clone(),
        };
        for wait in self.waits(scene, prefix.steps.is_empty()) {
            let mut pins = self.pins(scene, prefix, wait);
            pins.extend(given.iter().cloned());
            let Answer::Can(w) = self.can_fire_in_given(r, at, &pins) else {
                continue;
            };
            if let Some(run) = self.extend(prefix, &w, wait + 1, expect.clone()) {
                return Some(run);
            }
        }
        None
    }

    /// `prefix`, then one row that stays in `at` and changes a var; `None`
    /// when no such row fires.
    fn loop_once(
        &self,
        prefix: &Run,
        scene: &Scene,
        at: StateId,
        given: &[(LeafId, Value)],
    ) -> Option<Run> {
        if prefix.steps.is_empty() {
            return None; // S0 before the command: its first cycle is the entry's
        }
        self.plan.rows.iter().enumerate().find_map(|(r, row)| {
            if !matches!(row.to, Target::Same) && row.to != Target::State(at) {
                return None;
            }
            let run = self.fire_after(prefix, scene, r, at, at, given)?;
            let after = self.scene(&run)?;
            (after.vars != scene.vars).then_some(run)
        })
    }

    /// A run that reaches `state` along `paths`, then holds `witness`'s
    /// inputs for `cycles` cycles in which no row fires: a stall or hang.
    pub fn stall_run(
        &self,
        paths: &[Option<Run>],
        state: StateId,
        witness: &Witness,
        cycles: u32,
    ) -> Option<Run> {
        let prefix = paths.get(state.index())?.as_ref()?;
        // In `S0` before any cycle, the first cycle is a new command's.
        if prefix.steps.is_empty() {
            return None;
        }
        let expect = Expect::Stays {
            state: self.plan.states.get(state.index())?.name.clone(),
        };
        self.extend(prefix, witness, cycles, expect)
    }

    /// A run for a finding in `state` that holds with the command's
    /// parameters at `params`: the way there with them pinned, then `held`
    /// for `cycles` cycles that must show `expect`. `None` when no way
    /// there is found, or the replay does not show `expect`.
    pub fn finding_run(
        &self,
        params: &[(Leaf, Value)],
        state: StateId,
        held: &[(Leaf, Value)],
        cycles: u32,
        expect: Expect,
    ) -> Option<Run> {
        let given: Vec<(LeafId, Value)> = params
            .iter()
            .filter_map(|(l, v)| Some((self.terms.find(l)?, v.clone())))
            .collect();
        let paths = self.paths_given(&given);
        let prefix = paths.get(state.index())?.as_ref()?;
        let mut inputs = held.to_vec();
        if prefix.steps.is_empty() {
            // In `S0` before any cycle: the step starts with the command,
            // whose first cycle only a hang (nothing fires from the start)
            // shares with the cycles after it.
            if !matches!(expect, Expect::Stays { .. }) {
                return None;
            }
            inputs.extend(params.iter().cloned());
        }
        let witness = Witness {
            state,
            inputs,
            shown: Vec::new(),
        };
        self.extend(prefix, &witness, cycles, expect)
    }

    /// `prefix` and one more step: `witness`'s inputs that a scenario can
    /// set, held for `cycles` cycles that must show `expect`. `None` when
    /// the witness needs what a scenario cannot set (a hook called with
    /// two arguments giving two results, a NaN) or the replay on the
    /// interpreter does not show `expect`.
    pub fn extend(
        &self,
        prefix: &Run,
        witness: &Witness,
        cycles: u32,
        expect: Expect,
    ) -> Option<Run> {
        self.try_extend(prefix, witness, cycles, expect).ok()
    }

    /// [`extend`](Self::extend), saying why not: [`RunError::Unwritable`]
    /// when a scenario cannot give the witness's inputs (or `prefix` does
    /// not replay), [`RunError::Replay`] when it can but the interpreter
    /// does not show `expect`.
    pub fn try_extend(
        &self,
        prefix: &Run,
        witness: &Witness,
        cycles: u32,
        expect: Expect,
    ) -> Result<Run, RunError> {
        let run = self
            .step_run(prefix, witness, cycles, expect)
            .ok_or(RunError::Unwritable)?;
        let ctrl = self.ctrl_id().ok_or(RunError::Unwritable)?;
        replay_on(self.ir, ctrl, &run).map_err(RunError::Replay)?;
        Ok(run)
    }

    /// The run of [`try_extend`](Self::try_extend) before its replay;
    /// `None` when a scenario cannot give the witness's inputs.
    pub(super) fn step_run(
        &self,
        prefix: &Run,
        witness: &Witness,
        cycles: u32,
        expect: Expect,
    ) -> Option<Run> {
        let ir = self.ir;
        let scene = self.scene(prefix)?;
        let first = prefix.steps.is_empty();
        let mut reads = scene.reads.clone();
        let mut changed = vec![false; reads.len()];
        let mut params = scene.params.clone();
        let mut step = RunStep {
            cycles: cycles.max(1),
            expect,
            ..RunStep::default()
        };
        for (leaf, v) in &witness.inputs {
            match leaf {
                Leaf::Buffer(b, steps) => {
                    let Some(i) = self.ctrl.reads.iter().position(|r| r == b) else {
                        continue;
                    };
                    *at_path_mut(&mut reads[i], steps)? = v.clone();
                    changed[i] = true;
                }
                Leaf::Call(h, _) => {
                    let hook = &self.ctrl.hooks[h.index()];
                    let value = json_of(ir, &hook.ret, v)?;
                    // The driver gives one result per hook and cycle.
                    if let Some(old) = step.hooks.insert(hook.name.clone(), value.clone()) {
                        if old != value {
                            return None;
                        }
                    }
                }
                Leaf::SubStatus(x) => {
                    let Value::Status(s) = v else { return None };
                    let sub = ir.controller(*x);
                    let name = sub.statuses.get(usize::from(*s))?.name.clone();
                    step.subordinates.insert(sub.name.clone(), name);
                }
                Leaf::Param(p, steps) if first => {
                    *at_path_mut(params.get_mut(p.index())?, steps)? = v.clone();
                }
                // A whole status field; a part of one (a field of a
                // buffer it holds) a scenario sets only with the rest.
                Leaf::SubField(x, f, steps) if steps.is_empty() => {
                    let sub = ir.controller(*x);
                    let var = sub.vars.get(f.index())?;
                    let value = json_of(ir, &var.ty, v)?;
                    step.status_fields
                        .entry(sub.name.clone())
                        .or_default()
                        .insert(var.name.clone(), value);
                }
                Leaf::SubField(..) => return None,
                _ => {}
            }
        }
        for (i, b) in self.ctrl.reads.iter().enumerate() {
            if changed[i] {
                let buf = &ir.buffers[b.index()];
                let json = json_of(ir, &Type::Buffer(buf.ty), &reads[i])?;
                step.reads.insert(buf.name.clone(), json);
            }
        }
        let mut run = prefix.clone();
        if first {
            let verb = &self.ctrl.commands[self.plan.verb.index()];
            run.params = BTreeMap::new();
            for (p, v) in verb.params.iter().zip(&params) {
                run.params.insert(p.name.clone(), json_of(ir, &p.ty, v)?);
            }
        }
        run.steps.push(step);
        Some(run)
    }

    /// The leaves a scenario cannot set, pinned as `prefix` leaves them
    /// after `wait` more cycles with nothing firing: what a witness of the
    /// next step must agree with. `None` when `prefix` does not replay.
    pub fn pins_after(&self, prefix: &Run, wait: u32) -> Option<Vec<(LeafId, Value)>> {
        let scene = self.scene(prefix)?;
        Some(self.pins(&scene, prefix, wait))
    }

    /// The waits worth trying after `prefix` (see `waits`); `None` when
    /// `prefix` does not replay.
    pub(super) fn waits_after(&self, prefix: &Run) -> Option<Vec<u32>> {
        let scene = self.scene(prefix)?;
        Some(self.waits(&scene, prefix.steps.is_empty()))
    }

    /// What the interpreter holds after `run`: a fresh controller for the
    /// empty run.
    fn scene(&self, run: &Run) -> Option<Scene> {
        let ctrl = self.ctrl_id()?;
        let verb = &self.ctrl.commands[self.plan.verb.index()];
        let fresh;
        let driven = if run.steps.is_empty() {
            fresh = interp::Driven::new(self.ir, ctrl);
            fresh
        } else {
            replay_on(self.ir, ctrl, run).ok()?
        };
        let i = driven.interpreter();
        let params = if run.steps.is_empty() {
            let zero = |t: &Type| interp::zero(self.ir, t);
            verb.params.iter().map(|p| zero(&p.ty)).collect()
        } else {
            i.command_buffer().2.clone()
        };
        Some(Scene {
            reads: i.reads().to_vec(),
            writes: i.writes().to_vec(),
            vars: i.vars().to_vec(),
            params,
            state_cycles: i.bookkeeping().state_cycles(),
            plan_cycles: i.bookkeeping().plan_cycles(),
        })
    }

    /// The waits worth trying before a row fires: none, and each one that
    /// brings a counter to the first value of one of its cells.
    fn waits(&self, scene: &Scene, first: bool) -> Vec<u32> {
        let mut out = vec![0];
        if first {
            return out; // the first cycle is the command's
        }
        for (leaf, now) in [
            (Leaf::StateCycles, scene.state_cycles),
            (Leaf::PlanCycles, scene.plan_cycles),
        ] {
            let Some(l) = self.terms.find(&leaf) else {
                continue;
            };
            for v in &self.cells[l] {
                if let Value::Int(v) = v {
                    let wait = v - i128::from(now);
                    if wait > 0 && wait <= i128::from(MAX_WAIT) {
                        out.push(wait as u32);
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The leaves a scenario cannot set, as the path leaves them after
    /// `wait` more cycles: `new_command` (true only on the first cycle),
    /// the counters, the parameters once issued, vars and `writes`.
    fn pins(&self, scene: &Scene, prefix: &Run, wait: u32) -> Vec<(LeafId, Value)> {
        let first = prefix.steps.is_empty();
        let mut pins = vec![(self.new_command, Value::Bool(first))];
        for (l, (leaf, _)) in self.terms.leaves.iter().enumerate() {
            let value = match leaf {
                Leaf::StateCycles => Some(Value::Int(
                    i128::from(scene.state_cycles) + i128::from(wait),
                )),
                Leaf::PlanCycles => {
                    Some(Value::Int(i128::from(scene.plan_cycles) + i128::from(wait)))
                }
                Leaf::Param(p, steps) if !first => {
                    scene.params.get(p.index()).and_then(|v| at_path(v, steps))
                }
                Leaf::Var(v, steps) => scene.vars.get(v.index()).and_then(|v| at_path(v, steps)),
                // A scenario writes every status each cycle: never stale.
                // …and every `reads` buffer (no `silent:` in a witness).
                Leaf::SubStale(_) | Leaf::BufStale(_) => Some(Value::Int(0)),
                Leaf::Buffer(b, steps) if !self.ctrl.reads.contains(b) => self
                    .ctrl
                    .writes
                    .iter()
                    .position(|w| w == b)
                    .and_then(|i| at_path(&scene.writes[i], steps)),
                _ => None,
            };
            if let Some(v) = value {
                pins.push((l, v));
            }
        }
        pins
    }
}

/// Why a witness did not become a step of a run.
#[derive(Clone, Debug, PartialEq)]
pub enum RunError {
    /// A scenario cannot give its inputs: a NaN or infinity, one hook with
    /// two results in a cycle, a status inside a buffer; or the run before
    /// it does not replay.
    Unwritable,
    /// The interpreter does not do what the step expects: what happened.
    Replay(String),
}

/// What the interpreter holds at the end of a path.
struct Scene {
    reads: Vec<Value>,
    writes: Vec<Value>,
    vars: Vec<Value>,
    params: Vec<Value>,
    state_cycles: u32,
    plan_cycles: u32,
}

/// The part of `v` at `steps`.
pub(super) fn at_path(v: &Value, steps: &[Step]) -> Option<Value> {
    let mut v = v;
    for s in steps {
        v = match (s, v) {
            (Step::Field(i), Value::Buffer(xs)) | (Step::Index(i), Value::Array(xs)) => {
                xs.get(*i as usize)?
            }
            _ => return None,
        };
    }
    Some(v.clone())
}

fn at_path_mut<'v>(v: &'v mut Value, steps: &[Step]) -> Option<&'v mut Value> {
    let mut v = v;
    for s in steps {
        v = match (s, v) {
            (Step::Field(i), Value::Buffer(xs)) | (Step::Index(i), Value::Array(xs)) => {
                xs.get_mut(*i as usize)?
            }
            _ => return None,
        };
    }
    Some(v)
}
