//! Reading a step's `expect:` (the system reader reads each controller's
//! expectations with it too): the row fired, the state, status and error,
//! the serial answered, the commands sent, vars, status fields, `writes`
//! buffers and hook calls, each name checked against the controller.

use super::{entries, line_of, Entries, Resolver};
use crate::interp::Value;
use crate::ir::*;
use crate::scenario::report::{row_aliases, row_name};
use crate::scenario::values::{value, verb_call};
use crate::scenario::{err, Called, Expect, ScenarioError};
use crate::yaml::Spanned;
use serde::Deserialize;
use serde_json::Value as Json;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(in crate::scenario) struct RawExpect {
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

impl Resolver<'_> {
    pub(in crate::scenario) fn expect(&self, e: RawExpect) -> Result<Expect, ScenarioError> {
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
}
