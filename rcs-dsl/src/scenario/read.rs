//! Reading a scenario: the first part of `rcsc test` after the plans are
//! checked. The YAML (through [`crate::yaml`], booleans only `true` and
//! `false`, so that `command: ON` is a verb) is read into raw types, then
//! every name is resolved against the controller of the IR and every value
//! typed ([`super::values`]), so that a scenario that runs names only what
//! exists. Every problem is a [`ScenarioError`] with its line.

use super::report::{row_aliases, row_name};
use super::values::{merge, value, verb_call};
use super::{err, Called, Echo, Expect, Scenario, ScenarioError, Step, SubSetting, MAX_CYCLES};
use crate::interp::{zero, Value};
use crate::ir::*;
use crate::source::SourceFile;
use crate::yaml::{self, Spanned};
use serde::Deserialize;
use serde_json::Value as Json;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    name: Option<String>,
    controller: Spanned<String>,
    initial: Option<RawSettings>,
    steps: Vec<Spanned<RawStep>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSettings {
    reads: Option<Entries>,
    hooks: Option<Entries>,
    subordinates: Option<Entries>,
    vars: Option<Entries>,
    writes: Option<Entries>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStep {
    command: Option<Spanned<Json>>,
    reads: Option<Entries>,
    hooks: Option<Entries>,
    subordinates: Option<Entries>,
    /// `silent: [B, …]`: `reads` buffers held unwritten (LANGUAGE.md §8).
    silent: Option<Spanned<Json>>,
    cycles: Option<Spanned<Json>>,
    expect: Option<RawExpect>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawExpect {
    fired: Option<Spanned<Json>>,
    state: Option<Spanned<String>>,
    status: Option<Spanned<String>>,
    error: Option<Spanned<String>>,
    answered: Option<Spanned<Json>>,
    sent: Option<Entries>,
    vars: Option<Entries>,
    writes: Option<Entries>,
    hooks_called: Option<Entries>,
    /// The controller's own status fields, each a whole value.
    status_fields: Option<Entries>,
}

/// A YAML mapping of names to values (`reads:`, `hooks:`, `sent:` …), in
/// file order, each entry with the line of its key, so that a name the
/// plans lack is reported on its own line.
#[derive(Default)]
pub(super) struct Entries(pub(super) Vec<Entry>);

pub(super) struct Entry {
    pub(super) line: usize,
    pub(super) name: String,
    pub(super) value: Json,
}

impl<'de> Deserialize<'de> for Entries {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = Entries;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a mapping of names to values")
            }
            fn visit_unit<E>(self) -> Result<Entries, E> {
                Ok(Entries::default())
            }
            fn visit_none<E>(self) -> Result<Entries, E> {
                Ok(Entries::default())
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut m: A,
            ) -> Result<Entries, A::Error> {
                let mut out = Vec::new();
                // Duplicate keys are refused by the YAML reader itself.
                while let Some(key) = m.next_key::<Spanned<String>>()? {
                    out.push(Entry {
                        line: line_of(&key),
                        name: key.value,
                        value: m.next_value()?,
                    });
                }
                Ok(Entries(out))
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// The line a scenario value was written on.
pub(super) fn line_of<T>(s: &Spanned<T>) -> usize {
    s.referenced.line() as usize
}

/// The entries of an optional mapping: (line of the key, name, value).
pub(super) fn entries(e: &Option<Entries>) -> impl Iterator<Item = (usize, &str, &Json)> {
    e.as_ref()
        .map_or(&[][..], |e| &e.0)
        .iter()
        .map(|e| (e.line, e.name.as_str(), &e.value))
}

/// A scenario of either kind: one controller, or a run of several
/// (`system: true`, `controllers: [...]`).
pub enum AnyScenario {
    One(Scenario),
    System(super::SystemScenario),
}

impl AnyScenario {
    pub fn name(&self) -> &str {
        match self {
            AnyScenario::One(s) => &s.name,
            AnyScenario::System(s) => &s.name,
        }
    }
}

/// Read and resolve a scenario of either kind: a file with `system:` or
/// `controllers:` at the top is a system scenario.
pub fn parse_any(ir: &Ir, file: &SourceFile, stem: &str) -> Result<AnyScenario, ScenarioError> {
    if super::system_read::is_system(&file.text) {
        super::system_read::parse_system(ir, &file.text, stem).map(AnyScenario::System)
    } else {
        parse(ir, file, stem).map(AnyScenario::One)
    }
}

/// Read and resolve a one-controller scenario. `stem` names it when it has
/// no `name:`. A system scenario is refused: read it with [`parse_any`].
pub fn parse(ir: &Ir, file: &SourceFile, stem: &str) -> Result<Scenario, ScenarioError> {
    if super::system_read::is_system(&file.text) {
        return Err(err(
            1,
            "a system scenario (`system:` or `controllers:`), not one of one controller",
        ));
    }
    let raw: RawScenario = yaml::from_str_names(&file.text)
        .map_err(|e| err(e.location.map_or(1, |l| l.line() as usize), e.message))?;
    let cline = line_of(&raw.controller);
    let ctrl = ir
        .controller_by_name(&raw.controller.value)
        .ok_or_else(|| {
            err(
                cline,
                format!("unknown controller `{}`", raw.controller.value),
            )
        })?;
    let r = Resolver {
        ir,
        c: ir.controller(ctrl),
    };
    let s = raw.initial.unwrap_or_default();
    let mut initial = r.step(cline, None, s.reads, s.hooks, s.subordinates, None, None)?;
    initial.vars = r.vars(&s.vars)?;
    initial.writes = r.writes(&s.writes)?;
    let mut steps = Vec::new();
    for s in raw.steps {
        let line = line_of(&s);
        let v = s.value;
        let silent = v.silent.as_ref().map(|s| r.silent(s)).transpose()?;
        let mut step = r.step(
            line,
            v.command,
            v.reads,
            v.hooks,
            v.subordinates,
            v.cycles,
            v.expect,
        )?;
        if let Some((at, silent)) = silent {
            if let Some((i, _)) = step.reads.iter().find(|(i, _)| silent.contains(i)) {
                let name = &ir.buffers[r.c.reads[*i].index()].name;
                return Err(err(
                    at,
                    format!("`{name}` is both written (`reads:`) and `silent:` in one step; write it again in a later step"),
                ));
            }
            step.silent = silent;
        }
        steps.push(step);
    }
    Ok(Scenario {
        name: raw.name.unwrap_or_else(|| stem.to_string()),
        controller: ctrl,
        initial,
        steps,
    })
}

pub(super) struct Resolver<'a> {
    pub(super) ir: &'a Ir,
    pub(super) c: &'a Controller,
}

impl Resolver<'_> {
    #[allow(clippy::too_many_arguments)]
    fn step(
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
        let mut read_list = Vec::new();
        for (line, name, v) in entries(&reads) {
            let i = self
                .c
                .reads
                .iter()
                .position(|b| self.ir.buffers[b.index()].name == *name)
                .ok_or_else(|| err(line, format!("`{}` reads no buffer `{name}`", self.c.name)))?;
            // Check the shape now; values merge into the current buffer when run.
            let ty = Type::Buffer(self.ir.buffers[self.c.reads[i].index()].ty);
            merge(self.ir, line, &zero(self.ir, &ty), &ty, v, name)?;
            read_list.push((i, v.clone()));
        }
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
    fn silent(&self, v: &Spanned<Json>) -> Result<(usize, Vec<usize>), ScenarioError> {
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
    pub(super) fn cycles(&self, c: &Spanned<Json>) -> Result<u64, ScenarioError> {
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
    pub(super) fn vars(&self, e: &Option<Entries>) -> Result<Vec<(usize, Value)>, ScenarioError> {
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

    /// `status_fields:` (in `expect:`): the controller's own status fields
    /// (`status NAME: TYPE`), each a whole value, as they stand after the
    /// step (what step 5 published).
    fn status_fields(&self, e: &Option<Entries>) -> Result<Vec<(usize, Value)>, ScenarioError> {
        let mut out = Vec::new();
        for (line, name, v) in entries(e) {
            let (id, f) = self
                .c
                .status_fields()
                .find(|(_, x)| x.name == *name)
                .ok_or_else(|| {
                    err(
                        line,
                        format!("`{}` has no status field `{name}`", self.c.name),
                    )
                })?;
            out.push((id.index(), value(self.ir, line, &f.ty, v, name)?));
        }
        Ok(out)
    }

    /// `writes:` (in `initial:` and `expect:`): fields of the controller's
    /// own buffers, checked now and merged when used.
    fn writes(&self, e: &Option<Entries>) -> Result<Vec<(usize, Json)>, ScenarioError> {
        let mut out = Vec::new();
        for (line, name, v) in entries(e) {
            let i = self
                .c
                .writes
                .iter()
                .position(|b| self.ir.buffers[b.index()].name == *name)
                .ok_or_else(|| err(line, format!("`{}` writes no buffer `{name}`", self.c.name)))?;
            let ty = Type::Buffer(self.ir.buffers[self.c.writes[i].index()].ty);
            merge(self.ir, line, &zero(self.ir, &ty), &ty, v, name)?;
            out.push((i, v.clone()));
        }
        Ok(out)
    }

    /// `hooks_called.NAME`: a count, or a list of calls, each a mapping of
    /// parameter names to the arguments expected.
    fn called(&self, line: usize, hook: &Hook, v: &Json) -> Result<Called, ScenarioError> {
        let shape = || {
            err(
                line,
                format!(
                    "`hooks_called.{}` is how many times the step called it (0 or more), or its calls: `[{{ param: value }}, …]`",
                    hook.name
                ),
            )
        };
        let calls = match v {
            Json::Number(n) => return n.as_u64().map(Called::Times).ok_or_else(shape),
            Json::Array(calls) => calls,
            _ => return Err(shape()),
        };
        let mut out = Vec::new();
        for call in calls {
            let Json::Object(m) = call else {
                return Err(shape());
            };
            let mut args = vec![None; hook.params.len()];
            for (k, x) in m {
                let p = hook
                    .params
                    .iter()
                    .position(|p| p.name == *k)
                    .ok_or_else(|| {
                        err(line, format!("hook `{}` has no parameter `{k}`", hook.name))
                    })?;
                args[p] = Some(value(self.ir, line, &hook.params[p].ty, x, k)?);
            }
            out.push(args);
        }
        Ok(Called::With(out))
    }

    /// The rows of the controller's plans, for a hint: `AHEAD: E0–E4; INIT: E0–E1`.
    fn rows_hint(&self) -> String {
        let plans: Vec<String> = self
            .c
            .plans
            .iter()
            .map(|p| {
                let verb = self
                    .c
                    .commands
                    .get(p.verb.index())
                    .map_or("?", |k| k.name.as_str());
                match p.rows.len() {
                    0 => format!("{verb}: no rows"),
                    1 => format!("{verb}: E0"),
                    n => format!("{verb}: E0–{}", row_name(n as u32 - 1)),
                }
            })
            .collect();
        format!("its rows are {} (or `none`)", plans.join("; "))
    }

    /// `INIT` or `{ AHEAD: { speed: 10.0 } }`.
    fn command(&self, line: usize, v: &Json) -> Result<(CommandId, Vec<Value>), ScenarioError> {
        verb_call(self.ir, self.c, line, v, || {
            "`command` is a verb (`INIT`) or `{ VERB: { param: value } }`".to_string()
        })
    }

    /// The index of subordinate `name` in this controller's `subordinates`.
    fn sub_index(&self, line: usize, name: &str) -> Result<usize, ScenarioError> {
        self.ir
            .controller_by_name(name)
            .and_then(|id| self.c.subordinate_index(id))
            .ok_or_else(|| {
                err(
                    line,
                    format!("`{name}` is not a subordinate of `{}`", self.c.name),
                )
            })
    }

    fn sub_setting(
        &self,
        line: usize,
        sub: &Controller,
        v: &Json,
    ) -> Result<SubSetting, ScenarioError> {
        let status_of = |name: &str| {
            sub.statuses
                .iter()
                .position(|s| s.name == name)
                .map(|i| i as u16)
                .ok_or_else(|| err(line, format!("`{}` has no status `{name}`", sub.name)))
        };
        let error_of = |name: &str| {
            crate::error_codes::code_of(sub, name)
                .map(|e| e.0)
                .ok_or_else(|| {
                    err(
                        line,
                        format!(
                            "`{}` has no error code `{name}`: {}",
                            sub.name,
                            error_names(sub)
                        ),
                    )
                })
        };
        let refuses = || {
            if sub.can_refuse() {
                Ok(())
            } else {
                Err(err(
                    line,
                    format!(
                        "`{}` refuses no command (none of its verbs has `accept when`), so it cannot answer REFUSED",
                        sub.name
                    ),
                ))
            }
        };
        let mut s = SubSetting {
            status: 0,
            error: 0,
            refused: false,
            echo: Echo::Current,
            silent: false,
            fields: Vec::new(),
        };
        match v {
            Json::String(r) if r == "REFUSED" => {
                refuses()?;
                s.refused = true;
                Ok(s)
            }
            Json::String(n) => {
                s.status = status_of(n)?;
                Ok(s)
            }
            Json::Object(m) => {
                for (k, x) in m {
                    match (k.as_str(), x) {
                        ("status", Json::String(r)) if r == "REFUSED" => {
                            refuses()?;
                            s.refused = true;
                        }
                        ("status", Json::String(n)) => s.status = status_of(n)?,
                        ("error", Json::String(n)) if n == "REFUSED" => {
                            refuses()?;
                            s.refused = true;
                        }
                        ("error", Json::String(n)) => s.error = error_of(n)?,
                        ("echo", Json::String(e)) if e == "current" => s.echo = Echo::Current,
                        ("echo", Json::String(e)) if e == "previous" => s.echo = Echo::Previous,
                        ("echo", Json::Number(n)) => {
                            s.echo = Echo::Literal(n.as_u64().and_then(|n| u32::try_from(n).ok()).ok_or_else(|| err(line, "`echo` is a serial (0 to 4294967295)"))?)
                        }
                        ("silent", Json::Bool(b)) => s.silent = *b,
                        (k, x) if sub.status_fields().any(|(_, v)| v.name == k) => {
                            let (_, f) = sub.status_fields().find(|(_, v)| v.name == k).expect("just found");
                            let v = value(self.ir, line, &f.ty, x, &format!("{}.{k}", sub.name))?;
                            s.fields.push((k.to_string(), v));
                        }
                        (k, _) => return Err(err(line, format!("bad subordinate setting `{k}`: expected `status: NAME`, `error: CODE`, `echo: current|previous|N`, `silent: true|false` or a status field of `{}`", sub.name))),
                    }
                }
                if s.error != 0 && s.status != rcs_runtime::Status::ERROR.0 && !s.refused {
                    return Err(err(
                        line,
                        format!(
                            "subordinate `{}`: an error code comes with `status: ERROR`",
                            sub.name
                        ),
                    ));
                }
                Ok(s)
            }
            _ => Err(err(
                line,
                format!(
                    "subordinate `{}`: expected a status name or `{{ status, echo, silent }}`",
                    sub.name
                ),
            )),
        }
    }

    pub(super) fn expect(&self, e: RawExpect) -> Result<Expect, ScenarioError> {
        let mut out = Expect::default();
        if let Some(f) = e.fired {
            let line = line_of(&f);
            let name = match &f.value {
                Json::String(s) => s.clone(),
                _ => return Err(err(line, "`fired` is a row name (`E3`) or `none`")),
            };
            if name == "none" {
                out.fired = Some(None);
            } else {
                let known = self
                    .c
                    .plans
                    .iter()
                    .flat_map(|p| &p.rows)
                    .any(|r| row_aliases(r).contains(&name));
                if !known {
                    return Err(err(
                        line,
                        format!(
                            "no row of `{}` is called `{name}`: {}",
                            self.c.name,
                            self.rows_hint()
                        ),
                    ));
                }
                out.fired = Some(Some(name));
            }
        }
        if let Some(s) = e.state {
            let (line, s) = (line_of(&s), s.value);
            let known = s == "S0"
                || self
                    .c
                    .plans
                    .iter()
                    .flat_map(|p| &p.states)
                    .any(|x| x.name == s);
            if !known {
                return Err(err(
                    line,
                    format!("no plan of `{}` has a state `{s}`", self.c.name),
                ));
            }
            out.state = Some(s);
        }
        if let Some(s) = e.status {
            let (line, s) = (line_of(&s), s.value);
            let i = self
                .c
                .statuses
                .iter()
                .position(|x| x.name == s)
                .ok_or_else(|| err(line, format!("`{}` has no status `{s}`", self.c.name)))?;
            out.status = Some(i as u16);
        }
        if let Some(x) = e.error {
            let (line, x) = (line_of(&x), x.value);
            out.error = Some(match x.as_str() {
                "none" => None,
                name => Some(
                    crate::error_codes::code_of(self.c, name)
                        .ok_or_else(|| {
                            err(
                                line,
                                format!("`{}` has no error code `{name}`", self.c.name),
                            )
                        })?
                        .0,
                ),
            });
        }
        if let Some(a) = e.answered {
            let line = line_of(&a);
            out.answered = Some(
                a.value
                    .as_u64()
                    .and_then(|n| u32::try_from(n).ok())
                    .ok_or_else(|| err(line, "`answered` is a serial (0 to 4294967295)"))?,
            );
        }
        if e.sent.is_some() {
            let mut list = Vec::new();
            for (line, name, v) in entries(&e.sent) {
                let si = self.sub_index(line, name)?;
                let sub = self.ir.controller(self.c.subordinates[si]);
                let (cmd, vals) = verb_call(self.ir, sub, line, v, || {
                    format!("`sent.{name}` is a verb or `{{ VERB: {{ param: value }} }}`")
                })?;
                list.push((self.c.subordinates[si], cmd, vals));
            }
            out.sent = Some(list);
        }
        out.vars = self.vars(&e.vars)?;
        out.vars.extend(self.status_fields(&e.status_fields)?);
        out.writes = self.writes(&e.writes)?;
        for (line, name, v) in entries(&e.hooks_called) {
            let h = self
                .c
                .hooks
                .iter()
                .position(|h| h.name == *name)
                .ok_or_else(|| err(line, format!("`{}` has no hook `{name}`", self.c.name)))?;
            out.hooks_called
                .push((HookId(h as u32), self.called(line, &self.c.hooks[h], v)?));
        }
        Ok(out)
    }
}

/// The error codes of `c` a scenario may name, for a help.
fn error_names(c: &Controller) -> String {
    let names: Vec<&str> = crate::error_codes::BUILTIN
        .iter()
        .map(|(n, _)| *n)
        .chain(c.errors.iter().map(|e| e.name.as_str()))
        .collect();
    format!("its codes are {}", names.join(", "))
}

/// The names of a `silent:` list (or one name alone), each a string; else
/// an error at the key's line saying it holds a list of `what`.
pub(super) fn silent_names<'a>(
    v: &'a Spanned<Json>,
    what: &str,
) -> Result<Vec<&'a str>, ScenarioError> {
    let shape = || {
        err(
            line_of(v),
            format!("`silent` is a list of {what} held unwritten: `silent: [io]`"),
        )
    };
    match &v.value {
        Json::Array(xs) => xs.iter().map(|x| x.as_str().ok_or_else(shape)).collect(),
        Json::String(s) => Ok(vec![s.as_str()]),
        _ => Err(shape()),
    }
}
