//! What the console knows about a plan set before anything runs: its
//! controllers, their verbs with typed parameters, status and error names,
//! each verb's plan as a table of rows (label, from, condition, to, as
//! written), and the schedule (which CPU runs which controller).
//!
//! Built once from the checked IR of `rcs_dsl`; the running system only
//! sends numbers (verb, state, row, status ids) and the catalog names them.
//! It also checks an operator's typed-in command parameters against their
//! declared types before anything is sent.

use std::path::Path;

use rcs_dsl::ir::{self, Ir, Type};
use rcs_dsl::source::SourceMap;
use rcs_runtime::{ErrorCode, Status};

/// One row of a plan, as written in the plan file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RowText {
    /// `E3`, or the row's position when it has no label.
    pub label: String,
    /// The from-state pattern (`S1`, `*`, `*3 except S2`).
    pub from: String,
    /// The condition (`when …` without `when`, or `otherwise`).
    pub cond: String,
    /// The target (`S2`, `Done`, `Error(X)`).
    pub to: String,
}

/// One verb's plan.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct PlanTable {
    /// State names by id (`S0` first).
    pub states: Vec<String>,
    /// Rows in precedence order (index = the runtime's `RowId`).
    pub rows: Vec<RowText>,
}

/// A parameter's declared type, as far as the console can type one in.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamType {
    /// `bool`: `true` / `false`.
    Bool,
    /// An integer type (name, inclusive range).
    Int(&'static str, i128, i128),
    /// `f32` / `f64`.
    Float(&'static str),
    /// An enum (name, variants).
    Enum(String, Vec<String>),
    /// A type no one types at a prompt (arrays, buffers…): refused.
    Other(String),
}

impl ParamType {
    /// The type's name as the plans write it (`f64`, `Direction`).
    pub fn name(&self) -> &str {
        match self {
            ParamType::Bool => "bool",
            ParamType::Int(n, ..) | ParamType::Float(n) => n,
            ParamType::Enum(n, _) | ParamType::Other(n) => n,
        }
    }
}

/// A parameter value, checked against its [`ParamType`].
#[derive(Debug, Clone, PartialEq)]
pub enum ArgValue {
    /// A `bool`.
    Bool(bool),
    /// Any integer type (in its range).
    Int(i128),
    /// `f32` / `f64` (finite).
    Float(f64),
    /// An enum variant by name.
    Enum(String),
}

/// A verb with its parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Verb {
    /// The verb's name (`TRANSIT`).
    pub name: String,
    /// Parameters: name and type.
    pub params: Vec<(String, ParamType)>,
    /// Its plan (`None`: a verb without plan).
    pub plan: Option<PlanTable>,
}

/// One controller of the plan set.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerInfo {
    /// Its name (`SM`).
    pub name: String,
    /// Its supervisor's name (`None`: a root, which the operator commands).
    pub supervisor: Option<String>,
    /// Its subordinates' names.
    pub subordinates: Vec<String>,
    /// Verbs by `VerbId`.
    pub verbs: Vec<Verb>,
    /// Status names by id: the built-ins, then the custom ones (as the IR
    /// lists them).
    pub statuses: Vec<String>,
    /// Declared error names, from `ErrorCode::FIRST_CUSTOM` on.
    pub errors: Vec<String>,
}

/// A CPU of the schedule.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CpuInfo {
    /// Its name (`main`, `helm`).
    pub name: String,
    /// Its period, ns.
    pub period_ns: u64,
    /// Its controllers in execution order.
    pub controllers: Vec<String>,
}

/// A plan set as the console shows it. See the module docs.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Catalog {
    /// The system's name.
    pub system: String,
    /// Controllers in plan-set order.
    pub controllers: Vec<ControllerInfo>,
    /// The schedule.
    pub cpus: Vec<CpuInfo>,
    /// The processes the manifest places the CPUs in (one, `main`, for a
    /// plan set in one process), in the order the schedule names them.
    pub processes: Vec<String>,
}

impl Catalog {
    /// Load and check the plan set at `path` (a plan-set folder): a clear
    /// message when it cannot be loaded or has errors.
    pub fn load(path: &Path) -> Result<Self, String> {
        let set = rcs_dsl::load_folder(path)
            .map_err(|e| format!("cannot load the plan set {}: {e}", path.display()))?;
        let checked = rcs_dsl::check(&set, &rcs_dsl::Options::default());
        let ir = checked.ir.ok_or_else(|| {
            let first = checked
                .diagnostics
                .iter()
                .find(|d| d.severity == rcs_dsl::Severity::Error)
                .map_or_else(String::new, |d| format!(": {}", d.message));
            format!(
                "the plan set {} has errors{first} (rcsc check shows them all)",
                path.display()
            )
        })?;
        Ok(Self::from_ir(&ir, &set.sources))
    }

    /// The catalog of checked IR whose source text is in `sources`.
    pub fn from_ir(ir: &Ir, sources: &SourceMap) -> Self {
        let text = |span: rcs_dsl::source::Span| -> String {
            let file = sources.get(span.file);
            file.text
                .get(span.range())
                .unwrap_or("?")
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" ")
        };
        let ctrl_name = |id: ir::CtrlId| {
            ir.controllers
                .get(id.0 as usize)
                .map_or_else(|| "?".to_owned(), |c| c.name.clone())
        };
        let controllers = ir
            .controllers
            .iter()
            .map(|c| ControllerInfo {
                name: c.name.clone(),
                supervisor: c.supervisor.map(ctrl_name),
                subordinates: c.subordinates.iter().map(|&s| ctrl_name(s)).collect(),
                verbs: c
                    .commands
                    .iter()
                    .map(|cmd| Verb {
                        name: cmd.name.clone(),
                        params: cmd
                            .params
                            .iter()
                            .map(|p| (p.name.clone(), param_type(ir, &p.ty)))
                            .collect(),
                        plan: cmd
                            .plan
                            .and_then(|id| c.plans.get(id.0 as usize))
                            .map(|plan| plan_table(plan, &text)),
                    })
                    .collect(),
                statuses: c.statuses.iter().map(|s| s.name.clone()).collect(),
                errors: c.errors.iter().map(|e| e.name.clone()).collect(),
            })
            .collect();
        let cpus = ir
            .schedule
            .iter()
            .map(|cpu| CpuInfo {
                name: cpu.name.clone(),
                period_ns: cpu.period_ns,
                controllers: cpu.order.iter().map(|&c| ctrl_name(c)).collect(),
            })
            .collect();
        Self {
            system: ir.system.clone(),
            controllers,
            cpus,
            processes: rcs_dsl::placement::Placement::of(ir).processes,
        }
    }

    /// The controller called `name`.
    pub fn controller(&self, name: &str) -> Option<&ControllerInfo> {
        self.controllers.iter().find(|c| c.name == name)
    }

    /// The roots: the controllers the operator may command.
    pub fn roots(&self) -> impl Iterator<Item = &ControllerInfo> {
        self.controllers.iter().filter(|c| c.supervisor.is_none())
    }

    /// The longest plan's row count (the room a monitor's hit counters need).
    pub fn max_rows(&self) -> usize {
        self.controllers
            .iter()
            .flat_map(|c| &c.verbs)
            .filter_map(|v| v.plan.as_ref())
            .map(|p| p.rows.len())
            .max()
            .unwrap_or(0)
    }

    /// Check `args` (as typed) against the parameters of `root`'s `verb`:
    /// the values to send, or why not. Only a root may be commanded.
    pub fn check_command(
        &self,
        root: &str,
        verb: &str,
        args: &[&str],
    ) -> Result<Vec<ArgValue>, String> {
        let c = self
            .controller(root)
            .ok_or_else(|| format!("no controller `{root}`"))?;
        if let Some(sup) = &c.supervisor {
            return Err(format!(
                "{root} is commanded by {sup}: the operator commands only roots"
            ));
        }
        let v = c
            .verbs
            .iter()
            .find(|v| v.name == verb)
            .ok_or_else(|| format!("{root} has no verb `{verb}`"))?;
        if args.len() != v.params.len() {
            return Err(format!(
                "{verb} takes {} parameter(s), {} given",
                v.params.len(),
                args.len()
            ));
        }
        v.params
            .iter()
            .zip(args)
            .map(|((name, ty), arg)| check_arg(ty, arg.trim()).map_err(|e| format!("{name}: {e}")))
            .collect()
    }
}

impl ControllerInfo {
    /// The name of status `s` (built-in or custom).
    pub fn status_name(&self, s: Status) -> String {
        self.statuses
            .get(usize::from(s.0))
            .cloned()
            .unwrap_or_else(|| format!("status {}", s.0))
    }

    /// The name of error code `e` (built-in or declared).
    pub fn error_name(&self, e: ErrorCode) -> String {
        match e {
            ErrorCode::NONE => "NONE".into(),
            ErrorCode::UNKNOWN_COMMAND => "UNKNOWN_COMMAND".into(),
            ErrorCode::INDEX_RANGE => "INDEX_RANGE".into(),
            ErrorCode::HOOK_PANIC => "HOOK_PANIC".into(),
            ErrorCode::REFUSED => "REFUSED".into(),
            ErrorCode(n) => n
                .checked_sub(ErrorCode::FIRST_CUSTOM)
                .and_then(|i| self.errors.get(usize::from(i)))
                .cloned()
                .unwrap_or_else(|| format!("error {n}")),
        }
    }
}

/// A typed-in parameter against its type.
pub fn check_arg(ty: &ParamType, arg: &str) -> Result<ArgValue, String> {
    match ty {
        ParamType::Bool => match arg {
            "true" => Ok(ArgValue::Bool(true)),
            "false" => Ok(ArgValue::Bool(false)),
            _ => Err(format!("`{arg}` is not a bool (true or false)")),
        },
        ParamType::Int(name, lo, hi) => match arg.parse::<i128>() {
            Ok(v) if (*lo..=*hi).contains(&v) => Ok(ArgValue::Int(v)),
            Ok(_) => Err(format!("`{arg}` is out of {name}'s range {lo}..={hi}")),
            Err(_) => Err(format!("`{arg}` is not an integer ({name})")),
        },
        ParamType::Float(name) => match arg.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(ArgValue::Float(v)),
            _ => Err(format!("`{arg}` is not a finite number ({name})")),
        },
        ParamType::Enum(name, variants) => {
            if variants.iter().any(|v| v == arg) {
                Ok(ArgValue::Enum(arg.to_owned()))
            } else {
                Err(format!(
                    "`{arg}` is not a {name} (one of {})",
                    variants.join(", ")
                ))
            }
        }
        ParamType::Other(name) => Err(format!("a {name} cannot be typed in the console")),
    }
}

fn param_type(ir: &Ir, ty: &Type) -> ParamType {
    match ty {
        Type::Bool => ParamType::Bool,
        Type::Int(t) => {
            let (lo, hi) = t.range();
            ParamType::Int(t.name(), lo, hi)
        }
        Type::Float(f) => ParamType::Float(f.name()),
        Type::Enum(id) => match ir.enums.get(id.0 as usize) {
            Some(e) => ParamType::Enum(
                e.name.clone(),
                e.variants.iter().map(|v| v.name.clone()).collect(),
            ),
            None => ParamType::Other("enum".into()),
        },
        other => ParamType::Other(format!("{other:?}")),
    }
}

fn plan_table(plan: &ir::Plan, text: &dyn Fn(rcs_dsl::source::Span) -> String) -> PlanTable {
    PlanTable {
        states: plan.states.iter().map(|s| s.name.clone()).collect(),
        rows: plan
            .rows
            .iter()
            .map(|r| RowText {
                label: r
                    .label
                    .map_or_else(|| format!("#{}", r.position), |l| format!("E{l}")),
                from: text(r.from_span),
                cond: match &r.cond {
                    ir::Condition::Otherwise => "otherwise".into(),
                    ir::Condition::When(_) => text(r.cond_span),
                },
                to: text(r.to_span),
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn args_are_checked_against_their_types() {
        assert_eq!(
            check_arg(&ParamType::Bool, "true"),
            Ok(ArgValue::Bool(true))
        );
        assert!(check_arg(&ParamType::Bool, "yes").is_err());
        assert_eq!(
            check_arg(&ParamType::Int("u8", 0, 255), "200"),
            Ok(ArgValue::Int(200))
        );
        let e = check_arg(&ParamType::Int("u8", 0, 255), "300").unwrap_err();
        assert!(e.contains("out of u8's range"), "{e}");
        assert!(check_arg(&ParamType::Float("f64"), "inf").is_err());
        assert_eq!(
            check_arg(&ParamType::Float("f64"), "12.5"),
            Ok(ArgValue::Float(12.5))
        );
        let dir = ParamType::Enum("Dir".into(), vec!["Ahead".into(), "Astern".into()]);
        assert!(check_arg(&dir, "Sideways")
            .unwrap_err()
            .contains("Ahead, Astern"));
    }
}
