//! Stage 2, every-cycle processing and status data (LANGUAGE.md §7): the
//! `pre { }` / `post { }` blocks of a controller (assignments and hook
//! calls only: a send, a `report` or a target there is
//! `every_cycle_decision`, a second block of a kind `every_cycle_twice`),
//! the names a status field may take, and `X.NAME`, a supervisor's read of
//! a subordinate's status field. Called from `lower::declarations` and the
//! expression checker of `lower::expr`.

use super::expr::{err_expr, Cx, Ty};
use crate::ast;
use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use crate::ir::*;
use crate::source::Span;

/// What a supervisor reads through the handshake as `X.prop`: a status
/// field of one of these names could never be read.
const SUB_PROPS: [&str; 5] = ["status", "done", "executing", "error", "stale_cycles"];

/// A status field may not take the name of a subordinate property.
pub(super) fn status_field_name_free(name: &ast::Name, diags: &mut Diagnostics) {
    if !SUB_PROPS.contains(&name.text.as_str()) {
        return;
    }
    diags.push(
        Diagnostic::error(
            Code::DuplicateDefinition,
            format!(
                "a status field cannot be named `{}`: a supervisor reads `X.{}` through the handshake",
                name.text, name.text
            ),
            name.span,
            "handshake property",
        )
        .with_help("rename the field; `status`, `done`, `executing`, `error` and `stale_cycles` are taken"),
    );
}

/// A status field named like one of the controller's status values (`status
/// AT_GOAL` and `status AT_GOAL: f64`) would make `X.AT_GOAL` and
/// `X::AT_GOAL` mean different things: refused, at the later declaration.
pub(super) fn check_status_value_clash(
    vars: &[Var],
    statuses: &[StatusDef],
    diags: &mut Diagnostics,
) {
    for v in vars.iter().filter(|v| v.status_field) {
        let Some(s) = statuses.iter().find(|s| s.name == v.name) else {
            continue;
        };
        let Some(first) = s.span else {
            diags.push(
                Diagnostic::error(
                    Code::DuplicateDefinition,
                    format!("`{}` is a built-in status", v.name),
                    v.span,
                    "status field named like a built-in status",
                )
                .with_help("rename the status field"),
            );
            continue;
        };
        let (later, earlier) = if first.start > v.span.start {
            (first, v.span)
        } else {
            (v.span, first)
        };
        diags.push(super::duplicate("status", &v.name, later, earlier));
    }
}

impl Cx<'_, '_> {
    /// Lower one `pre`/`post` block into `slot` (reporting a second one).
    pub(in crate::lower) fn every_cycle(
        &mut self,
        def: &ast::EveryCycleDef,
        slot: &mut Option<EveryCycle>,
    ) {
        let kw = def.phase.keyword();
        if let Some(first) = slot {
            self.diags.push(
                Diagnostic::error(
                    Code::EveryCycleTwice,
                    format!("controller `{}` has a second `{kw}` block", self.c.name),
                    def.keyword,
                    format!("second `{kw}`"),
                )
                .with_secondary(first.span, format!("first `{kw}` here"))
                .with_help(format!(
                    "merge the two blocks into one: a controller runs one `{kw}` block every cycle"
                )),
            );
            return;
        }
        if let Some(t) = &def.target {
            self.decision(
                t.span(),
                kw,
                "a target",
                "state changes, `Done` and `Error` belong in the rows".to_string(),
            );
        }
        let mut jobs = Vec::new();
        for j in &def.jobs {
            let refused = match j {
                ast::Job::Send { span, sub, .. } => Some((
                    *span,
                    "a command",
                    format!("send `{} <- …` from a row of a plan", sub.text),
                )),
                ast::Job::Forward { span, sub } => Some((
                    *span,
                    "a forwarded command",
                    format!(
                        "forward with `{} <- cmd` from a row of a plan: a block that runs \
                         every cycle has no command of its own to forward",
                        sub.text
                    ),
                )),
                ast::Job::Report(_, span) | ast::Job::ReportCode(_, _, span) => Some((
                    *span,
                    "a `report`",
                    "report from a row of a plan; a `pre` or `post` block may set status fields"
                        .to_string(),
                )),
                ast::Job::Assign { .. } | ast::Job::Call(_) => None,
            };
            match refused {
                Some((span, what, help)) => self.decision(span, kw, what, help),
                None => jobs.extend(self.job(j)),
            }
        }
        *slot = Some(EveryCycle {
            jobs,
            span: def.keyword,
        });
    }

    fn decision(&mut self, span: Span, kw: &str, what: &str, help: String) {
        self.diags.push(
            Diagnostic::error(
                Code::EveryCycleDecision,
                format!("a `{kw}` block cannot hold {what}: it runs every cycle, whatever the plan decides"),
                span,
                format!("{what} in `{kw}`"),
            )
            .with_help(help),
        );
    }

    /// `cmd.P` outside any plan: only a `pre`/`post` block gets here (a var
    /// initialiser is a constant context). It reads parameter P of the
    /// command being executed (LANGUAGE.md §7): every verb that declares
    /// P must declare it with one type; the value is that type's zero
    /// before the first command and while a verb without P runs.
    pub(in crate::lower) fn current_param(&mut self, span: Span, param: &str) -> (Expr, Ty) {
        let mut verbs: Vec<(CommandId, ParamId, &Type)> = Vec::new();
        for (ci, c) in self.c.commands.iter().enumerate() {
            if let Some(pi) = c.params.iter().position(|p| p.name == param) {
                verbs.push((CommandId(ci as u32), ParamId(pi as u32), &c.params[pi].ty));
            }
        }
        let Some(&(first_verb, _, ty)) = verbs.first() else {
            self.diags.push(
                Diagnostic::error(
                    Code::UnknownName,
                    format!("no command of `{}` has a parameter `{param}`", self.c.name),
                    span,
                    "no such parameter",
                )
                .with_help(
                    "`cmd.P` in `pre` and `post` reads parameter P of the command being executed",
                )
                .suggest(
                    param,
                    self.c
                        .commands
                        .iter()
                        .flat_map(|c| c.params.iter().map(|p| p.name.as_str())),
                ),
            );
            return (err_expr(span), Ty::Err);
        };
        if *ty == Type::Unit {
            return (err_expr(span), Ty::Err);
        }
        if let Some(&(other, _, other_ty)) = verbs.iter().find(|(_, _, t)| *t != ty) {
            let name = |v: CommandId| self.c.commands[v.index()].name.clone();
            let (a, b) = (name(first_verb), name(other));
            let (ta, tb) = (
                crate::lower::type_name(self.ir, ty),
                crate::lower::type_name(self.ir, other_ty),
            );
            self.mismatch(
                span,
                format!("`cmd.{param}` is a `{ta}` in `{a}` but a `{tb}` in `{b}`"),
                "one name, two types".to_string(),
            );
            self.help_last("`pre` and `post` run whatever the command; give the parameter one type in every verb that has it");
            return (err_expr(span), Ty::Err);
        }
        let ty = ty.clone();
        let list = verbs.iter().map(|&(v, p, _)| (v, p)).collect();
        (
            Expr {
                kind: ExprKind::CurrentParam(list),
                ty: ty.clone(),
                span,
            },
            Ty::Known(ty),
        )
    }

    /// `X.NAME` where NAME is not a handshake property: status field NAME of
    /// subordinate X, or `None` when X has none of that name.
    pub(in crate::lower) fn sub_field(
        &mut self,
        cid: CtrlId,
        span: Span,
        name: &str,
    ) -> Option<(Expr, Ty)> {
        let sub = &self.ir.controllers[cid.index()];
        let (vid, v) = sub.status_fields().find(|(_, v)| v.name == name)?;
        if v.ty == Type::Unit {
            return Some((err_expr(span), Ty::Err)); // its type did not resolve
        }
        let ty = v.ty.clone();
        Some((
            Expr {
                kind: ExprKind::SubField(cid, vid),
                ty: ty.clone(),
                span,
            },
            Ty::Known(ty),
        ))
    }

    /// The help of an unknown `X.NAME`: what X offers.
    pub(in crate::lower) fn sub_offers(&self, cid: CtrlId, name: &str) -> String {
        let sub = &self.ir.controllers[cid.index()];
        let fields: Vec<&str> = sub.status_fields().map(|(_, v)| v.name.as_str()).collect();
        let close = crate::suggest::closest(name, fields.iter().copied());
        let mut help =
            "a subordinate offers `status`, `done`, `executing`, `error` and `stale_cycles`"
                .to_string();
        if !fields.is_empty() {
            help.push_str(&format!(", and its status fields: {}", fields.join(", ")));
        }
        if let Some(f) = close {
            help = format!("did you mean `{}.{f}`? {help}", sub.name);
        }
        help
    }
}

impl Cx<'_, '_> {
    /// `report ERROR(CODE)`: status ERROR with a code, and the plan goes on.
    pub(in crate::lower) fn report_code(
        &mut self,
        name: &ast::Name,
        code: &ast::Name,
        span: Span,
    ) -> Option<Job> {
        if name.text != "ERROR" {
            self.diags.push(
                Diagnostic::error(
                    Code::WrongArguments,
                    format!(
                        "only `report ERROR` takes an error code, not `report {}`",
                        name.text
                    ),
                    code.span,
                    "unexpected code",
                )
                .with_help(format!("write `report {}`", name.text)),
            );
            return None;
        }
        let (error, error_of) = match self.error_code(code)? {
            super::plans::ErrorRef::Declared(e) => (Some(e), None),
            super::plans::ErrorRef::Held(v) => (None, Some(v)),
        };
        Some(Job::Report {
            status: StatusId::ERROR,
            span,
            error,
            error_of,
        })
    }
}
