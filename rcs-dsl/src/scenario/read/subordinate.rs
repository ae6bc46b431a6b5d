//! Reading how a subordinate answers in a step (`subordinates:`): a status
//! name, `REFUSED`, or `{ status, error, echo, silent, FIELD }`, each
//! checked against the subordinate's statuses, error codes and status
//! fields.

use super::Resolver;
use crate::ir::*;
use crate::scenario::values::value;
use crate::scenario::{err, Echo, ScenarioError, SubSetting};
use serde_json::Value as Json;

impl Resolver<'_> {
    /// The index of subordinate `name` in this controller's `subordinates`.
    pub(super) fn sub_index(&self, line: usize, name: &str) -> Result<usize, ScenarioError> {
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

    pub(super) fn sub_setting(
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
