//! Several interpreted controllers run together, as a plan set (or a
//! subtree of it) runs on its executives: what a system scenario drives on
//! the interpreter (`rcs_runtime::driver::DrivenSystem`). Each controller
//! is an [`Interpreter`] behind [`Driven`] (so hooks are scripted as for
//! one controller); between them sits a model of Global Memory that holds
//! what generated code writes in step 5 of each cycle — the status buffer,
//! the status fields, the `writes` buffers, and the command buffer of each
//! subordinate a command was sent to — each with its write generation, and
//! hands each controller, before its cycle, what changed since it last
//! read. A controller therefore sees what the controllers before it in the
//! same CPU cycle wrote at once, and the others' writes of their latest
//! cycle, exactly as on the executives. The caller owns the schedule: it
//! asks for one CPU's cycle at a time.

use super::{Driven, Interpreter, Value};
use crate::ir::*;
use rcs_runtime::driver::{unknown, DriveError, DrivenSystem, Record};
use rcs_runtime::{Stamped, StatusBuffer};

/// A command buffer in Global Memory, written by an interpreted supervisor.
#[derive(Clone)]
struct CommandSlot {
    serial: u32,
    epoch: u32,
    verb: CommandId,
    args: Vec<Value>,
    generation: u64,
}

/// What a controller of the run last took from Global Memory: the
/// generation of each thing it reads.
struct Seen {
    reads: Vec<u64>,
    subs: Vec<u64>,
    command: u64,
}

/// The controllers of a run, interpreted, on a model of Global Memory.
pub struct System<'ir> {
    ir: &'ir Ir,
    /// By controller id: `Some` for the controllers of the run.
    ctrls: Vec<Option<Driven<'ir>>>,
    seen: Vec<Seen>,
    /// Every buffer of the plan set and its write generation.
    buffers: Vec<(Value, u64)>,
    /// Each controller's published status buffer.
    status: Vec<Stamped<StatusBuffer>>,
    /// Each controller's published status fields.
    fields: Vec<Vec<(VarId, Value)>>,
    /// Each controller's command buffer, when its supervisor is in the run.
    commands: Vec<Option<CommandSlot>>,
}

impl<'ir> System<'ir> {
    /// The controllers `run` of `ir`, fresh (vars at their initialisers,
    /// every buffer zero). `run` should be closed under "subordinate of"
    /// (a set of whole subtrees); a subordinate left out is never answered.
    pub fn new(ir: &'ir Ir, run: &[CtrlId]) -> System<'ir> {
        let n = ir.controllers.len();
        let ctrls = (0..n)
            .map(|i| {
                let id = CtrlId(i as u32);
                run.contains(&id).then(|| Driven::new(ir, id))
            })
            .collect();
        let seen = ir
            .controllers
            .iter()
            .map(|c| Seen {
                reads: vec![0; c.reads.len()],
                subs: vec![0; c.subordinates.len()],
                command: 0,
            })
            .collect();
        System {
            ir,
            ctrls,
            seen,
            buffers: ir
                .buffers
                .iter()
                .map(|b| (super::zero(ir, &Type::Buffer(b.ty)), 0))
                .collect(),
            status: vec![Stamped::default(); n],
            fields: ir
                .controllers
                .iter()
                .map(|c| {
                    c.status_fields()
                        .map(|(id, v)| (id, super::zero(ir, &v.ty)))
                        .collect()
                })
                .collect(),
            commands: vec![None; n],
        }
    }

    /// Whether `c` is in the run and its supervisor is not: the scenario
    /// plays that supervisor.
    pub fn is_root(&self, c: CtrlId) -> bool {
        self.ctrls[c.index()].is_some()
            && self
                .ir
                .controller(c)
                .supervisor
                .is_none_or(|s| self.ctrls[s.index()].is_none())
    }

    /// The interpreter of controller `c`, if it is in the run.
    pub fn interpreter(&self, c: CtrlId) -> Option<&Interpreter<'ir>> {
        self.ctrls[c.index()].as_ref().map(Driven::interpreter)
    }

    fn driven(&mut self, name: &str) -> Result<(CtrlId, &mut Driven<'ir>), DriveError> {
        let id = self
            .ir
            .controller_by_name(name)
            .filter(|id| self.ctrls[id.index()].is_some())
            .ok_or_else(|| unknown("the run", "controller", name))?;
        let d = self.ctrls[id.index()]
            .as_mut()
            .ok_or_else(|| unknown("the run", "controller", name))?;
        Ok((id, d))
    }

    /// One cycle of controller `c`: what changed in Global Memory in,
    /// the cycle, its step 5 out.
    fn cycle_one(&mut self, c: CtrlId) -> Option<Record> {
        let ir = self.ir;
        let ctrl = ir.controller(c);
        let root = self.is_root(c);
        let d = self.ctrls[c.index()].as_mut()?;
        let seen = &mut self.seen[c.index()];
        let interp = d.interpreter_mut();
        for (i, b) in ctrl.reads.iter().enumerate() {
            let (value, generation) = &self.buffers[b.index()];
            if *generation != seen.reads[i] {
                seen.reads[i] = *generation;
                interp.set_read(i, value.clone());
            }
        }
        if !root {
            if let Some(cmd) = &self.commands[c.index()] {
                if cmd.generation != seen.command {
                    seen.command = cmd.generation;
                    interp.receive(cmd.serial, cmd.epoch, cmd.verb, cmd.args.clone());
                }
            }
        }
        for (i, s) in ctrl.subordinates.iter().enumerate() {
            let status = &self.status[s.index()];
            if status.generation != seen.subs[i] {
                seen.subs[i] = status.generation;
                interp.write_sub_status(i, status.value);
                for (var, v) in &self.fields[s.index()] {
                    interp.write_sub_field(i, *var, v.clone());
                }
            }
        }
        let rec = rcs_runtime::driver::Driven::cycle(d);
        // Step 5: status, status fields, `writes` buffers, commands sent.
        let interp = d.interpreter();
        let status = &mut self.status[c.index()];
        status.value = interp.bookkeeping().status_buffer();
        status.generation += 1;
        status.writer_cycle = rec.cycle;
        self.fields[c.index()] = interp.status_fields();
        for (i, b) in ctrl.writes.iter().enumerate() {
            let slot = &mut self.buffers[b.index()];
            slot.0 = interp.writes()[i].clone();
            slot.1 += 1;
        }
        for s in &rec.sent {
            let sub = ctrl.subordinates[usize::from(s.sub)];
            let generation = self.commands[sub.index()]
                .as_ref()
                .map_or(0, |x| x.generation);
            self.commands[sub.index()] = Some(CommandSlot {
                serial: s.serial,
                epoch: interp.sent_epoch(usize::from(s.sub)),
                verb: CommandId(u32::from(s.verb)),
                args: s.args.clone(),
                generation: generation + 1,
            });
        }
        Some(rec)
    }
}

impl DrivenSystem for System<'_> {
    fn command(&mut self, root: &str, verb: &str, args: &[Value]) -> Result<u32, DriveError> {
        let (id, _) = self.driven(root)?;
        if !self.is_root(id) {
            return Err(unknown("the run", "root controller", root));
        }
        let (_, d) = self.driven(root)?;
        rcs_runtime::driver::Driven::command(d, verb, args)
    }

    fn set_read(&mut self, buffer: &str, value: &Value) -> Result<(), DriveError> {
        let ir = self.ir;
        let b = ir
            .buffers
            .iter()
            .position(|b| b.name == buffer)
            .filter(|b| {
                ir.buffers[*b]
                    .writer
                    .is_none_or(|w| self.ctrls[w.index()].is_none())
            })
            .ok_or_else(|| unknown("the run", "external buffer", buffer))?;
        let v = super::conform(ir, &Type::Buffer(ir.buffers[b].ty), value).ok_or_else(|| {
            DriveError::Type {
                controller: "the run".to_string(),
                what: buffer.to_string(),
            }
        })?;
        let slot = &mut self.buffers[b];
        slot.0 = v;
        slot.1 += 1;
        Ok(())
    }

    fn set_hook(&mut self, controller: &str, hook: &str, value: &Value) -> Result<(), DriveError> {
        let (_, d) = self.driven(controller)?;
        rcs_runtime::driver::Driven::set_hook(d, hook, value)
    }

    fn set_var(&mut self, controller: &str, var: &str, value: &Value) -> Result<(), DriveError> {
        let (_, d) = self.driven(controller)?;
        rcs_runtime::driver::Driven::set_var(d, var, value)
    }

    fn run_cpu(&mut self, cpu: &str) -> Result<Vec<(String, Record)>, DriveError> {
        let ir = self.ir;
        let cpu = ir
            .schedule
            .iter()
            .find(|x| x.name == cpu)
            .ok_or_else(|| unknown("the run", "CPU", cpu))?;
        let mut out = Vec::new();
        for c in &cpu.order {
            if let Some(rec) = self.cycle_one(*c) {
                out.push((ir.controller(*c).name.clone(), rec));
            }
        }
        Ok(out)
    }
}
