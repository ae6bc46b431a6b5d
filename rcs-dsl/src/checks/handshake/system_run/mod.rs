//! The witnesses of the handshake findings as *system runs* (stage 3b,
//! after every check): a finding about a supervisor comes with the
//! supervisor's own run, in which the scenario plays its subordinate's
//! statuses. Here that run is turned into a system scenario of the
//! supervisor's whole subtree, in which the subordinate runs its own plan:
//!
//! 1. the supervisor's steps become steps of the subtree, on the real
//!    schedule (a supervisor cycle is `k` ticks of the base period), with
//!    their `reads`, hooks and expectations (the row that fires, the
//!    state); the statuses it played are not played;
//! 2. where a step plays an answer of a subordinate (`DONE`, `ERROR`, a
//!    status it reports), the run so far is played once, to see on which
//!    tick the supervisor's last command reached the subordinate, and the
//!    subordinate's own run to that answer (a row of its plan that ends
//!    in `Done`, fails or reports it, its parameters pinned to the
//!    arguments really sent) is laid from that tick on, in its own cycles;
//!    the supervisor's step then starts on its first cycle after the
//!    answer (it waited that much longer, seeing `EXECUTING`);
//! 3. the scenario expects, besides the supervisor's rows and states,
//!    the subordinate's status the finding is about at the end.
//!
//! The script is then replayed through its file on the interpreter; only a
//! replay that shows the finding is kept. Where no such run is found (the
//! supervisor's way there needs a subordinate's answer the subordinate's
//! inputs cannot be made to give, a buffer a controller of the subtree
//! writes, a failure by a built-in error), the finding keeps its
//! supervisor's run alone: it is proved all the same, by the analysis of
//! both plans.

mod subordinate;

use crate::analysis::run::{Expect, Run, RunStep};
use crate::diagnostic::{Across, Diagnostic};
use crate::interp::{zero, Value};
use crate::ir::{CommandId, CtrlId, Ir, Type};
use crate::scenario::{ControllerExpect, SystemScript, SystemStep};
use std::collections::BTreeMap;
pub(crate) use subordinate::failure_run;
use subordinate::{answer_run, passing_on};

/// Give each handshake finding its system run; a finding for which none
/// is found is dropped (the return says which to keep). The supervisor's
/// own run plays its subordinates' answers, and a played answer can be
/// one the subordinate never gives there: on the random hierarchies of
/// `tests/hierarchies.rs`, supervisor runs waited on an answer to a
/// command never sent, or on `NOT_READY` from a subordinate that on its
/// CPU reads every command at once. Only the whole subtree running shows
/// the finding is real.
pub(crate) fn add_system_runs(ir: &Ir, diags: &mut [Diagnostic]) -> Vec<bool> {
    diags
        .iter_mut()
        .map(|d| {
            let name = d.code.name();
            let Some(w) = &mut d.witness else { return true };
            let Some(across) = w.across.take() else {
                return true;
            };
            let Some(run) = &w.run else { return false };
            // The supervisor's run chose its command's parameters for its
            // own plan; where it passes them on to the subordinate, values
            // that make the subordinate fail may be needed.
            let script = system_run(ir, run, &across, name).or_else(|| {
                let passed = passing_on(ir, run, across.sub)?;
                system_run(ir, &passed, &across, name)
            });
            let Some(script) = script else {
                return false;
            };
            d.notes.push(format!(
                "reproduced with `{}`'s whole subtree running, `{}` on its own plan: \
                 `rcsc check --witnesses DIR` writes it as a system scenario",
                run.controller,
                ir.controller(across.sub).name
            ));
            w.system = Some(script);
            true
        })
        .collect()
}

/// An input change at a tick: `reads` buffers, hooks, a command to the
/// supervisor.
#[derive(Default)]
struct Inputs {
    commands: Vec<(String, String, Vec<Value>)>,
    reads: Vec<(String, Value)>,
    hooks: Vec<(String, String, Value)>,
}

/// The system run of a finding whose supervisor's run is `run`; `None`
/// when none is found or its replay does not show the finding.
fn system_run(ir: &Ir, run: &Run, across: &Across, lint: &str) -> Option<SystemScript> {
    let sup = ir.controller_by_name(&run.controller)?;
    let members = subtree(ir, sup);
    let sched = Schedule::of(ir, &members);
    let names: Vec<String> = members
        .iter()
        .map(|c| ir.controller(*c).name.clone())
        .collect();
    let mut lay = Laying {
        given: Given {
            names: &names,
            lint,
            sup,
            k_sup: sched.ticks(sup)?,
            sched: &sched,
            members: &members,
        },
        events: BTreeMap::new(),
        expect: BTreeMap::new(),
        played: BTreeMap::new(),
        tick: 0,
    };
    let x = across.sub;
    let x_name = ir.controller(x).name.clone();
    if let Some(earlier) = &across.earlier {
        // An earlier command that has the subordinate answer what the
        // finding's run then reads as an old answer.
        lay.run(ir, earlier)?;
        let status = run
            .steps
            .iter()
            .filter_map(|s| s.subordinates.get(&x_name))
            .find(|s| is_answer(s))?;
        let seen = lay.answer(ir, x, status)?;
        lay.tick = lay.tick.max(seen);
        lay.played.insert(x_name.clone(), status.clone());
    }
    lay.run(ir, run)?;
    let mut end = lay.tick;
    if let Some(status) = &across.shows {
        // The subordinate shows the answer the finding is about, at the
        // end: given on its own plan if the supervisor's run did not
        // play it, else still standing.
        if lay.played.get(&x_name) != Some(status) {
            end = end.max(lay.answer(ir, x, status)?);
        }
        lay.expect.entry(end).or_default().push((
            x_name,
            ControllerExpect {
                status: Some(status.clone()),
                ..Default::default()
            },
        ));
    }
    let script = script_of(&names, &lay.events, &lay.expect, end, lint);
    let outcome = crate::scenario::run_script(ir, &script).ok()?;
    outcome.failure.is_none().then_some(script)
}

/// A system run being laid out, tick by tick.
struct Laying<'a> {
    given: Given<'a>,
    events: BTreeMap<u64, Inputs>,
    expect: BTreeMap<u64, Vec<(String, ControllerExpect)>>,
    /// The answers the supervisor's runs played so far, by subordinate.
    played: BTreeMap<String, String>,
    /// Where the next supervisor step starts.
    tick: u64,
}

impl Laying<'_> {
    /// Lay a supervisor's run from `tick` on: its command, its steps with
    /// their inputs and expectations, and before a step that plays an
    /// answer for the first time, the subordinate's own run to it.
    fn run(&mut self, ir: &Ir, run: &Run) -> Option<()> {
        let sup = self.given.sup;
        for (i, step) in run.steps.iter().enumerate() {
            for (x_name, status) in &step.subordinates {
                if !is_answer(status) || self.played.get(x_name) == Some(status) {
                    continue;
                }
                let x = ir.controller_by_name(x_name)?;
                let seen = self.answer(ir, x, status)?;
                self.tick = self.tick.max(seen);
            }
            self.played.extend(step.subordinates.clone());
            let at = self.events.entry(self.tick).or_default();
            if i == 0 {
                at.commands
                    .push(command(ir, sup, &run.command, &run.params)?);
            }
            if let Some(c) = &step.command {
                at.commands.push(command(ir, sup, &c.verb, &c.params)?);
            }
            inputs_of(ir, sup, self.given.members, step, at)?;
            self.tick += u64::from(step.cycles.max(1)) * self.given.k_sup;
            if let Some(e) = sup_expect(&step.expect) {
                self.expect
                    .entry(self.tick)
                    .or_default()
                    .push((run.controller.clone(), e));
            }
        }
        Some(())
    }

    /// [`Given::answer`] before the current tick.
    fn answer(&mut self, ir: &Ir, x: CtrlId, status: &str) -> Option<u64> {
        self.given
            .answer(ir, &mut self.events, x, status, self.tick)
    }
}

/// A statement about a subordinate that the supervisor waits for (not
/// the handshake's own `EXECUTING` and `NOT_READY`).
fn is_answer(status: &str) -> bool {
    !matches!(status, "EXECUTING" | "NOT_READY")
}

/// How many ticks of the base period each CPU of a run's period is.
struct Schedule {
    every: Vec<(String, u64)>,
    cpus: Vec<(String, Vec<CtrlId>)>,
}

impl Schedule {
    fn of(ir: &Ir, members: &[CtrlId]) -> Schedule {
        let (every, _) = crate::scenario::schedule(ir, members);
        let cpus = ir
            .schedule
            .iter()
            .map(|cpu| (cpu.name.clone(), cpu.order.clone()))
            .collect();
        Schedule { every, cpus }
    }

    /// Controller `c`'s period in ticks; it runs on the ticks that are
    /// multiples of it.
    fn ticks(&self, c: CtrlId) -> Option<u64> {
        let (cpu, _) = self.cpus.iter().find(|(_, order)| order.contains(&c))?;
        self.every.iter().find(|(n, _)| n == cpu).map(|(_, k)| *k)
    }
}

/// What laying a subordinate's answer into the run needs.
struct Given<'a> {
    names: &'a [String],
    lint: &'a str,
    sup: CtrlId,
    k_sup: u64,
    sched: &'a Schedule,
    members: &'a [CtrlId],
}

impl Given<'_> {
    /// Make subordinate `x` answer `status` to the last command the
    /// supervisor sent it before tick `before`: its own run to that
    /// answer, laid into `events` from the tick the command reached it
    /// (nothing, when it answers so by itself: a refusal). Returns the
    /// first supervisor tick that sees the answer.
    fn answer(
        &self,
        ir: &Ir,
        events: &mut BTreeMap<u64, Inputs>,
        x: CtrlId,
        status: &str,
        before: u64,
    ) -> Option<u64> {
        let k_x = self.sched.ticks(x)?;
        // How the run goes without the subordinate's part, a little past
        // `before` (a command sent on the last cycle reaches it later).
        let horizon = before + 2 * k_x.max(self.k_sup);
        let probe = script_of(self.names, events, &BTreeMap::new(), horizon, self.lint);
        let got = arrival(ir, &probe, self.sup, x, before, self.k_sup, k_x)?;
        let last_cycle = if got.refused && status == "ERROR" {
            got.tick
        } else {
            let run = answer_run(ir, x, got.verb, &got.args, status)?;
            let mut t = got.tick;
            for step in &run.steps {
                inputs_of(ir, x, self.members, step, events.entry(t).or_default())?;
                t += u64::from(step.cycles.max(1)) * k_x;
            }
            t - k_x
        };
        // The supervisor's first cycle after the subordinate's last.
        Some((last_cycle + 1).div_ceil(self.k_sup) * self.k_sup)
    }
}

/// The controllers of `root`'s subtree, `root` first.
fn subtree(ir: &Ir, root: CtrlId) -> Vec<CtrlId> {
    let mut out = vec![root];
    let mut i = 0;
    while let Some(&c) = out.get(i) {
        out.extend(ir.controller(c).subordinates.iter().copied());
        i += 1;
    }
    out
}

/// A command of a run as the scenario sends it to controller `c`.
fn command(
    ir: &Ir,
    c: CtrlId,
    verb: &str,
    params: &BTreeMap<String, serde_json::Value>,
) -> Option<(String, String, Vec<Value>)> {
    let ctrl = ir.controller(c);
    let k = ctrl.commands.iter().find(|k| k.name == verb)?;
    let args = k
        .params
        .iter()
        .map(|p| match params.get(&p.name) {
            Some(j) => crate::scenario::value(ir, 0, &p.ty, j, &p.name).ok(),
            None => Some(zero(ir, &p.ty)),
        })
        .collect::<Option<Vec<Value>>>()?;
    Some((ctrl.name.clone(), verb.to_string(), args))
}

/// A step's `reads` and hooks of controller `c`, into `at`; `None` when
/// it sets a buffer a controller of the run writes (the run cannot).
fn inputs_of(
    ir: &Ir,
    c: CtrlId,
    members: &[CtrlId],
    step: &RunStep,
    at: &mut Inputs,
) -> Option<()> {
    for (name, j) in &step.reads {
        let b = ir.buffers.iter().find(|b| b.name == *name)?;
        if b.writer.is_some_and(|w| members.contains(&w)) {
            return None;
        }
        let ty = Type::Buffer(b.ty);
        let v = crate::scenario::merge(ir, 0, &zero(ir, &ty), &ty, j, name).ok()?;
        at.reads.retain(|(n, _)| n != name);
        at.reads.push((name.clone(), v));
    }
    let ctrl = ir.controller(c);
    for (name, j) in &step.hooks {
        let h = ctrl.hooks.iter().find(|h| h.name == *name)?;
        let v = crate::scenario::value(ir, 0, &h.ret, j, name).ok()?;
        at.hooks.push((ctrl.name.clone(), name.clone(), v));
    }
    Some(())
}

/// The supervisor's expectation for the last cycle of its run.
fn sup_expect(e: &Expect) -> Option<ControllerExpect> {
    match e {
        Expect::Fires { row, state } => Some(ControllerExpect {
            fired: Some(Some(row.clone())),
            state: Some(state.clone()),
            ..Default::default()
        }),
        Expect::Stays { state } => Some(ControllerExpect {
            fired: Some(None),
            state: Some(state.clone()),
            ..Default::default()
        }),
        _ => None,
    }
}

/// The script of input changes and expectations, by tick, up to `end`.
fn script_of(
    names: &[String],
    events: &BTreeMap<u64, Inputs>,
    expect: &BTreeMap<u64, Vec<(String, ControllerExpect)>>,
    end: u64,
    lint: &str,
) -> SystemScript {
    let mut bounds: Vec<u64> = events
        .keys()
        .copied()
        .chain(expect.keys().copied())
        .filter(|t| *t <= end)
        .chain([0, end])
        .collect();
    bounds.sort_unstable();
    bounds.dedup();
    let mut steps = Vec::new();
    for pair in bounds.windows(2) {
        let (from, to) = (pair[0], pair[1]);
        let mut step = SystemStep {
            cycles: to - from,
            expect: expect.get(&to).cloned().unwrap_or_default(),
            ..Default::default()
        };
        if let Some(i) = events.get(&from) {
            step.commands = i.commands.clone();
            step.reads = i.reads.clone();
            step.hooks = i.hooks.clone();
        }
        steps.push(step);
    }
    SystemScript {
        name: format!("{lint} (system run)"),
        controllers: Some(names.to_vec()),
        initial: SystemStep::default(),
        steps,
    }
}

/// Where the supervisor's last command to a subordinate before a tick
/// reached it.
struct Arrival {
    /// The tick of the subordinate's cycle that read it.
    tick: u64,
    verb: CommandId,
    args: Vec<Value>,
    /// The subordinate refused it (`accept when`).
    refused: bool,
}

/// Play `probe` and find the tick on which subordinate `sub` first reads
/// the last command `sup` sent it before tick `before`.
fn arrival(
    ir: &Ir,
    probe: &SystemScript,
    sup: CtrlId,
    sub: CtrlId,
    before: u64,
    k_sup: u64,
    k_sub: u64,
) -> Option<Arrival> {
    let position = ir
        .controller(sup)
        .subordinates
        .iter()
        .position(|s| *s == sub)? as u16;
    let mut sent: Option<(u64, u32, CommandId, Vec<Value>)> = None;
    let mut runs: Vec<(u64, u32, u32)> = Vec::new();
    crate::scenario::run_script_observed(ir, probe, &mut |c, rec| {
        if c == sup && rec.cycle * k_sup < before {
            if let Some(s) = rec.sent.iter().find(|s| s.sub == position) {
                sent = Some((
                    rec.cycle * k_sup,
                    s.serial,
                    CommandId(u32::from(s.verb)),
                    s.args.clone(),
                ));
            }
        } else if c == sub {
            runs.push((rec.cycle * k_sub, rec.echo_serial, rec.refused_serial));
        }
    })
    .ok()?;
    let (at, serial, verb, args) = sent?;
    runs.iter()
        .find(|(t, echo, refused)| *t >= at && (*echo == serial || *refused == serial))
        .map(|(t, _, refused)| Arrival {
            tick: *t,
            verb,
            args,
            refused: *refused == serial,
        })
}
