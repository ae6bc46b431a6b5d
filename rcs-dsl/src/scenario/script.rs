//! System scenarios built in code: [`SystemScript`], a plain description
//! of a system run by names and values (what the cross-controller lints
//! write as witnesses), its file ([`SystemScript::to_yaml`], read back by
//! [`SystemScript::from_yaml`] to the same script) and its replay on the
//! interpreter ([`run_script`]), which runs the *file* — what a finding
//! shows is what a user's `rcsc test` will run.

use super::system::{run_system, SysStep, SystemOutcome, SystemScenario};
use super::values::merge;
use super::ScenarioError;
use crate::interp::{zero, Value};
use crate::ir::*;
use std::fmt::Write as _;

/// A system scenario by names: the controllers of the run, and steps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SystemScript {
    pub name: String,
    /// `None`: every controller (`system: true`); otherwise the
    /// controllers of the run by name, whole subtrees (`controllers:`).
    pub controllers: Option<Vec<String>>,
    /// Before the first cycle (`initial:`): `reads`, `hooks` and `vars`
    /// only; its other fields are not written.
    pub initial: SystemStep,
    pub steps: Vec<SystemStep>,
}

/// One step: inputs, how many ticks of the base period, expectations.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SystemStep {
    /// `(root, verb, arguments in declaration order)`: the command the
    /// scenario, as the root's supervisor, sends each root named.
    pub commands: Vec<(String, String, Vec<Value>)>,
    /// External buffers (no controller of the run writes them), each
    /// written whole.
    pub reads: Vec<(String, Value)>,
    /// `(controller, hook, value)`: what the hook returns from now on.
    pub hooks: Vec<(String, String, Value)>,
    /// `(controller, var, value)`: `initial:` only.
    pub vars: Vec<(String, String, Value)>,
    /// External buffers held unwritten from this step on (`silent:`).
    pub silent: Vec<String>,
    /// Ticks of the base period (1 to [`super::MAX_CYCLES`]; 0 is read as 1).
    pub cycles: u64,
    /// Per controller of the run, what its last cycle must show.
    pub expect: Vec<(String, ControllerExpect)>,
}

/// What one controller's last cycle of a step must show; `None` or empty:
/// not compared. The keys of a one-controller scenario's `expect`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ControllerExpect {
    /// `Some(None)`: no row fired; `Some(Some("E3"))`: row E3.
    pub fired: Option<Option<String>>,
    pub state: Option<String>,
    /// `EXECUTING`, `DONE`, `ERROR` or a declared status.
    pub status: Option<String>,
    /// `Some(None)`: no error code.
    pub error: Option<Option<String>>,
    /// Vars (status fields included), each whole.
    pub vars: Vec<(String, Value)>,
    /// Exactly the commands sent in the last cycle: `(subordinate, verb,
    /// arguments)`; `Some(vec![])` for none.
    pub sent: Option<Vec<(String, String, Vec<Value>)>>,
}

/// Run a script on the reference interpreter, through its file: the YAML
/// [`SystemScript::to_yaml`] writes is read back and run, so a finding is
/// replayed exactly as the witness file will run.
pub fn run_script(ir: &Ir, script: &SystemScript) -> Result<SystemOutcome, ScenarioError> {
    let text = script.to_yaml(ir);
    let s = super::system_read::parse_system(ir, &text, &script.name)?;
    Ok(run_system(ir, &s))
}

/// [`run_script`], showing each controller cycle's record to `on_cycle`
/// (how a witness learns when a command reached a subordinate).
pub(crate) fn run_script_observed(
    ir: &Ir,
    script: &SystemScript,
    on_cycle: &mut dyn FnMut(CtrlId, &rcs_runtime::driver::Record),
) -> Result<SystemOutcome, ScenarioError> {
    let text = script.to_yaml(ir);
    let s = super::system_read::parse_system(ir, &text, &script.name)?;
    let mut system = crate::interp::System::new(ir, &s.controllers);
    Ok(super::system::run_system_on(ir, &s, &mut system, on_cycle))
}

impl SystemScript {
    /// The scenario file (`*.scenario.yaml`): [`from_yaml`](Self::from_yaml)
    /// reads it back to this script. Names not in `ir` are written as
    /// given (the reader then refuses them with their line); a float that
    /// is not finite has no scenario spelling and is written `.nan`/`.inf`,
    /// which the reader refuses.
    pub fn to_yaml(&self, ir: &Ir) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "name: {}", quoted(&self.name));
        match &self.controllers {
            None => out.push_str("system: true\n"),
            Some(list) => {
                let names: Vec<String> = list.iter().map(|n| plain(n)).collect();
                let _ = writeln!(out, "controllers: [{}]", names.join(", "));
            }
        }
        let i = &self.initial;
        if !(i.reads.is_empty() && i.hooks.is_empty() && i.vars.is_empty()) {
            out.push_str("initial:\n");
            inputs(ir, &mut out, "  ", i);
            if !i.vars.is_empty() {
                let _ = writeln!(
                    out,
                    "  vars: {}",
                    per_controller(&i.vars, |c, v, x| {
                        let t = var_type(ir, c, v);
                        yaml(ir, t.as_ref(), x)
                    })
                );
            }
        }
        if self.steps.is_empty() {
            out.push_str("steps: []\n");
            return out;
        }
        out.push_str("steps:\n");
        for s in &self.steps {
            let _ = writeln!(out, "  - cycles: {}", s.cycles.max(1));
            if !s.commands.is_empty() {
                let parts: Vec<String> = s
                    .commands
                    .iter()
                    .map(|(root, verb, args)| {
                        let params = ir
                            .controller_by_name(root)
                            .and_then(|c| {
                                ir.controller(c).commands.iter().find(|k| k.name == *verb)
                            })
                            .map(|k| k.params.as_slice())
                            .unwrap_or_default();
                        format!("{}: {}", plain(root), call(ir, verb, params, args))
                    })
                    .collect();
                let _ = writeln!(out, "    commands: {{ {} }}", parts.join(", "));
            }
            inputs(ir, &mut out, "    ", s);
            if !s.silent.is_empty() {
                let names: Vec<String> = s.silent.iter().map(|n| plain(n)).collect();
                let _ = writeln!(out, "    silent: [{}]", names.join(", "));
            }
            if !s.expect.is_empty() {
                out.push_str("    expect:\n");
                for (c, e) in &s.expect {
                    let _ = writeln!(out, "      {}: {}", plain(c), expect(ir, c, e));
                }
            }
        }
        out
    }

    /// Read a system scenario file as a script (every name checked against
    /// `ir`, as [`super::parse_any`] does). Expectations a script has no
    /// field for (`writes`, `hooks_called`, `answered`) are left out.
    pub fn from_yaml(ir: &Ir, text: &str, stem: &str) -> Result<SystemScript, ScenarioError> {
        let s = super::system_read::parse_system(ir, text, stem)?;
        Ok(script_of(ir, &s))
    }
}

/// `reads:` and `hooks:` of a step, each on its own line.
fn inputs(ir: &Ir, out: &mut String, indent: &str, s: &SystemStep) {
    if !s.reads.is_empty() {
        let parts: Vec<String> = s
            .reads
            .iter()
            .map(|(b, v)| {
                let t = ir
                    .buffers
                    .iter()
                    .find(|x| x.name == *b)
                    .map(|x| Type::Buffer(x.ty));
                format!("{}: {}", plain(b), yaml(ir, t.as_ref(), v))
            })
            .collect();
        let _ = writeln!(out, "{indent}reads: {{ {} }}", parts.join(", "));
    }
    if !s.hooks.is_empty() {
        let _ = writeln!(
            out,
            "{indent}hooks: {}",
            per_controller(&s.hooks, |c, h, x| {
                let t = ir
                    .controller_by_name(c)
                    .and_then(|c| ir.controller(c).hooks.iter().find(|k| k.name == h))
                    .map(|k| k.ret.clone());
                yaml(ir, t.as_ref(), x)
            })
        );
    }
}

/// `{ C: { name: value, … }, … }`, controllers in first-mention order.
fn per_controller(
    list: &[(String, String, Value)],
    show: impl Fn(&str, &str, &Value) -> String,
) -> String {
    let mut order: Vec<&str> = Vec::new();
    for (c, _, _) in list {
        if !order.contains(&c.as_str()) {
            order.push(c);
        }
    }
    let parts: Vec<String> = order
        .iter()
        .map(|c| {
            let inner: Vec<String> = list
                .iter()
                .filter(|(x, _, _)| x == c)
                .map(|(_, n, v)| format!("{}: {}", plain(n), show(c, n, v)))
                .collect();
            format!("{}: {{ {} }}", plain(c), inner.join(", "))
        })
        .collect();
    format!("{{ {} }}", parts.join(", "))
}

fn var_type(ir: &Ir, c: &str, v: &str) -> Option<Type> {
    ir.controller_by_name(c)
        .and_then(|c| ir.controller(c).vars.iter().find(|x| x.name == v))
        .map(|x| x.ty.clone())
}

/// `VERB` or `{ VERB: { param: value } }`.
fn call(ir: &Ir, verb: &str, params: &[Param], args: &[Value]) -> String {
    if args.is_empty() {
        return plain(verb);
    }
    let parts: Vec<String> = args
        .iter()
        .enumerate()
        .map(|(i, a)| match params.get(i) {
            Some(p) => format!("{}: {}", plain(&p.name), yaml(ir, Some(&p.ty), a)),
            None => format!("arg{i}: {}", yaml(ir, None, a)),
        })
        .collect();
    format!("{{ {}: {{ {} }} }}", plain(verb), parts.join(", "))
}

fn expect(ir: &Ir, c: &str, e: &ControllerExpect) -> String {
    let mut parts = Vec::new();
    if let Some(f) = &e.fired {
        parts.push(format!("fired: {}", plain(f.as_deref().unwrap_or("none"))));
    }
    if let Some(s) = &e.state {
        parts.push(format!("state: {}", plain(s)));
    }
    if let Some(s) = &e.status {
        parts.push(format!("status: {}", plain(s)));
    }
    if let Some(x) = &e.error {
        parts.push(format!("error: {}", plain(x.as_deref().unwrap_or("none"))));
    }
    if !e.vars.is_empty() {
        let vars: Vec<String> = e
            .vars
            .iter()
            .map(|(v, x)| format!("{}: {}", plain(v), yaml(ir, var_type(ir, c, v).as_ref(), x)))
            .collect();
        parts.push(format!("vars: {{ {} }}", vars.join(", ")));
    }
    if let Some(sent) = &e.sent {
        let list: Vec<String> = sent
            .iter()
            .map(|(sub, verb, args)| {
                let params = ir
                    .controller_by_name(sub)
                    .and_then(|s| ir.controller(s).commands.iter().find(|k| k.name == *verb))
                    .map(|k| k.params.as_slice())
                    .unwrap_or_default();
                format!("{}: {}", plain(sub), call(ir, verb, params, args))
            })
            .collect();
        parts.push(if list.is_empty() {
            "sent: {}".to_string()
        } else {
            format!("sent: {{ {} }}", list.join(", "))
        });
    }
    format!("{{ {} }}", parts.join(", "))
}

/// A value as a scenario writes it, whole (no `…`): the reader gives back
/// the same value. Without a type, a plain rendering.
fn yaml(ir: &Ir, t: Option<&Type>, v: &Value) -> String {
    match (t, v) {
        (Some(Type::ErrorCode(c)), Value::Int(n)) => plain(&crate::error_codes::name_of(
            ir.controller(*c),
            rcs_runtime::ErrorCode(u16::try_from(*n).unwrap_or(u16::MAX)),
        )),
        (Some(Type::Enum(e)), Value::Enum(i)) => ir.enums[e.index()]
            .variants
            .get(*i as usize)
            .map_or_else(|| i.to_string(), |x| plain(&x.name)),
        (Some(Type::Status(c)), Value::Status(s)) => ir
            .controller(*c)
            .statuses
            .get(usize::from(*s))
            .map_or_else(|| s.to_string(), |x| plain(&x.name)),
        (Some(Type::Buffer(b)), Value::Buffer(fields)) => {
            let bt = &ir.buffer_types[b.index()];
            let parts: Vec<String> = bt
                .fields
                .iter()
                .zip(fields)
                .map(|(f, x)| format!("{}: {}", plain(&f.name), yaml(ir, Some(&f.ty), x)))
                .collect();
            format!("{{ {} }}", parts.join(", "))
        }
        (t, Value::Array(xs)) => {
            let elem = match t {
                Some(Type::Array(e, _)) => Some(&**e),
                _ => None,
            };
            let parts: Vec<String> = xs.iter().map(|x| yaml(ir, elem, x)).collect();
            format!("[{}]", parts.join(", "))
        }
        (_, Value::Bool(b)) => b.to_string(),
        (_, Value::Int(i)) => i.to_string(),
        (_, Value::Float(f)) => float(*f),
        (_, Value::Enum(i)) => i.to_string(),
        (_, Value::Status(s)) => s.to_string(),
        (_, Value::Buffer(xs)) => {
            let parts: Vec<String> = xs.iter().map(|x| yaml(ir, None, x)).collect();
            format!("[{}]", parts.join(", "))
        }
        (_, Value::Unit) => "~".to_string(),
    }
}

/// The shortest text that reads back as `f`, always with a `.` so that
/// YAML reads a float.
fn float(f: f64) -> String {
    if f.is_nan() {
        return ".nan".to_string();
    }
    if f.is_infinite() {
        return if f > 0.0 { ".inf" } else { "-.inf" }.to_string();
    }
    let s = format!("{f:?}");
    match s.find(['e', 'E']) {
        Some(i) if !s[..i].contains('.') => format!("{}.0{}", &s[..i], &s[i..]),
        _ => s,
    }
}

/// A name as a plain scalar, quoted when YAML would read it as something
/// else (`null`, `true`, a number, an empty string, punctuation).
fn plain(name: &str) -> String {
    let ident = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    let special = matches!(
        name.to_ascii_lowercase().as_str(),
        "null" | "true" | "false" | "nan" | "inf"
    );
    if ident && !special {
        name.to_string()
    } else {
        quoted(name)
    }
}

/// A double-quoted YAML string (JSON's escapes are YAML's).
fn quoted(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".to_string())
}

/// A resolved system scenario back as a script, by names.
fn script_of(ir: &Ir, s: &SystemScenario) -> SystemScript {
    let all = s.controllers.len() == ir.controllers.len();
    let mut current: Vec<Value> = ir
        .buffers
        .iter()
        .map(|b| zero(ir, &Type::Buffer(b.ty)))
        .collect();
    let mut step_of = |st: &SysStep| -> SystemStep {
        let reads = st
            .reads
            .iter()
            .map(|(b, j)| {
                let buf = &ir.buffers[b.index()];
                let ty = Type::Buffer(buf.ty);
                // Checked when read: the merge cannot fail here.
                if let Ok(v) = merge(ir, st.line, &current[b.index()], &ty, j, &buf.name) {
                    current[b.index()] = v;
                }
                (buf.name.clone(), current[b.index()].clone())
            })
            .collect();
        let name = |c: CtrlId| ir.controller(c).name.clone();
        SystemStep {
            commands: st
                .commands
                .iter()
                .map(|(c, k, a)| {
                    (
                        name(*c),
                        ir.controller(*c).commands[k.index()].name.clone(),
                        a.clone(),
                    )
                })
                .collect(),
            reads,
            hooks: st
                .hooks
                .iter()
                .map(|(c, h, v)| {
                    (
                        name(*c),
                        ir.controller(*c).hooks[h.index()].name.clone(),
                        v.clone(),
                    )
                })
                .collect(),
            vars: st
                .vars
                .iter()
                .map(|(c, i, v)| (name(*c), ir.controller(*c).vars[*i].name.clone(), v.clone()))
                .collect(),
            silent: st
                .silent
                .iter()
                .map(|b| ir.buffers[b.index()].name.clone())
                .collect(),
            cycles: st.cycles,
            expect: st
                .expect
                .iter()
                .map(|(c, _, e)| {
                    let ctrl = ir.controller(*c);
                    (
                        name(*c),
                        ControllerExpect {
                            fired: e.fired.clone(),
                            state: e.state.clone(),
                            status: e.status.and_then(|x| {
                                ctrl.statuses.get(usize::from(x)).map(|s| s.name.clone())
                            }),
                            error: e.error.map(|x| {
                                x.map(|x| {
                                    crate::error_codes::name_of(ctrl, rcs_runtime::ErrorCode(x))
                                })
                            }),
                            vars: e
                                .vars
                                .iter()
                                .map(|(i, v)| (ctrl.vars[*i].name.clone(), v.clone()))
                                .collect(),
                            sent: e.sent.as_ref().map(|l| {
                                l.iter()
                                    .map(|(sub, k, a)| {
                                        let sub = ir.controller(*sub);
                                        (
                                            sub.name.clone(),
                                            sub.commands[k.index()].name.clone(),
                                            a.clone(),
                                        )
                                    })
                                    .collect()
                            }),
                        },
                    )
                })
                .collect(),
        }
    };
    let mut initial = step_of(&s.initial);
    initial.cycles = 0;
    let steps = s.steps.iter().map(&mut step_of).collect();
    SystemScript {
        name: s.name.clone(),
        controllers: (!all).then(|| {
            s.controllers
                .iter()
                .map(|c| ir.controller(*c).name.clone())
                .collect()
        }),
        initial,
        steps,
    }
}
