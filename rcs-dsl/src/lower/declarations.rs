//! Stage 2, second half, the controllers: pass 1 declares every
//! controller's commands, statuses, errors, vars and hooks; pass 2 checks
//! var initialisers and lowers the plans (through `lower::plans`).

use super::expr::Cx;
use super::{duplicate, resolve_type, resolve_type_in, ByName, Globals};
use crate::ast;
use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use crate::ir::*;
use crate::manifest::DEFAULT_PERIOD_NS;
use crate::source::Span;

/// Pass 1 for every controller: commands, statuses, errors, vars, hooks.
pub(super) fn lower_declarations(g: &Globals, ir: &mut Ir, diags: &mut Diagnostics) {
    for (i, c) in g.controllers.iter().enumerate() {
        g.scope.set(Some(i));
        let mut commands: Vec<Command> = Vec::new();
        let mut statuses = std::mem::take(&mut ir.controllers[i].statuses);
        let mut errors: Vec<ErrorDef> = Vec::new();
        let (mut command_names, mut error_names) = (ByName::default(), ByName::default());
        let mut status_names = ByName::of(statuses.iter().map(|s| s.name.as_str()));
        let mut vars: Vec<Var> = Vec::new();
        let mut hooks: Vec<Hook> = Vec::new();
        // One value namespace: vars, hooks, buffers and subordinates.
        let mut values: Vec<(String, Span)> = Vec::new();
        let mut value_names = ByName::default();
        // A name given twice keeps its first place (the buffer and
        // subordinate checks report the second).
        let mut first_value = |n: &ast::Name| {
            if value_names.first_or_insert(&n.text, values.len()).is_none() {
                values.push((n.text.to_string(), n.span));
            }
        };
        for e in &c.entries {
            match &e.kind {
                ast::EntryKind::Reads(n, _) | ast::EntryKind::Writes(n, _) => first_value(n),
                ast::EntryKind::Subordinates(ns) => ns.iter().for_each(&mut first_value),
                _ => {}
            }
        }
        let mut claim = |name: &ast::Name, what: &str, diags: &mut Diagnostics| -> bool {
            if let Some(d) = super::consts::reserved(name) {
                diags.push(d);
            }
            if g.consts_table.is_file_const(&name.text) {
                diags.push(
                    Diagnostic::error(
                        Code::DuplicateDefinition,
                        format!("`{}` is already a file-level constant", name.text),
                        name.span,
                        "would shadow the constant",
                    )
                    .with_help("names of a controller do not shadow file-level constants; rename one of them"),
                );
                return false;
            }
            let found = value_names.first_or_insert(&name.text, values.len());
            if let Some((_, first)) = found.map(|k| &values[k]) {
                // `reads`, `writes` and `subordinates` were collected first;
                // the diagnostic goes on whichever declaration comes later.
                let (later, earlier) = if first.start > name.span.start {
                    (*first, name.span)
                } else {
                    (name.span, *first)
                };
                diags.push(duplicate(what, &name.text, later, earlier));
                false
            } else {
                values.push((name.text.to_string(), name.span));
                true
            }
        };
        for e in &c.entries {
            let docs = &e.outer.docs;
            match &e.kind {
                ast::EntryKind::Command {
                    name,
                    params,
                    accept,
                } => {
                    let n = commands.len();
                    if !command_names.claim("command", name, n, |k| commands[k].span, diags) {
                        continue;
                    }
                    commands.push(Command {
                        name: name.text.to_string(),
                        docs: docs.clone(),
                        params: lower_params(g, params, diags),
                        plan: None,
                        span: name.span,
                        // Known from here on (other controllers' bodies
                        // ask whether X can refuse); the condition itself
                        // is lowered with the body.
                        accept: accept.as_ref().map(|a| Accept {
                            cond: Expr {
                                kind: ExprKind::Bool(true),
                                ty: Type::Bool,
                                span: a.keyword,
                            },
                            span: a.keyword,
                        }),
                    });
                }
                ast::EntryKind::Status(names) => {
                    for name in names {
                        if let Some(first) = status_names
                            .first_or_insert(&name.text, statuses.len())
                            .map(|k| &statuses[k])
                        {
                            match first.span {
                                Some(f) => diags.push(duplicate("status", &name.text, name.span, f)),
                                None => diags.push(
                                    Diagnostic::error(
                                        Code::DuplicateDefinition,
                                        format!("`{}` is a built-in status", name.text),
                                        name.span,
                                        "already defined by every controller",
                                    )
                                    .with_help("custom statuses come on top of NOT_READY, EXECUTING, DONE and ERROR"),
                                ),
                            }
                            continue;
                        }
                        statuses.push(StatusDef {
                            name: name.text.to_string(),
                            docs: docs.clone(),
                            span: Some(name.span),
                        });
                    }
                }
                ast::EntryKind::Error(names) => {
                    for name in names {
                        if crate::error_codes::is_builtin(&name.text) {
                            diags.push(
                                Diagnostic::error(
                                    Code::DuplicateDefinition,
                                    format!("`{}` is a built-in error code", name.text),
                                    name.span,
                                    "already defined for every controller",
                                )
                                .with_help("declared codes come on top of UNKNOWN_COMMAND, INDEX_RANGE, HOOK_PANIC and REFUSED: choose another name"),
                            );
                            continue;
                        }
                        let n = errors.len();
                        if !error_names.claim("error code", name, n, |k| errors[k].span, diags) {
                            continue;
                        }
                        errors.push(ErrorDef {
                            name: name.text.to_string(),
                            docs: docs.clone(),
                            span: name.span,
                        });
                    }
                }
                ast::EntryKind::Var { name, ty, .. }
                | ast::EntryKind::StatusField { name, ty, .. } => {
                    let status_field = matches!(e.kind, ast::EntryKind::StatusField { .. });
                    if status_field {
                        // A reserved name is reported, and the field still
                        // declared so that its uses do not cascade.
                        super::every_cycle::status_field_name_free(name, diags);
                    }
                    if !claim(name, "name", diags) {
                        continue;
                    }
                    vars.push(declare_var(g, name, ty, docs, status_field, diags));
                }
                ast::EntryKind::Hook { name, params, ret } => {
                    if !claim(name, "name", diags) {
                        continue;
                    }
                    let params = lower_params(g, params, diags);
                    let ret = match ret {
                        Some(t) => resolve_type(g, t, diags).unwrap_or(Type::Unit),
                        None => Type::Unit,
                    };
                    hooks.push(Hook {
                        name: name.text.to_string(),
                        docs: docs.clone(),
                        params,
                        ret,
                        span: name.span,
                    });
                }
                ast::EntryKind::Const(k) => {
                    claim(&k.name, "name", diags);
                }
                ast::EntryKind::Reads(n, _) | ast::EntryKind::Writes(n, _) => {
                    if let Some(d) = super::consts::reserved(n) {
                        diags.push(d);
                    }
                }
                _ => {}
            }
        }
        g.scope.set(None);
        super::every_cycle::check_status_value_clash(&vars, &statuses, diags);
        let ctrl = &mut ir.controllers[i];
        ctrl.commands = commands;
        ctrl.statuses = statuses;
        ctrl.errors = errors;
        ctrl.vars = vars;
        ctrl.hooks = hooks;
    }
}

/// A var or status field as pass 1 declares it: its type resolved, its
/// initialiser left for pass 2 (it may name constants and enum variants).
fn declare_var(
    g: &Globals,
    name: &ast::Name,
    ty: &ast::TypeExpr,
    docs: &[String],
    status_field: bool,
    diags: &mut Diagnostics,
) -> Var {
    Var {
        name: name.text.to_string(),
        docs: docs.to_vec(),
        // Unresolved: keep the var so its uses do not cascade.
        ty: resolve_type(g, ty, diags).unwrap_or(Type::Unit),
        init: None,
        span: name.span,
        status_field,
    }
}

fn lower_params(g: &Globals, params: &[ast::Param], diags: &mut Diagnostics) -> Vec<Param> {
    let mut out: Vec<Param> = Vec::new();
    let mut names = ByName::default();
    for p in params {
        if !names.claim("parameter", &p.name, out.len(), |k| out[k].span, diags) {
            continue;
        }
        let ty = resolve_type(g, &p.ty, diags).unwrap_or(Type::Unit);
        out.push(Param {
            name: p.name.text.to_string(),
            docs: p.docs.clone(),
            ty,
            span: p.name.span,
        });
    }
    out
}

/// Pass 2 for one controller: var initialisers and plans.
pub(super) fn lower_controller_body(
    g: &Globals,
    names: &super::index::Index,
    ir: &Ir,
    id: CtrlId,
    c: &ast::ControllerDef,
    plan_rows: Vec<Vec<ast::Row>>,
) -> ControllerBody {
    // The rows of each plan entry, in order (taken out of the AST: see
    // `take_plan_rows`); each is dropped once its plan is lowered.
    let mut plan_rows = plan_rows.into_iter();
    let mut diags = Diagnostics::new();
    let diags = &mut diags;
    let mut inits = Vec::new();
    let mut accepts = Vec::new();
    let mut plans: Vec<Plan> = Vec::new();
    let (mut pre, mut post): (Option<EveryCycle>, Option<EveryCycle>) = (None, None);
    let mut plan_of: Vec<Option<PlanId>> = vec![None; ir.controllers[id.index()].commands.len()];
    let written_times;
    {
        let ctrl = &ir.controllers[id.index()];
        // Hooks whose declared return type did not resolve (already reported).
        let unresolved_hooks: Vec<String> = c
            .entries
            .iter()
            .filter_map(|e| match &e.kind {
                ast::EntryKind::Hook {
                    name, ret: Some(t), ..
                } if resolve_type_in(g, Some(id.index()), t, &mut Diagnostics::new()).is_none() => {
                    Some(name.text.to_string())
                }
                _ => None,
            })
            .collect();
        let mut cx = Cx {
            g,
            ix: names,
            ir,
            ctrl: id,
            c: ctrl,
            plan_cmd: None,
            const_ctx: true,
            unresolved_hooks,
            diags,
            plan_verbs: Vec::new(),
            accept_ctx: false,
            time: super::time::TimeCx {
                period_ns: g
                    .periods
                    .get(ctrl.name.as_str())
                    .map_or(DEFAULT_PERIOD_NS, |(p, _)| *p),
                written: Vec::new(),
            },
        };
        for e in &c.entries {
            match &e.kind {
                ast::EntryKind::Command {
                    name,
                    accept: Some(a),
                    ..
                } => {
                    // The arriving command's parameters, like in its plan.
                    let Some(ci) = ctrl
                        .commands
                        .iter()
                        .position(|k| k.name == name.text && k.span == name.span)
                    else {
                        continue;
                    };
                    let cmd = CommandId(ci as u32);
                    cx.const_ctx = false;
                    cx.accept_ctx = true;
                    cx.plan_cmd = Some(cmd);
                    cx.plan_verbs = vec![cmd];
                    let cond = cx.check(&a.cond, &Type::Bool);
                    cx.accept_ctx = false;
                    cx.plan_verbs.clear();
                    accepts.push((
                        ci,
                        Accept {
                            cond,
                            span: a.keyword,
                        },
                    ));
                }
                ast::EntryKind::Var {
                    name,
                    init: Some(init),
                    ..
                }
                | ast::EntryKind::StatusField {
                    name,
                    init: Some(init),
                    ..
                } => {
                    let Some(vi) = ctrl
                        .vars
                        .iter()
                        .position(|v| v.name == name.text && v.span == name.span)
                    else {
                        continue;
                    };
                    let ty = ctrl.vars[vi].ty.clone();
                    if ty == Type::Unit {
                        continue; // its type did not resolve; already reported
                    }
                    cx.const_ctx = true;
                    cx.plan_cmd = None;
                    let e = cx.check(init, &ty);
                    inits.push((vi, e));
                }
                ast::EntryKind::Plan(p) => {
                    let rows = plan_rows.next().unwrap_or_default();
                    let Some(verbs) = cx.plan_verbs(p, &plan_of, &plans) else {
                        continue;
                    };
                    let cmd = verbs[0];
                    cx.const_ctx = false;
                    cx.plan_cmd = Some(cmd);
                    cx.plan_verbs = verbs.clone();
                    let mut plan = cx.plan(p, rows, cmd, &e.outer);
                    for v in &verbs {
                        plan_of[v.index()] = Some(PlanId(plans.len() as u32));
                    }
                    plan.verbs = verbs;
                    plans.push(plan);
                    cx.plan_verbs.clear();
                }
                ast::EntryKind::EveryCycle(def) => {
                    cx.const_ctx = false;
                    cx.plan_cmd = None;
                    let slot = match def.phase {
                        ast::Phase::Pre => &mut pre,
                        ast::Phase::Post => &mut post,
                    };
                    cx.every_cycle(def, slot);
                }
                _ => {}
            }
        }
        written_times = std::mem::take(&mut cx.time.written);
    }
    ControllerBody {
        inits,
        accepts,
        plans,
        plan_of,
        pre,
        post,
        diags: std::mem::take(diags),
        written_times,
    }
}

/// What lowering a controller's body produced, computed from a shared `&Ir`
/// (so that controllers are lowered on worker threads) and then put into
/// the controller by [`ControllerBody::apply`].
pub(super) struct ControllerBody {
    /// Each var's initial value, by the var's index.
    inits: Vec<(usize, Expr)>,
    /// Each `accept when` condition, by its command's index.
    accepts: Vec<(usize, Accept)>,
    pub(super) plans: Vec<Plan>,
    /// Each command's plan, by the command's index.
    plan_of: Vec<Option<PlanId>>,
    /// The `pre` and `post` blocks.
    pre: Option<EveryCycle>,
    post: Option<EveryCycle>,
    pub diags: Diagnostics,
    /// Comparisons of times with durations (`lower::time`).
    pub(super) written_times: Vec<WrittenTime>,
}

impl ControllerBody {
    pub(super) fn apply(self, ctrl: &mut Controller) {
        for (vi, e) in self.inits {
            ctrl.vars[vi].init = Some(e);
        }
        for (cmd, p) in ctrl.commands.iter_mut().zip(self.plan_of) {
            cmd.plan = p;
        }
        for (ci, a) in self.accepts {
            ctrl.commands[ci].accept = Some(a);
        }
        ctrl.plans = self.plans;
        ctrl.pre = self.pre;
        ctrl.post = self.post;
        ctrl.written_times = self.written_times;
    }
}
