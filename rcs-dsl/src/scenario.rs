//! Scenarios (`*.scenario.yaml`, TOOLING.md): a controller driven alone
//! through written steps — the scenario plays its supervisor, its
//! subordinates, its `reads` buffers and its hooks — with expectations
//! checked after each step. This module reads a scenario (through
//! [`crate::yaml`]), resolves every name against the IR, and runs it on
//! the reference interpreter.

use crate::interp::{self, wrap, zero, Value};
use crate::ir::*;
use crate::source::SourceFile;
use crate::yaml::{self, Spanned};
use rcs_runtime::driver::{Driven, Record};
use rcs_runtime::{Status, StatusBuffer};
use serde::Deserialize;
use serde_json::Value as Json;
use std::collections::BTreeMap;

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
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStep {
    command: Option<Spanned<Json>>,
    reads: Option<Entries>,
    hooks: Option<Entries>,
    subordinates: Option<Entries>,
    cycles: Option<u32>,
    expect: Option<RawExpect>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawExpect {
    fired: Option<Spanned<Json>>,
    state: Option<Spanned<String>>,
    status: Option<Spanned<String>>,
    error: Option<Spanned<String>>,
    sent: Option<Entries>,
    vars: Option<Entries>,
    writes: Option<Entries>,
}

/// A YAML mapping of names to values (`reads:`, `hooks:`, `sent:` …), in
/// file order, each entry with the line of its key, so that a name the
/// plans lack is reported on its own line.
#[derive(Default)]
struct Entries(Vec<Entry>);

struct Entry {
    line: usize,
    name: String,
    value: Json,
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
fn line_of<T>(s: &Spanned<T>) -> usize {
    s.referenced.line() as usize
}

/// The entries of an optional mapping: (line of the key, name, value).
fn entries(e: &Option<Entries>) -> impl Iterator<Item = (usize, &str, &Json)> {
    e.as_ref()
        .map_or(&[][..], |e| &e.0)
        .iter()
        .map(|e| (e.line, e.name.as_str(), &e.value))
}

/// A problem with a scenario file (not a failed expectation): where and what.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioError {
    pub line: usize,
    pub message: String,
}

/// How a subordinate's status buffer looks to the controller.
#[derive(Clone, Debug, PartialEq)]
struct SubSetting {
    status: u16,
    echo: Echo,
    silent: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Echo {
    Current,
    Previous,
    Literal(u32),
}

/// What a step expects after its last cycle.
#[derive(Clone, Debug, Default)]
struct Expect {
    /// `Some(None)`: no row fired.
    fired: Option<Option<String>>,
    state: Option<String>,
    status: Option<u16>,
    /// `Some(None)`: no error.
    error: Option<Option<u16>>,
    sent: Option<Vec<(CtrlId, CommandId, Vec<Value>)>>,
    vars: Vec<(usize, Value)>,
    /// Subset match: only the fields named are compared.
    writes: Vec<(usize, Json)>,
}

struct Step {
    line: usize,
    command: Option<(CommandId, Vec<Value>)>,
    reads: Vec<(usize, Json)>,
    hooks: Vec<(HookId, Value)>,
    subs: Vec<(usize, SubSetting)>,
    cycles: u32,
    expect: Expect,
}

/// A scenario resolved against a controller of the IR.
pub struct Scenario {
    pub name: String,
    pub controller: CtrlId,
    initial: Step,
    steps: Vec<Step>,
}

fn err(line: usize, message: impl Into<String>) -> ScenarioError {
    ScenarioError {
        line,
        message: message.into(),
    }
}

/// Read and resolve a scenario. `stem` names it when it has no `name:`.
pub fn parse(ir: &Ir, file: &SourceFile, stem: &str) -> Result<Scenario, ScenarioError> {
    let raw: RawScenario = yaml::from_str(&file.text)
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
    let initial = match raw.initial {
        Some(s) => r.step(cline, None, s.reads, s.hooks, s.subordinates, None, None)?,
        None => r.step(cline, None, None, None, None, None, None)?,
    };
    let mut steps = Vec::new();
    for s in raw.steps {
        let line = line_of(&s);
        let v = s.value;
        steps.push(r.step(
            line,
            v.command,
            v.reads,
            v.hooks,
            v.subordinates,
            v.cycles,
            v.expect,
        )?);
    }
    Ok(Scenario {
        name: raw.name.unwrap_or_else(|| stem.to_string()),
        controller: ctrl,
        initial,
        steps,
    })
}

struct Resolver<'a> {
    ir: &'a Ir,
    c: &'a Controller,
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
        cycles: Option<u32>,
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
            cycles: cycles.unwrap_or(1).max(1),
            expect,
        })
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
        match v {
            Json::String(s) => Ok(SubSetting {
                status: status_of(s)?,
                echo: Echo::Current,
                silent: false,
            }),
            Json::Object(m) => {
                let mut s = SubSetting {
                    status: 0,
                    echo: Echo::Current,
                    silent: false,
                };
                for (k, x) in m {
                    match (k.as_str(), x) {
                        ("status", Json::String(n)) => s.status = status_of(n)?,
                        ("echo", Json::String(e)) if e == "current" => s.echo = Echo::Current,
                        ("echo", Json::String(e)) if e == "previous" => s.echo = Echo::Previous,
                        ("echo", Json::Number(n)) => {
                            s.echo = Echo::Literal(n.as_u64().and_then(|n| u32::try_from(n).ok()).ok_or_else(|| err(line, "`echo` is a serial (0 to 4294967295)"))?)
                        }
                        ("silent", Json::Bool(b)) => s.silent = *b,
                        (k, _) => return Err(err(line, format!("bad subordinate setting `{k}`: expected `status: NAME`, `echo: current|previous|N`, `silent: true|false`"))),
                    }
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

    fn expect(&self, e: RawExpect) -> Result<Expect, ScenarioError> {
        let mut out = Expect::default();
        if let Some(f) = e.fired {
            let line = line_of(&f);
            let name = match &f.value {
                Json::String(s) => s.clone(),
                Json::Number(n) => n.to_string(),
                _ => {
                    return Err(err(
                        line,
                        "`fired` is a row name (`E3`, `*0`, `otherwise`, `#2`) or `none`",
                    ))
                }
            };
            if name == "none" {
                out.fired = Some(None);
            } else {
                let known = self
                    .c
                    .plans
                    .iter()
                    .flat_map(|p| &p.rows)
                    .any(|r| row_names(r).contains(&name));
                if !known {
                    return Err(err(
                        line,
                        format!("no row of `{}` is called `{name}`", self.c.name),
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
                "UNKNOWN_COMMAND" => Some(rcs_runtime::ErrorCode::UNKNOWN_COMMAND.0),
                name => {
                    let i = self
                        .c
                        .errors
                        .iter()
                        .position(|x| x.name == name)
                        .ok_or_else(|| {
                            err(
                                line,
                                format!("`{}` has no error code `{name}`", self.c.name),
                            )
                        })?;
                    Some(rcs_runtime::ErrorCode::custom(i as u16).0)
                }
            });
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
        for (line, name, v) in entries(&e.vars) {
            let i = self
                .c
                .vars
                .iter()
                .position(|x| x.name == *name)
                .ok_or_else(|| err(line, format!("`{}` has no var `{name}`", self.c.name)))?;
            out.vars
                .push((i, value(self.ir, line, &self.c.vars[i].ty, v, name)?));
        }
        for (line, name, v) in entries(&e.writes) {
            let i = self
                .c
                .writes
                .iter()
                .position(|b| self.ir.buffers[b.index()].name == *name)
                .ok_or_else(|| err(line, format!("`{}` writes no buffer `{name}`", self.c.name)))?;
            let ty = Type::Buffer(self.ir.buffers[self.c.writes[i].index()].ty);
            merge(self.ir, line, &zero(self.ir, &ty), &ty, v, name)?;
            out.writes.push((i, v.clone()));
        }
        Ok(out)
    }
}

/// Every name a row answers to in `fired`: `EN`, `*N`, `otherwise`, `#N`.
fn row_names(r: &Row) -> Vec<String> {
    let mut names = vec![format!("#{}", r.position)];
    if let Some(n) = r.label {
        names.push(format!("E{n}"));
    }
    if r.is_dont_care() {
        names.push(format!("*{}", r.position));
    }
    if r.is_otherwise() {
        names.push("otherwise".to_string());
    }
    names
}

fn object<'j>(
    line: usize,
    v: Option<&'j Json>,
    what: &str,
) -> Result<Vec<(&'j String, &'j Json)>, ScenarioError> {
    match v {
        None | Some(Json::Null) => Ok(Vec::new()),
        Some(Json::Object(m)) => Ok(m.iter().collect()),
        Some(_) => Err(err(
            line,
            format!("`{what}` is a mapping of names to values"),
        )),
    }
}

/// `VERB` or `{ VERB: { param: value } }` for controller `c`; `shape`
/// says what was expected when the value has neither form.
fn verb_call(
    ir: &Ir,
    c: &Controller,
    line: usize,
    v: &Json,
    shape: impl FnOnce() -> String,
) -> Result<(CommandId, Vec<Value>), ScenarioError> {
    let (verb, args) = match v {
        Json::String(s) => (s.as_str(), None),
        Json::Object(m) if m.len() == 1 => {
            let (k, a) = m.iter().next().expect("one entry");
            (k.as_str(), Some(a))
        }
        Json::Bool(b) => return Err(err(line, yaml_boolean_verb(c, *b, shape()))),
        _ => return Err(err(line, shape())),
    };
    verb_args(ir, c, line, verb, args)
}

/// The message for a verb YAML read as a boolean (YAML 1.1 reads `ON`,
/// `OFF`, `YES`, `NO`, `Y`, `N`, `TRUE` and `FALSE` so): which verb it
/// probably was, and to quote it.
fn yaml_boolean_verb(c: &Controller, value: bool, shape: String) -> String {
    const WORDS: [(&str, bool); 8] = [
        ("on", true),
        ("yes", true),
        ("y", true),
        ("true", true),
        ("off", false),
        ("no", false),
        ("n", false),
        ("false", false),
    ];
    let verb = c.commands.iter().find(|k| {
        WORDS
            .iter()
            .any(|(w, b)| *b == value && k.name.eq_ignore_ascii_case(w))
    });
    match verb {
        Some(k) => format!(
            "YAML reads `{0}` as the boolean `{value}`, not as the verb `{0}`: quote it, `\"{0}\"`",
            k.name
        ),
        None => format!(
            "{shape}, not the boolean `{value}` (YAML reads unquoted yes/no/on/off/true/false as booleans: quote such a verb)"
        ),
    }
}

fn verb_args(
    ir: &Ir,
    c: &Controller,
    line: usize,
    verb: &str,
    args: Option<&Json>,
) -> Result<(CommandId, Vec<Value>), ScenarioError> {
    let ci = c
        .commands
        .iter()
        .position(|k| k.name == verb)
        .ok_or_else(|| err(line, format!("`{}` has no command `{verb}`", c.name)))?;
    let cmd = &c.commands[ci];
    let given: BTreeMap<&String, &Json> = object(line, args, "parameters")?.into_iter().collect();
    for k in given.keys() {
        if !cmd.params.iter().any(|p| p.name == **k) {
            return Err(err(
                line,
                format!("command `{verb}` of `{}` has no parameter `{k}`", c.name),
            ));
        }
    }
    let mut vals = Vec::new();
    for p in &cmd.params {
        let v = given.get(&p.name).ok_or_else(|| {
            err(
                line,
                format!("command `{verb}` needs parameter `{}`", p.name),
            )
        })?;
        vals.push(value(ir, line, &p.ty, v, &p.name)?);
    }
    Ok((CommandId(ci as u32), vals))
}

/// A YAML value as a run-time value of type `t`.
fn value(ir: &Ir, line: usize, t: &Type, v: &Json, what: &str) -> Result<Value, ScenarioError> {
    let bad = || {
        err(
            line,
            format!(
                "`{what}`: expected {}, found `{v}`",
                crate::type_name(ir, t)
            ),
        )
    };
    Ok(match (t, v) {
        (Type::Bool, Json::Bool(b)) => Value::Bool(*b),
        (Type::Int(it), Json::Number(n)) => {
            let i = n
                .as_i64()
                .map(i128::from)
                .or_else(|| n.as_u64().map(i128::from))
                .ok_or_else(bad)?;
            let (lo, hi) = it.range();
            if i < lo || i > hi {
                return Err(bad());
            }
            Value::Int(wrap(i, *it))
        }
        (Type::Float(ft), Json::Number(n)) => {
            let f = n.as_f64().ok_or_else(bad)?;
            Value::Float(if *ft == FloatTy::F32 {
                f as f32 as f64
            } else {
                f
            })
        }
        (Type::Enum(e), Json::String(s)) => Value::Enum(
            ir.enums[e.index()]
                .variants
                .iter()
                .position(|x| x.name == *s)
                .ok_or_else(bad)? as u32,
        ),
        (Type::Buffer(_), Json::Object(_)) => merge(ir, line, &zero(ir, t), t, v, what)?,
        (Type::Array(elem, n), Json::Array(items)) if items.len() == *n as usize => Value::Array(
            items
                .iter()
                .map(|x| value(ir, line, elem, x, what))
                .collect::<Result<_, _>>()?,
        ),
        _ => return Err(bad()),
    })
}

/// Deep-merge a YAML mapping into a buffer value (fields not named keep theirs).
fn merge(
    ir: &Ir,
    line: usize,
    base: &Value,
    t: &Type,
    v: &Json,
    what: &str,
) -> Result<Value, ScenarioError> {
    match (t, base, v) {
        (Type::Buffer(b), Value::Buffer(fields), Json::Object(m)) => {
            let bt = &ir.buffer_types[b.index()];
            let mut out = fields.clone();
            for (k, x) in m {
                let fi = bt.fields.iter().position(|f| f.name == *k).ok_or_else(|| {
                    err(
                        line,
                        format!("buffer type `{}` has no field `{k}`", bt.name),
                    )
                })?;
                out[fi] = merge(ir, line, &fields[fi], &bt.fields[fi].ty, x, k)?;
            }
            Ok(Value::Buffer(out))
        }
        _ => value(ir, line, t, v, what),
    }
}

/// One scenario's outcome.
#[derive(Debug)]
pub struct Outcome {
    pub name: String,
    /// `None`: passed. Otherwise the line of the failing step and the report.
    pub failure: Option<(usize, String)>,
    /// Rows fired, by name, cycle by cycle (`-` for none).
    pub fired: Vec<String>,
    /// Rows fired as (verb, row), cycle by cycle, for coverage.
    pub rows: Vec<(CommandId, RowId)>,
}

fn float_eq(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Float(x), Value::Float(y)) => (x - y).abs() <= 1e-9,
        (Value::Buffer(xs), Value::Buffer(ys)) | (Value::Array(xs), Value::Array(ys)) => {
            xs.len() == ys.len() && xs.iter().zip(ys).all(|(x, y)| float_eq(x, y))
        }
        _ => a == b,
    }
}

/// Run a scenario on the reference interpreter.
pub fn run(ir: &Ir, s: &Scenario) -> Outcome {
    run_on(ir, s, &mut interp::Driven::new(ir, s.controller))
}

/// Run a scenario on any backend: the interpreter or a generated `Driver`
/// of the same controller, fresh.
pub fn run_on(ir: &Ir, s: &Scenario, driven: &mut dyn Driven) -> Outcome {
    let mut out = Outcome {
        name: s.name.clone(),
        failure: None,
        fired: Vec::new(),
        rows: Vec::new(),
    };
    if let Err((line, report)) = drive(ir, s, driven, &mut out) {
        out.failure = Some((line, report));
    }
    out
}

fn drive(
    ir: &Ir,
    s: &Scenario,
    d: &mut dyn Driven,
    out: &mut Outcome,
) -> Result<(), (usize, String)> {
    let c = ir.controller(s.controller);
    let sub_name = |i: usize| ir.controller(c.subordinates[i]).name.as_str();
    let mut reads: Vec<Value> = c
        .reads
        .iter()
        .map(|b| zero(ir, &Type::Buffer(ir.buffers[b.index()].ty)))
        .collect();
    let mut subs: Vec<SubSetting> = vec![
        SubSetting {
            status: 0,
            echo: Echo::Literal(0),
            silent: false
        };
        c.subordinates.len()
    ];
    for (k, step) in std::iter::once(&s.initial).chain(&s.steps).enumerate() {
        let line = step.line;
        let fail = |e: rcs_runtime::driver::DriveError| (line, e.to_string());
        if let Some((cmd, args)) = &step.command {
            d.command(&c.commands[cmd.index()].name, args)
                .map_err(fail)?;
        }
        for (i, v) in &step.reads {
            let b = &ir.buffers[c.reads[*i].index()];
            let merged = merge(ir, line, &reads[*i], &Type::Buffer(b.ty), v, &b.name)
                .map_err(|e| (e.line, e.message))?;
            d.set_read(&b.name, &merged).map_err(fail)?;
            reads[*i] = merged;
        }
        for (h, v) in &step.hooks {
            d.set_hook(&c.hooks[h.index()].name, v).map_err(fail)?;
        }
        for (i, setting) in &step.subs {
            subs[*i] = setting.clone();
        }
        // `echo: current` is the serial last sent as of the start of the step.
        let mut echoes = Vec::with_capacity(subs.len());
        for (i, sub) in subs.iter().enumerate() {
            echoes.push(echo_of(sub.echo, d.last_sent(sub_name(i)).map_err(fail)?));
        }
        if k == 0 {
            continue; // `initial` sets the scene; it runs no cycle.
        }
        let mut last = None;
        for _ in 0..step.cycles {
            for (i, sub) in subs.iter().enumerate() {
                if !sub.silent {
                    let status = StatusBuffer {
                        echo_serial: echoes[i],
                        status: Status(sub.status),
                        ..StatusBuffer::default()
                    };
                    d.write_sub_status(sub_name(i), status).map_err(fail)?;
                }
            }
            let rec = d.cycle();
            out.fired.push(
                rec.fired
                    .map(|r| fired_name(c, &rec, r))
                    .unwrap_or_else(|| "-".to_string()),
            );
            if let (Some(v), Some(r)) = (rec.verb, rec.fired) {
                out.rows
                    .push((CommandId(u32::from(v)), RowId(u32::from(r))));
            }
            last = Some(rec);
        }
        let rec = last.expect("a step runs at least one cycle");
        if let Some(report) = check(ir, c, &step.expect, &rec) {
            return Err((line, report));
        }
    }
    Ok(())
}

fn echo_of(e: Echo, last_sent: u32) -> u32 {
    match e {
        Echo::Current => last_sent,
        Echo::Previous => last_sent.wrapping_sub(1),
        Echo::Literal(n) => n,
    }
}

fn plan_of<'c>(c: &'c Controller, rec: &Record) -> Option<&'c Plan> {
    rec.verb
        .and_then(|v| c.commands.get(usize::from(v))?.plan)
        .map(|p| &c.plans[p.index()])
}

fn fired_name(c: &Controller, rec: &Record, row: u16) -> String {
    plan_of(c, rec)
        .and_then(|p| p.rows.get(usize::from(row)))
        // The name `fired:` accepts, even for a misnumbered `*N` row.
        .map(crate::analysis::run::row_name)
        .unwrap_or_else(|| format!("#{row}"))
}

/// Compare a step's expectations with the last cycle; `None` when all hold.
fn check(ir: &Ir, c: &Controller, e: &Expect, rec: &Record) -> Option<String> {
    let mut problems = Vec::new();
    let plan = plan_of(c, rec);
    if let Some(want) = &e.fired {
        let got = rec
            .fired
            .and_then(|r| plan.and_then(|p| p.rows.get(usize::from(r))));
        let ok = match (want, got) {
            (None, None) => true,
            (Some(name), Some(row)) => row_names(row).contains(name),
            _ => false,
        };
        if !ok {
            let got = got
                .map(|r| r.display_name())
                .unwrap_or_else(|| "none".into());
            problems.push(format!(
                "fired: expected {}, got {got}",
                want.clone().unwrap_or_else(|| "none".into())
            ));
        }
    }
    if let Some(want) = &e.state {
        let got = plan
            .and_then(|p| p.states.get(usize::from(rec.state)))
            .map(|s| s.name.clone())
            .unwrap_or_else(|| "S0".into());
        if *want != got {
            problems.push(format!("state: expected {want}, got {got}"));
        }
    }
    if let Some(want) = e.status {
        if want != rec.status.0 {
            let name = |i: u32| {
                c.statuses
                    .get(i as usize)
                    .map(|s| s.name.clone())
                    .unwrap_or_else(|| i.to_string())
            };
            problems.push(format!(
                "status: expected {}, got {}",
                name(u32::from(want)),
                name(u32::from(rec.status.0))
            ));
        }
    }
    if let Some(want) = &e.error {
        let got = (!rec.error.is_none()).then_some(rec.error.0);
        if *want != got {
            let name = |x: Option<u16>| match x {
                None => "none".to_string(),
                Some(1) => "UNKNOWN_COMMAND".to_string(),
                Some(n) => c
                    .errors
                    .get(usize::from(n) - 2)
                    .map(|e| e.name.clone())
                    .unwrap_or_else(|| n.to_string()),
            };
            problems.push(format!(
                "error: expected {}, got {}",
                name(*want),
                name(got)
            ));
        }
    }
    if let Some(want) = &e.sent {
        let got: Vec<(CtrlId, CommandId, Vec<Value>)> = rec
            .sent
            .iter()
            .map(|s| {
                (
                    c.subordinates[usize::from(s.sub)],
                    CommandId(u32::from(s.verb)),
                    s.args.clone(),
                )
            })
            .collect();
        let same = want.len() == got.len()
            && want.iter().all(|w| {
                got.iter().any(|g| {
                    g.0 == w.0
                        && g.1 == w.1
                        && g.2.len() == w.2.len()
                        && g.2.iter().zip(&w.2).all(|(a, b)| float_eq(a, b))
                })
            });
        if !same {
            let show = |l: &[(CtrlId, CommandId, Vec<Value>)]| {
                if l.is_empty() {
                    return "{}".to_string();
                }
                l.iter()
                    .map(|(s, k, a)| {
                        let sub = ir.controller(*s);
                        format!(
                            "{} <- {}{}",
                            sub.name,
                            sub.commands[k.index()].name,
                            if a.is_empty() {
                                String::new()
                            } else {
                                format!("{a:?}")
                            }
                        )
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            problems.push(format!("sent: expected {}, got {}", show(want), show(&got)));
        }
    }
    for (i, v) in &e.vars {
        if !float_eq(v, &rec.vars[*i]) {
            problems.push(format!(
                "vars.{}: expected {v:?}, got {:?}",
                c.vars[*i].name, rec.vars[*i]
            ));
        }
    }
    for (i, v) in &e.writes {
        // Merge the expected fields into the actual value: equal iff they match.
        let ty = Type::Buffer(ir.buffers[c.writes[*i].index()].ty);
        let name = &ir.buffers[c.writes[*i].index()].name;
        match merge(ir, 0, &rec.writes[*i], &ty, v, name) {
            Ok(expected) if float_eq(&expected, &rec.writes[*i]) => {}
            _ => problems.push(format!(
                "writes.{name}: expected {v}, got {:?}",
                rec.writes[*i]
            )),
        }
    }
    (!problems.is_empty()).then(|| problems.join("; "))
}
