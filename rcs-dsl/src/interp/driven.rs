//! The interpreter behind the driver interface the generated `Driver`s
//! implement too (`rcs_runtime::driver::Driven`): what scenarios and the
//! differential test run a controller through, with scripted hooks.

use super::{conform, zero, HookData, Hooks, Interpreter};
use crate::ir::*;
use rcs_runtime::driver::Value;
use rcs_runtime::{ErrorCode, Status, StatusBuffer};

/// The interpreter as a [`Driven`](rcs_runtime::driver::Driven) controller,
/// the interface the generated `Driver`s implement too: names resolved
/// against the IR, values checked against their declared types, and hooks
/// that return what the caller last set (their type's zero before that).
pub struct Driven<'ir> {
    ir: &'ir Ir,
    interp: Interpreter<'ir>,
    hooks: Scripted<'ir>,
}

struct Scripted<'ir> {
    ir: &'ir Ir,
    values: Vec<Option<Value>>,
    /// Calls of each hook since the last cycle's record.
    calls: Vec<u32>,
    /// Those calls' arguments, in order.
    args: Vec<(u16, Vec<Value>)>,
}

impl Hooks for Scripted<'_> {
    fn call(&mut self, data: &HookData, hook: HookId, args: &[Value]) -> Value {
        self.calls[hook.index()] = self.calls[hook.index()].saturating_add(1);
        self.args.push((hook.0 as u16, args.to_vec()));
        self.values[hook.index()]
            .clone()
            .unwrap_or_else(|| zero(self.ir, &data.ctrl.hooks[hook.index()].ret))
    }
}

impl<'ir> Driven<'ir> {
    /// Controller `ctrl`, fresh (as [`Interpreter::new`]).
    pub fn new(ir: &'ir Ir, ctrl: CtrlId) -> Driven<'ir> {
        let interp = Interpreter::new(ir, ctrl);
        let hooks = Scripted {
            ir,
            values: vec![None; interp.controller().hooks.len()],
            calls: vec![0; interp.controller().hooks.len()],
            args: Vec::new(),
        };
        Driven { ir, interp, hooks }
    }

    /// The interpreter underneath.
    pub fn interpreter(&self) -> &Interpreter<'ir> {
        &self.interp
    }

    /// The interpreter underneath, to feed it what a system run's Global
    /// Memory holds ([`super::System`]).
    pub(super) fn interpreter_mut(&mut self) -> &mut Interpreter<'ir> {
        &mut self.interp
    }

    fn sub_index(&self, sub: &str) -> Result<usize, rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        self.ir
            .controller_by_name(sub)
            .and_then(|id| c.subordinate_index(id))
            .ok_or_else(|| rcs_runtime::driver::unknown(&c.name, "subordinate", sub))
    }

    /// Buffer `name` of `list` (the controller's `reads` or `writes`):
    /// its index and `value` typed as it.
    fn buffer_value(
        &self,
        list: &[BufferId],
        kind: &str,
        name: &str,
        value: &Value,
    ) -> Result<(usize, Value), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let i = position_of(c, list, |b| &self.ir.buffers[b.index()].name, kind, name)?;
        let ty = Type::Buffer(self.ir.buffers[list[i].index()].ty);
        Ok((i, self.typed(&ty, name, value)?))
    }

    fn typed(
        &self,
        t: &Type,
        what: &str,
        v: &Value,
    ) -> Result<Value, rcs_runtime::driver::DriveError> {
        conform(self.ir, t, v).ok_or_else(|| rcs_runtime::driver::DriveError::Type {
            controller: self.interp.controller().name.clone(),
            what: what.to_string(),
        })
    }
}

/// Where the entry called `name` stands in `list` (one of controller
/// `c`'s declarations), or the driver's error for an unknown `kind`.
fn position_of<'l, T>(
    c: &Controller,
    list: &'l [T],
    name_of: impl Fn(&'l T) -> &'l str,
    kind: &str,
    name: &str,
) -> Result<usize, rcs_runtime::driver::DriveError> {
    list.iter()
        .position(|x| name_of(x) == name)
        .ok_or_else(|| rcs_runtime::driver::unknown(&c.name, kind, name))
}

impl rcs_runtime::driver::Driven for Driven<'_> {
    fn name(&self) -> &str {
        &self.interp.controller().name
    }

    fn command(
        &mut self,
        verb: &str,
        args: &[Value],
    ) -> Result<u32, rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let id = position_of(c, &c.commands, |k| &k.name, "verb", verb)?;
        let cmd = &c.commands[id];
        rcs_runtime::driver::arity(&c.name, verb, args, cmd.params.len())?;
        let args = cmd
            .params
            .iter()
            .zip(args)
            .map(|(p, a)| self.typed(&p.ty, &format!("{verb}.{}", p.name), a))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(self.interp.command(CommandId(id as u32), args))
    }

    fn set_read(
        &mut self,
        buffer: &str,
        value: &Value,
    ) -> Result<(), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let (i, v) = self.buffer_value(&c.reads, "read buffer", buffer, value)?;
        self.interp.set_read(i, v);
        Ok(())
    }

    fn set_hook(
        &mut self,
        hook: &str,
        value: &Value,
    ) -> Result<(), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let i = position_of(c, &c.hooks, |h| &h.name, "hook", hook)?;
        let v = self.typed(&c.hooks[i].ret, hook, value)?;
        self.hooks.values[i] = Some(v);
        Ok(())
    }

    fn set_var(&mut self, var: &str, value: &Value) -> Result<(), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let i = position_of(c, &c.vars, |v| &v.name, "var", var)?;
        let v = self.typed(&c.vars[i].ty, var, value)?;
        self.interp.vars[i] = v;
        Ok(())
    }

    fn set_write(
        &mut self,
        buffer: &str,
        value: &Value,
    ) -> Result<(), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        let (i, v) = self.buffer_value(&c.writes, "write buffer", buffer, value)?;
        self.interp.writes[i] = v;
        Ok(())
    }

    fn write_sub_status(
        &mut self,
        sub: &str,
        status: StatusBuffer,
    ) -> Result<(), rcs_runtime::driver::DriveError> {
        let i = self.sub_index(sub)?;
        let mut status = status;
        if status.echo_epoch == 0 {
            // Scenarios name serials only: the echo is in the epoch of this
            // controller's commands to `sub` (`Driven::write_sub_status`).
            status.echo_epoch = self.interp.sent_epoch(i);
        }
        if status.refused_serial != 0 && status.refused_epoch == 0 {
            status.refused_epoch = self.interp.sent_epoch(i);
        }
        self.interp.write_sub_status(i, status);
        Ok(())
    }

    fn last_sent(&mut self, sub: &str) -> Result<u32, rcs_runtime::driver::DriveError> {
        Ok(self.interp.last_sent(self.sub_index(sub)?))
    }

    fn write_sub_field(
        &mut self,
        sub: &str,
        field: &str,
        value: &Value,
    ) -> Result<(), rcs_runtime::driver::DriveError> {
        let c = self.interp.controller();
        // An unknown subordinate and an unknown field read alike: `X.NAME`.
        let unknown =
            || rcs_runtime::driver::unknown(&c.name, "status field", &format!("{sub}.{field}"));
        let i = self.sub_index(sub).map_err(|_| unknown())?;
        let s = self.ir.controller(c.subordinates[i]);
        let (id, var) = s
            .status_fields()
            .find(|(_, v)| v.name == field)
            .ok_or_else(unknown)?;
        let v = self.typed(&var.ty, &format!("{sub}.{field}"), value)?;
        self.interp.write_sub_field(i, id, v);
        Ok(())
    }

    fn cycle(&mut self) -> rcs_runtime::driver::Record {
        let rec = self.interp.cycle(&mut self.hooks);
        let hook_calls = self.hooks.calls.clone();
        self.hooks.calls.fill(0);
        let hook_args = std::mem::take(&mut self.hooks.args);
        let c = self.interp.controller();
        rcs_runtime::driver::Record {
            cycle: rec.cycle,
            verb: rec.verb.map(|v| v.0 as u16),
            fired: rec.fired.map(|r| r.0 as u16),
            state: rec.state.0 as u16,
            status: Status(rec.status.0 as u16),
            error: ErrorCode(rec.error.unwrap_or(0)),
            echo_serial: self.interp.bookkeeping().echo_serial(),
            refused_serial: self.interp.bookkeeping().refused_serial(),
            sent: rec
                .sent
                .into_iter()
                .map(|s| rcs_runtime::driver::Sent {
                    sub: c.subordinate_index(s.sub).unwrap_or(0) as u16,
                    verb: s.command.0 as u16,
                    args: s.args,
                    serial: s.serial,
                })
                .collect(),
            vars: rec.vars,
            writes: rec.writes,
            hook_calls,
            hook_args,
        }
    }
}
