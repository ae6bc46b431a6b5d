//! Reading a *system* scenario (`system: true`, or `controllers: [A, B]`):
//! a run of several controllers of the plan set on their schedule, where
//! the scenario plays only the environment (docs/scenarios.md, "System
//! scenarios"). Like [`super::read`], every name is resolved and every
//! value typed before anything runs, each problem a [`ScenarioError`] with
//! its line; the expectations per controller are read by the one-controller
//! reader ([`Resolver::expect`]), so they keep their keys and meaning.

use super::read::{entries, line_of, Entries, RawExpect, Resolver};
use super::system::{SysStep, SystemScenario};
use super::values::{merge, value, verb_call};
use super::{err, ScenarioError};
use crate::interp::{zero, Value};
use crate::ir::*;
use crate::yaml::Spanned;
use serde::Deserialize;
use serde_json::Value as Json;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSystem {
    name: Option<String>,
    system: Option<Spanned<Json>>,
    controllers: Option<Spanned<Json>>,
    initial: Option<RawInitial>,
    steps: Vec<Spanned<RawStep>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawInitial {
    reads: Option<Entries>,
    hooks: Option<Keyed<Json>>,
    vars: Option<Keyed<Json>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStep {
    /// The one root's command, as in a one-controller scenario.
    command: Option<Spanned<Json>>,
    /// `{ ROOT: VERB | { VERB: { param: value } } }`, any roots.
    commands: Option<Entries>,
    reads: Option<Entries>,
    hooks: Option<Keyed<Json>>,
    silent: Option<Spanned<Json>>,
    cycles: Option<Spanned<Json>>,
    expect: Option<Keyed<RawExpect>>,
}

/// A mapping of controller names to `T`, in file order, each with the line
/// of its key.
struct Keyed<T>(Vec<(usize, String, T)>);

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Keyed<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for Visitor<T> {
            type Value = Keyed<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a mapping of controller names")
            }
            fn visit_unit<E>(self) -> Result<Keyed<T>, E> {
                Ok(Keyed(Vec::new()))
            }
            fn visit_none<E>(self) -> Result<Keyed<T>, E> {
                Ok(Keyed(Vec::new()))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut m: A,
            ) -> Result<Keyed<T>, A::Error> {
                let mut out = Vec::new();
                while let Some(key) = m.next_key::<Spanned<String>>()? {
                    let line = line_of(&key);
                    out.push((line, key.value, m.next_value()?));
                }
                Ok(Keyed(out))
            }
        }
        d.deserialize_any(Visitor(std::marker::PhantomData))
    }
}

/// Whether a scenario file is a system scenario (it has `system:` or
/// `controllers:` at the top), without judging the rest.
pub(super) fn is_system(text: &str) -> bool {
    #[derive(Deserialize)]
    struct Probe {
        system: Option<serde::de::IgnoredAny>,
        controllers: Option<serde::de::IgnoredAny>,
    }
    match crate::yaml::from_str_names::<Probe>(text) {
        Ok(p) => p.system.is_some() || p.controllers.is_some(),
        // A file that does not read as YAML is judged by its lines, so its
        // error is the one of its kind's reader.
        Err(_) => text
            .lines()
            .any(|l| l.starts_with("system:") || l.starts_with("controllers:")),
    }
}

/// Read and resolve a system scenario. `stem` names it when it has no `name:`.
pub(super) fn parse_system(
    ir: &Ir,
    text: &str,
    stem: &str,
) -> Result<SystemScenario, ScenarioError> {
    let raw: RawSystem = crate::yaml::from_str_names(text)
        .map_err(|e| err(e.location.map_or(1, |l| l.line() as usize), e.message))?;
    let run = run_of(ir, &raw)?;
    let r = SystemResolver { ir, run: &run };
    let roots = roots_of(ir, &run);
    let init = raw.initial.unwrap_or_default();
    let mut initial = SysStep {
        line: 1,
        ..SysStep::default()
    };
    initial.reads = r.reads(&init.reads)?;
    initial.hooks = r.hooks(&init.hooks)?;
    for (line, name, vars) in init.vars.map_or_else(Vec::new, |k| k.0) {
        let c = r.controller(line, &name)?;
        let res = Resolver {
            ir,
            c: ir.controller(c),
        };
        let vars = Some(per_controller(line, &name, "vars", &vars)?);
        for (i, v) in res.vars(&vars)? {
            initial.vars.push((c, i, v));
        }
    }
    let mut steps = Vec::new();
    for s in raw.steps {
        let line = line_of(&s);
        let v = s.value;
        let mut step = SysStep {
            line,
            cycles: 1,
            ..SysStep::default()
        };
        if let Some(c) = &v.command {
            let [root] = roots.as_slice() else {
                let names: Vec<&str> = roots
                    .iter()
                    .map(|c| ir.controller(*c).name.as_str())
                    .collect();
                return Err(err(
                    line_of(c),
                    format!(
                        "this run has {} roots ({}): say which one each command is for, `commands: {{ {}: VERB }}`",
                        roots.len(),
                        names.join(", "),
                        names.first().copied().unwrap_or("ROOT")
                    ),
                ));
            };
            let ctrl = ir.controller(*root);
            let (k, args) = verb_call(ir, ctrl, line_of(c), &c.value, || {
                "`command` is a verb (`INIT`) or `{ VERB: { param: value } }`".to_string()
            })?;
            step.commands.push((*root, k, args));
        }
        for (cline, name, call) in entries(&v.commands) {
            let c = r.controller(cline, name)?;
            if !roots.contains(&c) {
                return Err(err(
                    cline,
                    format!(
                        "`{name}` is not a root of this run: its supervisor `{}` is in the run and commands it",
                        ir.controller(c).supervisor.map_or("?", |s| ir.controller(s).name.as_str())
                    ),
                ));
            }
            if step.commands.iter().any(|(x, _, _)| *x == c) {
                return Err(err(
                    cline,
                    format!("`{name}` is commanded twice in one step"),
                ));
            }
            let (k, args) = verb_call(ir, ir.controller(c), cline, call, || {
                format!("`commands.{name}` is a verb or `{{ VERB: {{ param: value }} }}`")
            })?;
            step.commands.push((c, k, args));
        }
        step.reads = r.reads(&v.reads)?;
        step.hooks = r.hooks(&v.hooks)?;
        if let Some(s) = &v.silent {
            step.silent = r.silent(s)?;
            if let Some((b, _)) = step.reads.iter().find(|(b, _)| step.silent.contains(b)) {
                return Err(err(
                    line_of(s),
                    format!(
                        "`{}` is both written (`reads:`) and `silent:` in one step; write it again in a later step",
                        ir.buffers[b.index()].name
                    ),
                ));
            }
        }
        if let Some(c) = &v.cycles {
            step.cycles = Resolver {
                ir,
                c: ir.controller(run[0]),
            }
            .cycles(c)?;
        }
        for (eline, name, e) in v.expect.map_or_else(Vec::new, |k| k.0) {
            let c = r.controller(eline, &name)?;
            let res = Resolver {
                ir,
                c: ir.controller(c),
            };
            step.expect.push((c, eline, res.expect(e)?));
        }
        steps.push(step);
    }
    Ok(SystemScenario {
        name: raw.name.unwrap_or_else(|| stem.to_string()),
        controllers: run,
        roots,
        initial,
        steps,
    })
}

/// The controllers of `run` whose supervisor is not in it: those the
/// scenario commands (`command:` goes to the one root, if one).
pub(crate) fn roots_of(ir: &Ir, run: &[CtrlId]) -> Vec<CtrlId> {
    run.iter()
        .copied()
        .filter(|c| {
            ir.controller(*c)
                .supervisor
                .is_none_or(|s| !run.contains(&s))
        })
        .collect()
}

/// The controllers of the run, by id order: every one (`system: true`) or
/// those named, which must hold whole subtrees.
fn run_of(ir: &Ir, raw: &RawSystem) -> Result<Vec<CtrlId>, ScenarioError> {
    let all = || {
        (0..ir.controllers.len())
            .map(|i| CtrlId(i as u32))
            .collect()
    };
    match (&raw.system, &raw.controllers) {
        (Some(s), Some(_)) => Err(err(
            line_of(s),
            "give either `system: true` (every controller) or `controllers: [...]` (a subtree), not both",
        )),
        (Some(s), None) => match s.value {
            Json::Bool(true) => Ok(all()),
            _ => Err(err(
                line_of(s),
                "`system` is `true` (run every controller); for one controller write `controller: NAME`",
            )),
        },
        (None, Some(list)) => {
            let line = line_of(list);
            let shape = || {
                err(
                    line,
                    "`controllers` is a list of controller names: `controllers: [UNIT, INFEED]`",
                )
            };
            let Json::Array(names) = &list.value else {
                return Err(shape());
            };
            let mut run = Vec::new();
            for n in names {
                let name = n.as_str().ok_or_else(shape)?;
                let id = ir
                    .controller_by_name(name)
                    .ok_or_else(|| err(line, format!("unknown controller `{name}`")))?;
                if run.contains(&id) {
                    return Err(err(line, format!("`{name}` is named twice")));
                }
                run.push(id);
            }
            if run.is_empty() {
                return Err(err(line, "`controllers` names no controller"));
            }
            for c in &run {
                let ctrl = ir.controller(*c);
                if let Some(s) = ctrl.subordinates.iter().find(|s| !run.contains(s)) {
                    return Err(err(
                        line,
                        format!(
                            "`{}` is a subordinate of `{}` but not in `controllers`: a run holds whole subtrees (add `{}`)",
                            ir.controller(*s).name,
                            ctrl.name,
                            ir.controller(*s).name
                        ),
                    ));
                }
            }
            run.sort();
            Ok(run)
        }
        (None, None) => Err(err(1, "not a system scenario")),
    }
}

struct SystemResolver<'a> {
    ir: &'a Ir,
    run: &'a [CtrlId],
}

impl SystemResolver<'_> {
    fn controller(&self, line: usize, name: &str) -> Result<CtrlId, ScenarioError> {
        let id = self
            .ir
            .controller_by_name(name)
            .ok_or_else(|| err(line, format!("unknown controller `{name}`")))?;
        if !self.run.contains(&id) {
            return Err(err(line, format!("`{name}` is not in this run")));
        }
        Ok(id)
    }

    /// A buffer the environment writes: read by a controller of the run
    /// and written by none of them.
    fn external(&self, line: usize, name: &str) -> Result<BufferId, ScenarioError> {
        let b = self
            .ir
            .buffers
            .iter()
            .position(|b| b.name == name)
            .ok_or_else(|| err(line, format!("no buffer `{name}`")))?;
        let buf = &self.ir.buffers[b];
        if let Some(w) = buf.writer.filter(|w| self.run.contains(w)) {
            return Err(err(
                line,
                format!(
                    "`{name}` is written by `{}`, which is in the run: only buffers no controller of the run writes are the scenario's",
                    self.ir.controller(w).name
                ),
            ));
        }
        if !buf.readers.iter().any(|r| self.run.contains(r)) {
            return Err(err(
                line,
                format!("no controller of the run reads `{name}`"),
            ));
        }
        Ok(BufferId(b as u32))
    }

    fn reads(&self, e: &Option<Entries>) -> Result<Vec<(BufferId, Json)>, ScenarioError> {
        let mut out = Vec::new();
        for (line, name, v) in entries(e) {
            let b = self.external(line, name)?;
            let ty = Type::Buffer(self.ir.buffers[b.index()].ty);
            merge(self.ir, line, &zero(self.ir, &ty), &ty, v, name)?;
            out.push((b, v.clone()));
        }
        Ok(out)
    }

    fn silent(&self, v: &Spanned<Json>) -> Result<Vec<BufferId>, ScenarioError> {
        let line = line_of(v);
        let names = super::read::silent_names(v, "external buffers")?;
        names.into_iter().map(|n| self.external(line, n)).collect()
    }

    /// `hooks: { CTRL: { hook: value } }`.
    fn hooks(
        &self,
        e: &Option<Keyed<Json>>,
    ) -> Result<Vec<(CtrlId, HookId, Value)>, ScenarioError> {
        let mut out = Vec::new();
        for (line, name, hooks) in e.as_ref().map_or(&[][..], |k| &k.0) {
            let owner = self.run.iter().find(|c| {
                self.ir
                    .controller(**c)
                    .hooks
                    .iter()
                    .any(|h| h.name == *name)
            });
            if let (None, Some(owner)) = (self.ir.controller_by_name(name), owner) {
                return Err(err(
                    *line,
                    format!(
                        "hooks are given per controller: `hooks: {{ {}: {{ {name}: … }} }}`",
                        self.ir.controller(*owner).name
                    ),
                ));
            }
            let c = self.controller(*line, name)?;
            let ctrl = self.ir.controller(c);
            for h in per_controller(*line, name, "hooks", hooks)?.0 {
                let i = ctrl
                    .hooks
                    .iter()
                    .position(|x| x.name == h.name)
                    .ok_or_else(|| err(h.line, format!("`{name}` has no hook `{}`", h.name)))?;
                let v = value(self.ir, h.line, &ctrl.hooks[i].ret, &h.value, &h.name)?;
                out.push((c, HookId(i as u32), v));
            }
        }
        Ok(out)
    }
}

/// The mapping given for one controller (`hooks: { PR: { … } }`), its
/// entries on the line of the controller's key.
fn per_controller(line: usize, name: &str, what: &str, v: &Json) -> Result<Entries, ScenarioError> {
    match v {
        Json::Object(m) => Ok(Entries(
            m.iter()
                .map(|(k, x)| super::read::Entry {
                    line,
                    name: k.clone(),
                    value: x.clone(),
                })
                .collect(),
        )),
        Json::Null => Ok(Entries::default()),
        _ => Err(err(
            line,
            format!("`{what}.{name}` is a mapping of names to values: `{what}: {{ {name}: {{ name: value }} }}`"),
        )),
    }
}
