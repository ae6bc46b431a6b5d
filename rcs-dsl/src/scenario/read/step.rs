//! Reading one step of a one-controller scenario (and its `initial:`):
//! the command it sends, the `reads` buffers, hooks and subordinates it
//! sets, `silent:`, `cycles:`, and the vars and `writes` buffers it gives.

use super::{entries, line_of, silent_names, Entries, RawExpect, Resolver};
use crate::interp::{zero, Value};
use crate::ir::*;
use crate::scenario::values::{merge, value, verb_call};
use crate::scenario::{err, Expect, ScenarioError, Step, MAX_CYCLES};
use crate::yaml::Spanned;
use serde_json::Value as Json;

impl Resolver<'_> {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn step(
        &self,
        line: usize,
        command: Option<Spanned<Json>>,
        reads: Option<Entries>,
        hooks: Option<Entries>,
        subs: Option<Entries>,
        cycles: Option<Spanned<Json>>,
        expect: Option<RawExpect>,
    ) -> Result<Step, ScenarioError> {
        let command = command
            .map(|c| self.command(line_of(&c), &c.value))
            .transpose()?;
        let read_list = self.buffer_entries(&reads, &self.c.reads, "reads")?;
        let mut hook_list = Vec::new();
        for (line, name, v) in entries(&hooks) {
            let h = self
                .c
                .hooks
                .iter()
                .position(|h| h.name == *name)
                .ok_or_else(|| err(line, format!("`{}` has no hook `{name}`", self.c.name)))?;
            let value = value(self.ir, line, &self.c.hooks[h].ret, v, name)?;
            hook_list.push((HookId(h as u32), value));
        }
        let mut sub_list = Vec::new();
        for (line, name, v) in entries(&subs) {
            let i = self.sub_index(line, name)?;
            let sub = self.ir.controller(self.c.subordinates[i]);
            sub_list.push((i, self.sub_setting(line, sub, v)?));
        }
        let expect = match expect {
            Some(e) => self.expect(e)?,
            None => Expect::default(),
        };
        Ok(Step {
            line,
            command,
            reads: read_list,
            hooks: hook_list,
            subs: sub_list,
            silent: Vec::new(),
            vars: Vec::new(),
            writes: Vec::new(),
            cycles: cycles.map_or(Ok(1), |c| self.cycles(&c))?,
            expect,
        })
    }

    /// `silent: [B, …]`: the `reads` buffers named, by index in `reads`,
    /// with the line of the key.
    pub(super) fn silent(&self, v: &Spanned<Json>) -> Result<(usize, Vec<usize>), ScenarioError> {
        let line = line_of(v);
        let names = silent_names(v, "`reads` buffers")?;
        let mut out = Vec::new();
        for name in names {
            let i = self
                .c
                .reads
                .iter()
                .position(|b| self.ir.buffers[b.index()].name == name)
                .ok_or_else(|| {
                    let hint = if self.ir.controller_by_name(name).is_some() {
                        format!("; a subordinate is held with `subordinates: {{ {name}: {{ silent: true }} }}`")
                    } else {
                        String::new()
                    };
                    err(line, format!("`{}` reads no buffer `{name}`{hint}", self.c.name))
                })?;
            out.push(i);
        }
        Ok((line, out))
    }

    /// `cycles: N`, 1 to [`MAX_CYCLES`].
    pub(in crate::scenario) fn cycles(&self, c: &Spanned<Json>) -> Result<u64, ScenarioError> {
        let n = match &c.value {
            Json::Number(n) => n.as_u64(),
            _ => None,
        };
        n.filter(|n| (1..=MAX_CYCLES).contains(n)).ok_or_else(|| {
            err(
                line_of(c),
                format!(
                    "`cycles` is a whole number from 1 to {MAX_CYCLES}, not `{}`",
                    c.value
                ),
            )
        })
    }

    /// `vars:` (in `initial:` and `expect:`): each a whole value.
    pub(in crate::scenario) fn vars(
        &self,
        e: &Option<Entries>,
    ) -> Result<Vec<(usize, Value)>, ScenarioError> {
        let mut out = Vec::new();
        for (line, name, v) in entries(e) {
            let i = self
                .c
                .vars
                .iter()
                .position(|x| x.name == *name)
                .ok_or_else(|| err(line, format!("`{}` has no var `{name}`", self.c.name)))?;
            out.push((i, value(self.ir, line, &self.c.vars[i].ty, v, name)?));
        }
        Ok(out)
    }

    /// `writes:` (in `initial:` and `expect:`): fields of the controller's
    /// own buffers, checked now and merged when used.
    pub(super) fn writes(&self, e: &Option<Entries>) -> Result<Vec<(usize, Json)>, ScenarioError> {
        self.buffer_entries(e, &self.c.writes, "writes")
    }

    /// The entries of a `reads:` or `writes:` mapping: each buffer's index
    /// in `buffers` (the controller's list `what` names) and its value.
    fn buffer_entries(
        &self,
        e: &Option<Entries>,
        buffers: &[BufferId],
        what: &str,
    ) -> Result<Vec<(usize, Json)>, ScenarioError> {
        let mut out = Vec::new();
        for (line, name, v) in entries(e) {
            let i = buffers
                .iter()
                .position(|b| self.ir.buffers[b.index()].name == *name)
                .ok_or_else(|| err(line, format!("`{}` {what} no buffer `{name}`", self.c.name)))?;
            // Check the shape now; values merge into the current buffer when run.
            let ty = Type::Buffer(self.ir.buffers[buffers[i].index()].ty);
            merge(self.ir, line, &zero(self.ir, &ty), &ty, v, name)?;
            out.push((i, v.clone()));
        }
        Ok(out)
    }

    /// `INIT` or `{ AHEAD: { speed: 10.0 } }`.
    pub(super) fn command(
        &self,
        line: usize,
        v: &Json,
    ) -> Result<(CommandId, Vec<Value>), ScenarioError> {
        verb_call(self.ir, self.c, line, v, || {
            "`command` is a verb (`INIT`) or `{ VERB: { param: value } }`".to_string()
        })
    }
}
