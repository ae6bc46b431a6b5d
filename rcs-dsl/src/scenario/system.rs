//! Running a system scenario ([`super::system_read`]) on any backend behind
//! [`DrivenSystem`]: the interpreter's [`crate::interp::System`] or the
//! generated `SystemDriver`. The runner owns the schedule, so both
//! backends interleave a multi-rate set alike: time advances in *ticks* of
//! the base period (the greatest common divisor of the periods of the CPUs
//! that run a controller of the run); on tick `t` (from 0) each such CPU
//! whose period is `k` base periods runs one cycle when `t` is a multiple
//! of `k`, the CPUs in schedule order, each CPU's controllers in its
//! order. `cycles: N` runs N ticks. Before every tick, the external
//! buffers some controller of the run watches (`B.stale_cycles`) are
//! written again unless `silent:` holds them, as a live writer does.
//!
//! Expectations per controller are those of a one-controller scenario,
//! checked against that controller's last cycle ([`super::report`]).

use super::report::{plan_of, problems};
use super::run::note_fired;
use super::values::merge;
use super::{Called, Expect, Outcome};
use crate::interp::Value;
use crate::ir::*;
use rcs_runtime::driver::{DriveError, DrivenSystem, Record};
use serde_json::Value as Json;
use std::collections::{BTreeMap, BTreeSet};

/// A system scenario resolved against the IR.
pub struct SystemScenario {
    pub name: String,
    /// The controllers of the run, in id order.
    pub controllers: Vec<CtrlId>,
    /// Those whose supervisor is not in the run: the scenario commands them.
    pub roots: Vec<CtrlId>,
    pub(super) initial: SysStep,
    pub(super) steps: Vec<SysStep>,
}

#[derive(Default)]
pub(super) struct SysStep {
    pub(super) line: usize,
    pub(super) commands: Vec<(CtrlId, CommandId, Vec<Value>)>,
    pub(super) reads: Vec<(BufferId, Json)>,
    pub(super) silent: Vec<BufferId>,
    pub(super) hooks: Vec<(CtrlId, HookId, Value)>,
    /// `initial:` only.
    pub(super) vars: Vec<(CtrlId, usize, Value)>,
    pub(super) cycles: u64,
    /// Per controller, with the line of its key.
    pub(super) expect: Vec<(CtrlId, usize, Expect)>,
}

/// One system scenario's outcome.
#[derive(Debug)]
pub struct SystemOutcome {
    pub name: String,
    /// `None`: passed. Otherwise the line of the failing step and the
    /// report, one line per expectation that did not hold, each naming the
    /// step and the controller.
    pub failure: Option<(usize, String)>,
    /// Per controller of the run: its rows fired, coverage and time per
    /// state, as a one-controller scenario's [`Outcome`] (named after the
    /// controller).
    pub controllers: Vec<(CtrlId, Outcome)>,
    /// Ticks of the base period run.
    pub ticks: u64,
}

/// The CPUs that run a controller of `run`, each with how many base
/// periods its own period is, in schedule order; and the base period in
/// nanoseconds.
pub fn schedule(ir: &Ir, run: &[CtrlId]) -> (Vec<(String, u64)>, u64) {
    let cpus: Vec<&Cpu> = ir
        .schedule
        .iter()
        .filter(|cpu| cpu.order.iter().any(|c| run.contains(c)))
        .collect();
    let gcd = |mut a: u64, mut b: u64| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    let base = cpus.iter().fold(0, |g, cpu| gcd(g, cpu.period_ns)).max(1);
    let every = cpus
        .iter()
        .map(|cpu| (cpu.name.clone(), (cpu.period_ns / base).max(1)))
        .collect();
    (every, base)
}

/// Run a system scenario on the reference interpreter.
pub fn run_system(ir: &Ir, s: &SystemScenario) -> SystemOutcome {
    run_system_on(
        ir,
        s,
        &mut crate::interp::System::new(ir, &s.controllers),
        &mut |_, _| {},
    )
}

/// Run a system scenario on any backend, fresh, showing each controller
/// cycle's record to `on_cycle` (the differential test compares them).
pub fn run_system_on(
    ir: &Ir,
    s: &SystemScenario,
    d: &mut dyn DrivenSystem,
    on_cycle: &mut dyn FnMut(CtrlId, &Record),
) -> SystemOutcome {
    let mut out = SystemOutcome {
        name: s.name.clone(),
        failure: None,
        controllers: s
            .controllers
            .iter()
            .map(|c| {
                (
                    *c,
                    Outcome {
                        name: ir.controller(*c).name.clone(),
                        failure: None,
                        fired: Vec::new(),
                        rows: BTreeSet::new(),
                        hits: BTreeMap::new(),
                        states: BTreeMap::new(),
                    },
                )
            })
            .collect(),
        ticks: 0,
    };
    if let Err(failure) = drive(ir, s, d, &mut out, on_cycle) {
        out.failure = Some(failure);
    }
    out
}

/// What a controller did over the current step, for `hooks_called`.
#[derive(Default)]
struct StepCalls {
    counts: Vec<u64>,
    args: Vec<(u16, Vec<Value>)>,
    /// Hooks whose arguments are expected, and how many calls to keep.
    keep: Vec<(u16, usize)>,
}

fn drive(
    ir: &Ir,
    s: &SystemScenario,
    d: &mut dyn DrivenSystem,
    out: &mut SystemOutcome,
    on_cycle: &mut dyn FnMut(CtrlId, &Record),
) -> Result<(), (usize, String)> {
    let (cpus, _) = schedule(ir, &s.controllers);
    let mut external: Vec<Value> = ir
        .buffers
        .iter()
        .map(|b| crate::interp::zero(ir, &Type::Buffer(b.ty)))
        .collect();
    // External buffers some controller of the run watches: rewritten
    // before every tick unless held.
    let mut watched = vec![false; ir.buffers.len()];
    for c in &s.controllers {
        let ctrl = ir.controller(*c);
        for (i, w) in crate::watchdog::watched_reads(ctrl).iter().enumerate() {
            let b = ctrl.reads[i];
            let writer_in_run = ir.buffers[b.index()]
                .writer
                .is_some_and(|w| s.controllers.contains(&w));
            if *w && !writer_in_run {
                watched[b.index()] = true;
            }
        }
    }
    let mut held = vec![false; ir.buffers.len()];
    let mut latest: BTreeMap<CtrlId, u32> = BTreeMap::new();
    let mut last: BTreeMap<CtrlId, Record> = BTreeMap::new();
    let index: BTreeMap<CtrlId, usize> = s
        .controllers
        .iter()
        .enumerate()
        .map(|(i, c)| (*c, i))
        .collect();
    let mut tick = 0u64;
    for (k, step) in std::iter::once(&s.initial).chain(&s.steps).enumerate() {
        let line = step.line;
        let fail = |e: DriveError| (line, e.to_string());
        for (c, cmd, args) in &step.commands {
            let ctrl = ir.controller(*c);
            let serial = d
                .command(&ctrl.name, &ctrl.commands[cmd.index()].name, args)
                .map_err(fail)?;
            latest.insert(*c, serial);
        }
        for (b, v) in &step.reads {
            let buf = &ir.buffers[b.index()];
            let merged = merge(
                ir,
                line,
                &external[b.index()],
                &Type::Buffer(buf.ty),
                v,
                &buf.name,
            )
            .map_err(|e| (e.line, e.message))?;
            d.set_read(&buf.name, &merged).map_err(fail)?;
            external[b.index()] = merged;
            held[b.index()] = false;
        }
        for b in &step.silent {
            held[b.index()] = true;
        }
        for (c, h, v) in &step.hooks {
            let ctrl = ir.controller(*c);
            d.set_hook(&ctrl.name, &ctrl.hooks[h.index()].name, v)
                .map_err(fail)?;
        }
        for (c, i, v) in &step.vars {
            let ctrl = ir.controller(*c);
            d.set_var(&ctrl.name, &ctrl.vars[*i].name, v)
                .map_err(fail)?;
        }
        if k == 0 {
            continue; // `initial` sets the scene; it runs no cycle.
        }
        let mut calls: BTreeMap<CtrlId, StepCalls> = BTreeMap::new();
        for (c, _, e) in &step.expect {
            let entry = calls.entry(*c).or_default();
            entry.counts = vec![0; ir.controller(*c).hooks.len()];
            for (h, called) in &e.hooks_called {
                if let Called::With(list) = called {
                    entry.keep.push((h.0 as u16, list.len() + 1));
                }
            }
        }
        for _ in 0..step.cycles {
            for (b, w) in watched.iter().enumerate() {
                if *w && !held[b] {
                    d.set_read(&ir.buffers[b].name, &external[b])
                        .map_err(fail)?;
                }
            }
            for (cpu, every) in &cpus {
                if !tick.is_multiple_of(*every) {
                    continue;
                }
                for (name, rec) in d.run_cpu(cpu).map_err(fail)? {
                    let Some(c) = ir.controller_by_name(&name) else {
                        continue;
                    };
                    let Some(i) = index.get(&c) else { continue };
                    let ctrl = ir.controller(c);
                    note_fired(ctrl, &rec, &mut out.controllers[*i].1);
                    on_cycle(c, &rec);
                    if let Some(sc) = calls.get_mut(&c) {
                        for (h, args) in &rec.hook_args {
                            let limit = sc.keep.iter().find(|(k, _)| k == h).map(|(_, n)| *n);
                            let kept = sc.args.iter().filter(|(k, _)| k == h).count();
                            if limit.is_some_and(|n| kept < n) {
                                sc.args.push((*h, args.clone()));
                            }
                        }
                        for (total, n) in sc.counts.iter_mut().zip(&rec.hook_calls) {
                            *total = total.saturating_add(u64::from(*n));
                        }
                    }
                    last.insert(c, rec);
                }
            }
            tick += 1;
            out.ticks = tick;
        }
        let mut report = Vec::new();
        for (c, _, e) in &step.expect {
            let ctrl = ir.controller(*c);
            let Some(rec) = last.get(c) else {
                report.push(format!(
                    "step {k}, {}: has not run a cycle yet (its CPU runs every {} ticks)",
                    ctrl.name,
                    every_of(ir, &cpus, *c)
                ));
                continue;
            };
            let seen = match latest.get(c) {
                Some(serial) => *serial,
                // A controller commanded inside the run: its supervisor
                // sees the latest command it sent, answered or refused.
                None => rec.echo_serial.max(rec.refused_serial),
            };
            let sc = calls.remove(c).unwrap_or_default();
            for p in problems(ir, ctrl, e, rec, seen, (&sc.counts, &sc.args)) {
                report.push(format!("step {k}, {}: {p}", ctrl.name));
            }
        }
        if !report.is_empty() {
            return Err((line, report.join("\n")));
        }
    }
    Ok(())
}

/// How many ticks apart controller `c`'s CPU runs.
fn every_of(ir: &Ir, cpus: &[(String, u64)], c: CtrlId) -> u64 {
    ir.schedule
        .iter()
        .find(|cpu| cpu.order.contains(&c))
        .and_then(|cpu| cpus.iter().find(|(n, _)| *n == cpu.name))
        .map_or(1, |(_, e)| *e)
}

/// The name of the state a record shows `c` in (`S0` before any command).
pub fn state_name(c: &Controller, rec: &Record) -> String {
    plan_of(c, rec)
        .and_then(|p| p.states.get(usize::from(rec.state)))
        .map_or_else(|| "S0".to_string(), |s| s.name.clone())
}
