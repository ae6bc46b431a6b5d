//! Stage 2, second half: controller declarations, plans, rows, jobs and the
//! expression type checker. Types flow both ways: an expected type (from an
//! assignment target, a parameter or the other operand) fixes integer and
//! float literals and resolves bare enum variants and statuses.

use super::{duplicate, primitive, resolve_type, Globals, ItemRef};
use crate::ast::{self, AssignOp, BinOp, UnOp};
use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use crate::ir::*;
use crate::source::Span;

/// A type during checking: literals stay flexible until something fixes them.
#[derive(Clone, Debug, PartialEq)]
enum Ty {
    Known(Type),
    IntLit,
    FloatLit,
    /// Already reported: fits everywhere and reports nothing more.
    Err,
}

/// What a bare name in a controller stands for.
#[derive(Clone, Copy, Debug)]
enum Value {
    Var(VarId),
    Buffer(BufferId, bool),
    Hook(HookId),
    Sub,
}

/// Pass 1 for every controller: commands, statuses, errors, vars, hooks.
pub(super) fn lower_declarations(g: &Globals, ir: &mut Ir, diags: &mut Diagnostics) {
    for (i, c) in g.controllers.iter().enumerate() {
        let mut commands: Vec<Command> = Vec::new();
        let mut statuses = std::mem::take(&mut ir.controllers[i].statuses);
        let mut errors: Vec<ErrorDef> = Vec::new();
        let mut vars: Vec<Var> = Vec::new();
        let mut hooks: Vec<Hook> = Vec::new();
        // One value namespace: vars, hooks, buffers and subordinates.
        let mut values: Vec<(String, Span)> = Vec::new();
        for e in &c.entries {
            match &e.kind {
                ast::EntryKind::Reads(n, _) | ast::EntryKind::Writes(n, _) => {
                    values.push((n.text.to_string(), n.span))
                }
                ast::EntryKind::Subordinates(ns) => {
                    for n in ns {
                        if !values.iter().any(|(v, _)| *v == n.text) {
                            values.push((n.text.to_string(), n.span));
                        }
                    }
                }
                _ => {}
            }
        }
        let mut claim = |name: &ast::Name, what: &str, diags: &mut Diagnostics| -> bool {
            if let Some((_, first)) = values.iter().find(|(v, _)| *v == name.text) {
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
                ast::EntryKind::Command(name, params) => {
                    if let Some(first) = commands.iter().find(|x| x.name == name.text) {
                        diags.push(duplicate("command", &name.text, name.span, first.span));
                        continue;
                    }
                    commands.push(Command {
                        name: name.text.to_string(),
                        docs: docs.clone(),
                        params: lower_params(g, params, diags),
                        plan: None,
                        span: name.span,
                    });
                }
                ast::EntryKind::Status(names) => {
                    for name in names {
                        if let Some(first) = statuses.iter().find(|x| x.name == name.text) {
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
                        if let Some(first) = errors.iter().find(|x| x.name == name.text) {
                            diags.push(duplicate("error code", &name.text, name.span, first.span));
                            continue;
                        }
                        errors.push(ErrorDef {
                            name: name.text.to_string(),
                            docs: docs.clone(),
                            span: name.span,
                        });
                    }
                }
                ast::EntryKind::Var { name, ty, .. } => {
                    if !claim(name, "name", diags) {
                        continue;
                    }
                    let ty = resolve_type(g, ty, diags);
                    vars.push(Var {
                        name: name.text.to_string(),
                        docs: docs.clone(),
                        // Unresolved: keep the var so its uses do not cascade.
                        ty: ty.unwrap_or(Type::Unit),
                        init: None,
                        span: name.span,
                    });
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
                _ => {}
            }
        }
        let ctrl = &mut ir.controllers[i];
        ctrl.commands = commands;
        ctrl.statuses = statuses;
        ctrl.errors = errors;
        ctrl.vars = vars;
        ctrl.hooks = hooks;
    }
}

fn lower_params(g: &Globals, params: &[ast::Param], diags: &mut Diagnostics) -> Vec<Param> {
    let mut out: Vec<Param> = Vec::new();
    for p in params {
        if let Some(first) = out.iter().find(|x| x.name == p.name.text) {
            diags.push(duplicate(
                "parameter",
                &p.name.text,
                p.name.span,
                first.span,
            ));
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
    ir: &mut Ir,
    id: CtrlId,
    c: &ast::ControllerDef,
    diags: &mut Diagnostics,
) {
    let mut inits = Vec::new();
    let mut plans: Vec<Plan> = Vec::new();
    let mut plan_of: Vec<Option<PlanId>> = vec![None; ir.controllers[id.index()].commands.len()];
    {
        let ctrl = &ir.controllers[id.index()];
        // Hooks whose declared return type did not resolve (already reported).
        let unresolved_hooks: Vec<String> = c
            .entries
            .iter()
            .filter_map(|e| match &e.kind {
                ast::EntryKind::Hook {
                    name, ret: Some(t), ..
                } if resolve_type(g, t, &mut Diagnostics::new()).is_none() => {
                    Some(name.text.to_string())
                }
                _ => None,
            })
            .collect();
        let mut cx = Cx {
            g,
            ir,
            ctrl: id,
            c: ctrl,
            plan_cmd: None,
            const_ctx: true,
            unresolved_hooks,
            diags,
        };
        for e in &c.entries {
            match &e.kind {
                ast::EntryKind::Var {
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
                    let Some(cmd) = ctrl.commands.iter().position(|x| x.name == p.verb.text) else {
                        cx.diags.push(
                            Diagnostic::error(
                                Code::UnknownCommand,
                                format!("`{}` has no command `{}`", ctrl.name, p.verb.text),
                                p.verb.span,
                                "no such command",
                            )
                            .with_help(format!("declare it: `command {}`", p.verb.text)),
                        );
                        continue;
                    };
                    if let Some(prev) = plan_of[cmd] {
                        let first: &Plan = &plans[prev.index()];
                        cx.diags
                            .push(duplicate("plan", &p.verb.text, p.verb.span, first.header));
                        continue;
                    }
                    cx.const_ctx = false;
                    cx.plan_cmd = Some(CommandId(cmd as u32));
                    let plan = cx.plan(p, CommandId(cmd as u32), &e.outer);
                    plan_of[cmd] = Some(PlanId(plans.len() as u32));
                    plans.push(plan);
                }
                _ => {}
            }
        }
    }
    let ctrl = &mut ir.controllers[id.index()];
    for (vi, e) in inits {
        ctrl.vars[vi].init = Some(e);
    }
    for (cmd, p) in ctrl.commands.iter_mut().zip(plan_of) {
        cmd.plan = p;
    }
    ctrl.plans = plans;
}

/// The checking context of one controller (and, inside a plan, its verb).
struct Cx<'a, 'g> {
    g: &'a Globals<'g>,
    ir: &'a Ir,
    ctrl: CtrlId,
    c: &'a Controller,
    plan_cmd: Option<CommandId>,
    /// In a var initialiser: only constants are allowed.
    const_ctx: bool,
    /// Hooks whose return type did not resolve: their calls fit everywhere.
    unresolved_hooks: Vec<String>,
    diags: &'a mut Diagnostics,
}

fn err_expr(span: Span) -> Expr {
    Expr {
        kind: ExprKind::Bool(false),
        ty: Type::Bool,
        span,
    }
}

impl Cx<'_, '_> {
    fn type_name(&self, t: &Type) -> String {
        type_name(self.ir, t)
    }

    fn ty_name(&self, t: &Ty) -> String {
        match t {
            Ty::Known(t) => format!("`{}`", self.type_name(t)),
            Ty::IntLit => "an integer literal".to_string(),
            Ty::FloatLit => "a float literal".to_string(),
            Ty::Err => "an unknown type".to_string(),
        }
    }

    fn mismatch(&mut self, span: Span, message: String, label: String) {
        self.diags
            .push(Diagnostic::error(Code::TypeMismatch, message, span, label));
    }

    fn value(&self, name: &str) -> Option<Value> {
        let c = self.c;
        if let Some(i) = c.vars.iter().position(|v| v.name == name) {
            return Some(Value::Var(VarId(i as u32)));
        }
        if let Some(b) = c
            .writes
            .iter()
            .find(|b| self.ir.buffers[b.index()].name == name)
        {
            return Some(Value::Buffer(*b, true));
        }
        if let Some(b) = c
            .reads
            .iter()
            .find(|b| self.ir.buffers[b.index()].name == name)
        {
            return Some(Value::Buffer(*b, false));
        }
        if let Some(i) = c.hooks.iter().position(|h| h.name == name) {
            return Some(Value::Hook(HookId(i as u32)));
        }
        if c.subordinates
            .iter()
            .any(|s| self.ir.controllers[s.index()].name == name)
        {
            return Some(Value::Sub);
        }
        None
    }

    fn not_const(&mut self, span: Span, what: &str) -> (Expr, Ty) {
        self.mismatch(
            span,
            format!("a `var` initialiser must be a constant, but this is {what}"),
            "not a constant".to_string(),
        );
        self.help_last(
            "initialise with literals and enum variants; set it in a plan's first row instead",
        );
        (err_expr(span), Ty::Err)
    }

    /// Add a help line to the diagnostic pushed last.
    fn help_last(&mut self, help: &str) {
        if let Some(d) = self.diags.last_mut() {
            d.help = Some(help.to_string());
        }
    }

    // ------------------------------------------------------------ types

    /// Check `e` against an expected type.
    fn check(&mut self, e: &ast::Expr, expected: &Type) -> Expr {
        let (mut ir, ty) = self.infer(e, Some(expected));
        self.expect(&mut ir, ty, expected, e.span);
        ir
    }

    /// Make an inferred expression have type `expected`, or report.
    fn expect(&mut self, ir: &mut Expr, ty: Ty, expected: &Type, span: Span) {
        match unify(&ty, &Ty::Known(expected.clone())) {
            Some(Ty::Err) => {}
            Some(_) => self.fix_literals(ir, expected),
            None => {
                let found = self.ty_name(&ty);
                self.mismatch(
                    span,
                    format!("expected `{}`, found {found}", self.type_name(expected)),
                    format!("expected `{}`", self.type_name(expected)),
                );
                if matches!(
                    (&ty, expected),
                    (
                        Ty::Known(Type::Int(_) | Type::Float(_)),
                        Type::Int(_) | Type::Float(_)
                    )
                ) {
                    self.help_last(&format!(
                        "convert explicitly with `as {}`",
                        self.type_name(expected)
                    ));
                }
            }
        }
    }

    /// Settle the type of a literal-only subtree once its context is known.
    fn fix_literals(&mut self, e: &mut Expr, ty: &Type) {
        let literal = match &e.kind {
            ExprKind::Int(_) | ExprKind::Float(_) => true,
            ExprKind::Unary(UnOp::Neg, _) | ExprKind::Binary(_, _, _) => e.ty != *ty,
            _ => false,
        };
        if !literal {
            return;
        }
        match (&mut e.kind, ty) {
            (ExprKind::Int(v), Type::Int(it)) => {
                let (lo, hi) = it.range();
                if *v < lo || *v > hi {
                    let v = *v;
                    self.mismatch(
                        e.span,
                        format!("literal `{v}` does not fit in `{}`", it.name()),
                        format!("`{}` holds {lo} to {hi}", it.name()),
                    );
                }
            }
            (ExprKind::Int(v), Type::Float(_)) => {
                let f = *v as f64;
                e.kind = ExprKind::Float(f);
            }
            // An `f64` literal that is finite but beyond `f32` (`1e300`)
            // would become infinity; refuse it as `1e400` is refused.
            (ExprKind::Float(v), Type::Float(FloatTy::F32)) if (*v as f32).is_infinite() => {
                let v = *v;
                self.mismatch(
                    e.span,
                    format!(
                        "literal `{}` does not fit in `f32`",
                        crate::pretty::float(v)
                    ),
                    format!("`f32` holds at most {:e} in magnitude", f32::MAX),
                );
            }
            (ExprKind::Unary(UnOp::Neg, inner), _) => self.fix_literals(inner, ty),
            (ExprKind::Binary(op, l, r), _) if is_arith(*op) => {
                self.fix_literals(l, ty);
                self.fix_literals(r, ty);
            }
            _ => {}
        }
        if matches!(
            e.kind,
            ExprKind::Int(_) | ExprKind::Float(_) | ExprKind::Unary(..)
        ) || matches!(&e.kind, ExprKind::Binary(op, ..) if is_arith(*op))
        {
            e.ty = ty.clone();
        }
    }

    /// Give a still-flexible root its default type (`i64` / `f64`).
    fn settle(&mut self, e: &mut Expr, ty: &Ty) -> Ty {
        match ty {
            Ty::IntLit => {
                self.fix_literals(e, &Type::Int(IntTy::I64));
                Ty::Known(Type::Int(IntTy::I64))
            }
            Ty::FloatLit => {
                self.fix_literals(e, &Type::Float(FloatTy::F64));
                Ty::Known(Type::Float(FloatTy::F64))
            }
            t => t.clone(),
        }
    }

    fn infer(&mut self, e: &ast::Expr, hint: Option<&Type>) -> (Expr, Ty) {
        let span = e.span;
        let mk = |kind: ExprKind, ty: Type| Expr { kind, ty, span };
        match &e.kind {
            ast::ExprKind::Paren(inner) => self.infer(inner, hint),
            ast::ExprKind::Int(v) => (
                mk(ExprKind::Int(*v as i128), Type::Int(IntTy::I64)),
                Ty::IntLit,
            ),
            ast::ExprKind::Float(v) => (
                mk(ExprKind::Float(*v), Type::Float(FloatTy::F64)),
                Ty::FloatLit,
            ),
            ast::ExprKind::Bool(b) => (mk(ExprKind::Bool(*b), Type::Bool), Ty::Known(Type::Bool)),
            ast::ExprKind::NewCommand | ast::ExprKind::StateCycles | ast::ExprKind::PlanCycles => {
                if self.const_ctx {
                    return self.not_const(span, "a plan quantity");
                }
                let (kind, ty) = match &e.kind {
                    ast::ExprKind::NewCommand => (ExprKind::NewCommand, Type::Bool),
                    ast::ExprKind::StateCycles => (ExprKind::StateCycles, Type::Int(IntTy::U32)),
                    _ => (ExprKind::PlanCycles, Type::Int(IntTy::U32)),
                };
                (mk(kind, ty.clone()), Ty::Known(ty))
            }
            ast::ExprKind::CmdParam(p) => {
                let Some(cmd) = self.plan_cmd else {
                    return self.not_const(span, "a command parameter");
                };
                let command = &self.c.commands[cmd.index()];
                match command.params.iter().position(|x| x.name == p.text) {
                    Some(pi) => {
                        let ty = command.params[pi].ty.clone();
                        if ty == Type::Unit {
                            return (err_expr(span), Ty::Err);
                        }
                        (
                            mk(ExprKind::CmdParam(cmd, ParamId(pi as u32)), ty.clone()),
                            Ty::Known(ty),
                        )
                    }
                    None => {
                        let have = if command.params.is_empty() {
                            format!("`{}` takes no parameters", command.name)
                        } else {
                            format!(
                                "the parameters of `{}` are: {}",
                                command.name,
                                command
                                    .params
                                    .iter()
                                    .map(|p| p.name.as_str())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            )
                        };
                        self.diags.push(
                            Diagnostic::error(
                                Code::UnknownName,
                                format!("command `{}` has no parameter `{}`", command.name, p.text),
                                p.span,
                                "no such parameter",
                            )
                            .with_help(have),
                        );
                        (err_expr(span), Ty::Err)
                    }
                }
            }
            ast::ExprKind::Path(qual, name) => self.path(qual.as_ref(), name, hint, span),
            ast::ExprKind::Call(name, args) => self.call(name, args, span),
            ast::ExprKind::Field(base, field) => self.field(base, field, span),
            ast::ExprKind::Index(base, idx) => {
                let (b, bt) = self.infer(base, None);
                let n = self.const_index(idx);
                match (bt, n) {
                    (Ty::Err, _) | (_, None) => (err_expr(span), Ty::Err),
                    (Ty::Known(Type::Array(elem, len)), Some(n)) => {
                        if n >= len as u64 {
                            self.mismatch(
                                idx.span,
                                format!("index {n} is out of bounds for an array of length {len}"),
                                format!("valid indices are 0 to {}", len - 1),
                            );
                            return (err_expr(span), Ty::Err);
                        }
                        (
                            mk(ExprKind::Index(Box::new(b), n as u32), (*elem).clone()),
                            Ty::Known(*elem),
                        )
                    }
                    (t, _) => {
                        let t = self.ty_name(&t);
                        self.mismatch(
                            base.span,
                            format!("cannot index into {t}"),
                            "not an array".to_string(),
                        );
                        (err_expr(span), Ty::Err)
                    }
                }
            }
            ast::ExprKind::Unary(op, inner) => self.unary(*op, inner, span),
            ast::ExprKind::Binary(op, l, r) => self.binary(*op, l, r, span),
            ast::ExprKind::Cast(inner, ty) => {
                let (mut x, t) = self.infer(inner, None);
                let target = match primitive(&ty.text) {
                    Some(t @ (Type::Int(_) | Type::Float(_))) => t,
                    Some(_) | None => {
                        let is_known = primitive(&ty.text).is_some()
                            || self.g.names.contains_key(ty.text.as_str());
                        if is_known {
                            self.mismatch(
                                ty.span,
                                format!("cannot cast to `{}`", ty.text),
                                "`as` converts between numeric types only".to_string(),
                            );
                        } else {
                            self.diags.push(Diagnostic::error(Code::UnknownName, format!("unknown type `{}`", ty.text), ty.span, "not a numeric type")
                                .with_help("`as` converts to i8, i16, i32, i64, u8, u16, u32, u64, f32 or f64"));
                        }
                        return (err_expr(span), Ty::Err);
                    }
                };
                match t {
                    Ty::Err => (err_expr(span), Ty::Err),
                    Ty::IntLit | Ty::FloatLit | Ty::Known(Type::Int(_) | Type::Float(_)) => {
                        self.settle(&mut x, &t);
                        (
                            mk(ExprKind::Cast(Box::new(x)), target.clone()),
                            Ty::Known(target),
                        )
                    }
                    Ty::Known(other) => {
                        self.mismatch(
                            inner.span,
                            format!("cannot cast `{}` to `{}`", self.type_name(&other), ty.text),
                            "not a number".to_string(),
                        );
                        (err_expr(span), Ty::Err)
                    }
                }
            }
        }
    }

    fn const_index(&mut self, idx: &ast::Expr) -> Option<u64> {
        match &idx.kind {
            ast::ExprKind::Int(n) => Some(*n as u64),
            ast::ExprKind::Paren(inner) => self.const_index(inner),
            _ => {
                self.mismatch(
                    idx.span,
                    "array index must be a constant integer".to_string(),
                    "not an integer literal".to_string(),
                );
                self.help_last("indices are checked at compile time so that no cycle can panic");
                None
            }
        }
    }

    fn path(
        &mut self,
        qual: Option<&ast::Name>,
        name: &ast::Name,
        hint: Option<&Type>,
        span: Span,
    ) -> (Expr, Ty) {
        let mk = |kind: ExprKind, ty: Type| Expr {
            kind,
            ty: ty.clone(),
            span,
        };
        if let Some(q) = qual {
            return match self.g.names.get(q.text.as_str()) {
                Some((ItemRef::Enum(eid), _)) => {
                    let en = &self.ir.enums[eid.index()];
                    match en.variants.iter().position(|v| v.name == name.text) {
                        Some(vi) => (
                            mk(ExprKind::Variant(*eid, vi as u32), Type::Enum(*eid)),
                            Ty::Known(Type::Enum(*eid)),
                        ),
                        None => {
                            self.diags.push(
                                Diagnostic::error(
                                    Code::UnknownName,
                                    format!("enum `{}` has no variant `{}`", en.name, name.text),
                                    name.span,
                                    "no such variant",
                                )
                                .with_help(format!(
                                    "the variants are: {}",
                                    en.variants
                                        .iter()
                                        .map(|v| v.name.as_str())
                                        .collect::<Vec<_>>()
                                        .join(", ")
                                )),
                            );
                            (err_expr(span), Ty::Err)
                        }
                    }
                }
                Some((ItemRef::Controller(cid), _)) => {
                    let ctrl = &self.ir.controllers[cid.index()];
                    match ctrl.statuses.iter().position(|s| s.name == name.text) {
                        Some(si) => (
                            mk(ExprKind::Status(StatusId(si as u32)), Type::Status(*cid)),
                            Ty::Known(Type::Status(*cid)),
                        ),
                        None => {
                            self.diags.push(Diagnostic::error(
                                Code::UnknownName,
                                format!("controller `{}` has no status `{}`", ctrl.name, name.text),
                                name.span,
                                "no such status",
                            ));
                            (err_expr(span), Ty::Err)
                        }
                    }
                }
                _ => {
                    self.diags.push(Diagnostic::error(
                        Code::UnknownName,
                        format!("unknown enum `{}`", q.text),
                        q.span,
                        "not an enum or controller",
                    ));
                    (err_expr(span), Ty::Err)
                }
            };
        }
        match self.value(&name.text) {
            Some(Value::Var(v)) => {
                if self.const_ctx {
                    return self.not_const(span, "a var");
                }
                let ty = self.c.vars[v.index()].ty.clone();
                if ty == Type::Unit {
                    return (err_expr(span), Ty::Err);
                }
                return (mk(ExprKind::Var(v), ty.clone()), Ty::Known(ty));
            }
            Some(Value::Buffer(b, _)) => {
                if self.const_ctx {
                    return self.not_const(span, "a buffer");
                }
                let ty = Type::Buffer(self.ir.buffers[b.index()].ty);
                return (mk(ExprKind::Buffer(b), ty.clone()), Ty::Known(ty));
            }
            Some(Value::Hook(_)) => {
                self.mismatch(
                    span,
                    format!("hook `{}` must be called", name.text),
                    "a hook, not a value".to_string(),
                );
                self.help_last(&format!("call it: `{}(…)`", name.text));
                return (err_expr(span), Ty::Err);
            }
            Some(Value::Sub) => {
                self.mismatch(
                    span,
                    format!("`{}` is a subordinate controller, not a value", name.text),
                    "a controller".to_string(),
                );
                self.help_last(&format!("use `{0}.status`, `{0}.done`, `{0}.executing`, `{0}.error` or `{0}.stale_cycles`", name.text));
                return (err_expr(span), Ty::Err);
            }
            None => {}
        }
        // A bare variant or status, resolved by the expected type first.
        match hint {
            Some(Type::Enum(eid)) => {
                if let Some(vi) = self.ir.enums[eid.index()]
                    .variants
                    .iter()
                    .position(|v| v.name == name.text)
                {
                    return (
                        mk(ExprKind::Variant(*eid, vi as u32), Type::Enum(*eid)),
                        Ty::Known(Type::Enum(*eid)),
                    );
                }
            }
            Some(Type::Status(cid)) => {
                let ctrl = &self.ir.controllers[cid.index()];
                if let Some(si) = ctrl.statuses.iter().position(|s| s.name == name.text) {
                    return (
                        mk(ExprKind::Status(StatusId(si as u32)), Type::Status(*cid)),
                        Ty::Known(Type::Status(*cid)),
                    );
                }
                // Compared with `X.status`: say what X can report.
                self.diags.push(
                    Diagnostic::error(
                        Code::UnknownName,
                        format!("controller `{}` has no status `{}`", ctrl.name, name.text),
                        name.span,
                        "no such status",
                    )
                    .with_help(format!(
                        "the statuses of `{}` are: {}",
                        ctrl.name,
                        ctrl.statuses
                            .iter()
                            .map(|s| s.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )),
                );
                return (err_expr(span), Ty::Err);
            }
            _ => {}
        }
        let owners: Vec<(usize, usize)> = self
            .ir
            .enums
            .iter()
            .enumerate()
            .filter_map(|(ei, en)| {
                en.variants
                    .iter()
                    .position(|v| v.name == name.text)
                    .map(|vi| (ei, vi))
            })
            .collect();
        match owners.as_slice() {
            [(ei, vi)] => {
                let eid = EnumId(*ei as u32);
                (
                    mk(ExprKind::Variant(eid, *vi as u32), Type::Enum(eid)),
                    Ty::Known(Type::Enum(eid)),
                )
            }
            [] => {
                let mut d = Diagnostic::error(
                    Code::UnknownName,
                    format!(
                        "cannot find `{}` in controller `{}`",
                        name.text, self.c.name
                    ),
                    name.span,
                    "not declared",
                );
                if let Some(cmd) = self.plan_cmd {
                    if self.c.commands[cmd.index()]
                        .params
                        .iter()
                        .any(|p| p.name == name.text)
                    {
                        d = d.with_help(format!(
                            "command parameters are read as `cmd.{}`",
                            name.text
                        ));
                    }
                }
                if d.help.is_none() {
                    if matches!(
                        self.g.names.get(name.text.as_str()),
                        Some((ItemRef::Controller(_), _))
                    ) {
                        d = d.with_help(format!(
                            "`{}` is a controller but not a subordinate of `{}`",
                            name.text, self.c.name
                        ));
                    } else {
                        d = d.with_help(
                            "declare it as a `var`, a `reads`/`writes` buffer, or an enum variant",
                        );
                    }
                }
                self.diags.push(d);
                (err_expr(span), Ty::Err)
            }
            many => {
                let enums: Vec<String> = many
                    .iter()
                    .map(|(ei, _)| format!("`{}::{}`", self.ir.enums[*ei].name, name.text))
                    .collect();
                self.diags.push(
                    Diagnostic::error(
                        Code::TypeMismatch,
                        format!("`{}` is a variant of several enums", name.text),
                        name.span,
                        "ambiguous variant",
                    )
                    .with_help(format!("write one of {}", enums.join(", "))),
                );
                (err_expr(span), Ty::Err)
            }
        }
    }

    fn call(&mut self, name: &ast::Name, args: &[ast::Expr], span: Span) -> (Expr, Ty) {
        if self.const_ctx {
            return self.not_const(span, "a hook call");
        }
        let hook = match self.value(&name.text) {
            Some(Value::Hook(h)) => h,
            _ => {
                self.diags.push(
                    Diagnostic::error(
                        Code::UnknownName,
                        format!(
                            "cannot find hook `{}` in controller `{}`",
                            name.text, self.c.name
                        ),
                        name.span,
                        "not a hook",
                    )
                    .with_help(format!("declare it: `hook {}(…) -> T`", name.text)),
                );
                for a in args {
                    self.infer_untyped(a);
                }
                return (err_expr(span), Ty::Err);
            }
        };
        let h = &self.c.hooks[hook.index()];
        if args.len() != h.params.len() {
            self.diags.push(
                Diagnostic::error(
                    Code::WrongArguments,
                    format!(
                        "hook `{}` takes {} argument{} but {} {} given",
                        h.name,
                        h.params.len(),
                        if h.params.len() == 1 { "" } else { "s" },
                        args.len(),
                        if args.len() == 1 { "was" } else { "were" }
                    ),
                    span,
                    format!(
                        "expected {} argument{}",
                        h.params.len(),
                        if h.params.len() == 1 { "" } else { "s" }
                    ),
                )
                .with_secondary(h.span, "hook declared here"),
            );
            for a in args {
                self.infer_untyped(a);
            }
            return (err_expr(span), Ty::Err);
        }
        let mut out = Vec::new();
        for (a, p) in args.iter().zip(h.params.clone()) {
            if p.ty == Type::Unit {
                self.infer_untyped(a);
                out.push(err_expr(a.span));
            } else {
                out.push(self.check(a, &p.ty));
            }
        }
        let ret = h.ret.clone();
        if self.unresolved_hooks.contains(&h.name) {
            return (err_expr(span), Ty::Err);
        }
        (
            Expr {
                kind: ExprKind::Call(hook, out),
                ty: ret.clone(),
                span,
            },
            Ty::Known(ret),
        )
    }

    fn field(&mut self, base: &ast::Expr, field: &ast::Name, span: Span) -> (Expr, Ty) {
        // `X.prop` on a controller name: the handshake view of a subordinate.
        if let ast::ExprKind::Path(None, x) = &base.kind {
            if self.value(&x.text).is_none() || matches!(self.value(&x.text), Some(Value::Sub)) {
                if let Some((ItemRef::Controller(cid), _)) = self.g.names.get(x.text.as_str()) {
                    return self.sub_prop(*cid, x, field, span);
                }
                let sub_prop = ["status", "done", "executing", "error", "stale_cycles"];
                if self.value(&x.text).is_none() && sub_prop.contains(&field.text.as_str()) {
                    self.diags.push(
                        Diagnostic::error(
                            Code::UnknownName,
                            format!("no controller named `{}`", x.text),
                            x.span,
                            "not declared",
                        )
                        .with_help(format!(
                            "`.{}` reads the status of a subordinate: a controller declared in this plan set and listed in `{}`'s `subordinates`",
                            field.text, self.c.name
                        )),
                    );
                    return (err_expr(span), Ty::Err);
                }
            }
        }
        let (b, bt) = self.infer(base, None);
        match bt {
            Ty::Err => (err_expr(span), Ty::Err),
            Ty::Known(Type::Buffer(bid)) => {
                let bty = &self.ir.buffer_types[bid.index()];
                match bty.fields.iter().position(|f| f.name == field.text) {
                    Some(fi) => {
                        let ty = bty.fields[fi].ty.clone();
                        if ty == Type::Unit {
                            return (err_expr(span), Ty::Err); // its type did not resolve
                        }
                        (
                            Expr {
                                kind: ExprKind::Field(Box::new(b), fi as u32),
                                ty: ty.clone(),
                                span,
                            },
                            Ty::Known(ty),
                        )
                    }
                    None => {
                        self.diags.push(
                            Diagnostic::error(
                                Code::UnknownName,
                                format!("buffer type `{}` has no field `{}`", bty.name, field.text),
                                field.span,
                                "no such field",
                            )
                            .with_help(format!(
                                "the fields are: {}",
                                bty.fields
                                    .iter()
                                    .map(|f| f.name.as_str())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ))
                            .with_secondary(bty.name_span, format!("`{}` declared here", bty.name)),
                        );
                        (err_expr(span), Ty::Err)
                    }
                }
            }
            t => {
                let t = self.ty_name(&t);
                self.mismatch(
                    field.span,
                    format!("{t} has no fields"),
                    format!("no field `{}`", field.text),
                );
                (err_expr(span), Ty::Err)
            }
        }
    }

    fn sub_prop(
        &mut self,
        cid: CtrlId,
        x: &ast::Name,
        field: &ast::Name,
        span: Span,
    ) -> (Expr, Ty) {
        if self.const_ctx {
            return self.not_const(span, "a subordinate's status");
        }
        if !self.c.subordinates.contains(&cid) {
            let d = if cid == self.ctrl {
                Diagnostic::error(
                    Code::UnknownSubordinate,
                    format!("`{}` cannot read its own status as a subordinate's", x.text),
                    x.span,
                    "this controller itself",
                )
                .with_help(
                    "a controller sees its subordinates' statuses; use `report` to set its own",
                )
            } else {
                Diagnostic::error(
                    Code::UnknownSubordinate,
                    format!("`{}` is not a subordinate of `{}`", x.text, self.c.name),
                    x.span,
                    "not a subordinate",
                )
                .with_help(format!("add it to `{}`'s `subordinates` list", self.c.name))
            };
            self.diags.push(d);
            return (err_expr(span), Ty::Err);
        }
        let (prop, ty) = match field.text.as_str() {
            "status" => (SubProp::Status, Type::Status(cid)),
            "done" => (SubProp::Done, Type::Bool),
            "executing" => (SubProp::Executing, Type::Bool),
            "error" => (SubProp::Error, Type::Bool),
            "stale_cycles" => (SubProp::StaleCycles, Type::Int(IntTy::U32)),
            other => {
                self.diags.push(Diagnostic::error(Code::UnknownName, format!("subordinate `{}` has no property `{other}`", x.text), field.span, "unknown property")
                    .with_help("a subordinate offers `status`, `done`, `executing`, `error` and `stale_cycles`"));
                return (err_expr(span), Ty::Err);
            }
        };
        (
            Expr {
                kind: ExprKind::Sub(cid, prop),
                ty: ty.clone(),
                span,
            },
            Ty::Known(ty),
        )
    }

    fn unary(&mut self, op: UnOp, inner: &ast::Expr, span: Span) -> (Expr, Ty) {
        let (x, t) = self.infer(inner, None);
        let ok = match (op, &t) {
            (_, Ty::Err) => return (err_expr(span), Ty::Err),
            (UnOp::Not, Ty::Known(Type::Bool)) => true,
            (UnOp::Neg, Ty::IntLit | Ty::FloatLit | Ty::Known(Type::Float(_))) => true,
            (UnOp::Neg, Ty::Known(Type::Int(it))) => it.signed(),
            _ => false,
        };
        if !ok {
            let (sym, want) = if op == UnOp::Not {
                ("!", "`bool`")
            } else {
                ("-", "a signed number")
            };
            let t = self.ty_name(&t);
            self.mismatch(
                span,
                format!("cannot apply `{sym}` to {t}"),
                format!("expected {want}"),
            );
            return (err_expr(span), Ty::Err);
        }
        // Fold `-literal` so that `-128` fits an `i8`.
        if op == UnOp::Neg {
            match x.kind {
                ExprKind::Int(v) => {
                    return (
                        Expr {
                            kind: ExprKind::Int(-v),
                            ty: x.ty,
                            span,
                        },
                        t,
                    )
                }
                ExprKind::Float(v) => {
                    return (
                        Expr {
                            kind: ExprKind::Float(-v),
                            ty: x.ty,
                            span,
                        },
                        t,
                    )
                }
                _ => {}
            }
        }
        let ty = x.ty.clone();
        (
            Expr {
                kind: ExprKind::Unary(op, Box::new(x)),
                ty,
                span,
            },
            t,
        )
    }

    fn binary(&mut self, op: BinOp, l: &ast::Expr, r: &ast::Expr, span: Span) -> (Expr, Ty) {
        match op {
            BinOp::And | BinOp::Or => {
                let a = self.check(l, &Type::Bool);
                let b = self.check(r, &Type::Bool);
                (
                    Expr {
                        kind: ExprKind::Binary(op, Box::new(a), Box::new(b)),
                        ty: Type::Bool,
                        span,
                    },
                    Ty::Known(Type::Bool),
                )
            }
            _ => {
                // Let a bare variant on the left take its type from the right.
                let left_first = !self.is_bare_unknown(l);
                let (mut a, mut ta, mut b, mut tb);
                if left_first {
                    (a, ta) = self.infer(l, None);
                    (b, tb) = self.infer_beside(r, &ta);
                } else {
                    (b, tb) = self.infer(r, None);
                    (a, ta) = self.infer_beside(l, &tb);
                }
                let Some(t) = unify(&ta, &tb) else {
                    let (na, nb) = (self.ty_name(&ta), self.ty_name(&tb));
                    self.diags.push(
                        Diagnostic::error(
                            Code::TypeMismatch,
                            format!("cannot apply `{}` to {na} and {nb}", op.symbol()),
                            span,
                            "mismatched operand types",
                        )
                        .with_secondary(l.span, na.clone())
                        .with_secondary(r.span, nb.clone()),
                    );
                    let numeric = |t: &Ty| {
                        matches!(
                            t,
                            Ty::IntLit | Ty::FloatLit | Ty::Known(Type::Int(_) | Type::Float(_))
                        )
                    };
                    let status = |t: &Ty| matches!(t, Ty::Known(Type::Status(_)));
                    if numeric(&ta) && numeric(&tb) {
                        self.help_last(
                            "no implicit conversions: use `as` to convert between numeric types",
                        );
                    } else if status(&ta) && status(&tb) {
                        self.help_last("each controller has its own statuses: compare each one with a status name, as in `X.status == DONE`");
                    }
                    return (err_expr(span), Ty::Err);
                };
                if t == Ty::Err {
                    return (err_expr(span), Ty::Err);
                }
                if let Ty::Known(k) = &t {
                    self.fix_literals(&mut a, k);
                    self.fix_literals(&mut b, k);
                    ta = t.clone();
                    tb = t.clone();
                }
                let _ = (&ta, &tb);
                let allowed = match op {
                    BinOp::Eq | BinOp::Ne => {
                        !matches!(t, Ty::Known(Type::Buffer(_) | Type::Array(..) | Type::Unit))
                    }
                    _ => matches!(
                        t,
                        Ty::IntLit | Ty::FloatLit | Ty::Known(Type::Int(_) | Type::Float(_))
                    ),
                };
                if !allowed {
                    let n = self.ty_name(&t);
                    let what = match op {
                        BinOp::Eq | BinOp::Ne => "compared",
                        BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => "ordered",
                        _ => "used in arithmetic",
                    };
                    self.mismatch(
                        span,
                        format!("values of {n} cannot be {what} with `{}`", op.symbol()),
                        format!("{n} here"),
                    );
                    return (err_expr(span), Ty::Err);
                }
                if is_arith(op) {
                    let ty = known(&t).unwrap_or(a.ty.clone());
                    (
                        Expr {
                            kind: ExprKind::Binary(op, Box::new(a), Box::new(b)),
                            ty,
                            span,
                        },
                        t,
                    )
                } else {
                    // A comparison of two literals: give them their defaults
                    // (with a known type, both sides were settled above).
                    if matches!(t, Ty::IntLit | Ty::FloatLit) {
                        let settled = self.settle(&mut a, &t);
                        if let Ty::Known(k) = &settled {
                            self.fix_literals(&mut b, k);
                        }
                    }
                    (
                        Expr {
                            kind: ExprKind::Binary(op, Box::new(a), Box::new(b)),
                            ty: Type::Bool,
                            span,
                        },
                        Ty::Known(Type::Bool),
                    )
                }
            }
        }
    }

    /// Infer an operand whose expected type is unknown because of an error
    /// already reported: a bare name that is no value here (most likely a
    /// variant or status) then gets the error type instead of a second report.
    fn infer_untyped(&mut self, e: &ast::Expr) -> (Expr, Ty) {
        if self.is_bare_unknown(e) {
            return (err_expr(e.span), Ty::Err);
        }
        self.infer(e, None)
    }

    /// Infer the operand beside one of type `other` (the other side of `==`).
    fn infer_beside(&mut self, e: &ast::Expr, other: &Ty) -> (Expr, Ty) {
        match other {
            Ty::Err => self.infer_untyped(e),
            t => self.infer(e, known(t).as_ref()),
        }
    }

    /// A bare name that is not a value here (probably a variant or status).
    fn is_bare_unknown(&self, e: &ast::Expr) -> bool {
        match &e.kind {
            ast::ExprKind::Paren(i) => self.is_bare_unknown(i),
            ast::ExprKind::Path(None, n) => self.value(&n.text).is_none(),
            _ => false,
        }
    }

    // ------------------------------------------------------------ plans

    fn plan(&mut self, p: &ast::PlanDef, cmd: CommandId, outer: &ast::Outer) -> Plan {
        let mut states = vec![State {
            name: "S0".to_string(),
            span: None,
        }];
        let mut rows = Vec::new();
        for (pos, r) in p.rows.iter().enumerate() {
            if let Some(row) = self.row(r, pos as u32, &mut states) {
                rows.push(row);
            }
        }
        let span = p
            .rows
            .last()
            .map(|r| p.header.to(r.span))
            .unwrap_or(p.header);
        Plan {
            verb: cmd,
            docs: outer.docs.clone(),
            states,
            rows,
            lints: outer.lints.iter().map(|(l, _)| *l).collect(),
            header: p.header,
            span,
        }
    }

    fn row(&mut self, r: &ast::Row, position: u32, states: &mut Vec<State>) -> Option<Row> {
        let intern = |states: &mut Vec<State>, n: &ast::Name| -> StateId {
            match states.iter().position(|s| s.name == n.text) {
                Some(i) => {
                    if states[i].span.is_none() {
                        states[i].span = Some(n.span);
                    }
                    StateId(i as u32)
                }
                None => {
                    states.push(State {
                        name: n.text.to_string(),
                        span: Some(n.span),
                    });
                    StateId(states.len() as u32 - 1)
                }
            }
        };
        let (from, from_span) = match &r.from {
            ast::From::DontCare(n, s) => {
                (From::DontCare(n.map(|n| n.min(u32::MAX as u64) as u32)), *s)
            }
            ast::From::Implicit => (From::DontCare(None), r.cond_span),
            ast::From::State(n) if n.text == "Done" || n.text == "Error" => {
                self.diags.push(
                    Diagnostic::error(
                        Code::UnreachableRow,
                        format!("a row cannot start in `{}`", n.text),
                        n.span,
                        "terminal state",
                    )
                    .with_help(format!(
                        "after `{}` the plan runs no rows until a new command arrives",
                        n.text
                    )),
                );
                (From::DontCare(None), n.span)
            }
            ast::From::State(n) => (From::State(intern(states, n)), n.span),
        };
        let (cond, is_entry) = match &r.cond {
            None => (Condition::Otherwise, false),
            Some(c) => {
                let e = self.check(c, &Type::Bool);
                let entry = has_new_command_conjunct(&e);
                (Condition::When(e), entry)
            }
        };
        let to = match &r.target {
            ast::Target::Same(_) => Target::Same,
            ast::Target::Error(None, _) => Target::Error(None),
            ast::Target::Error(Some(code), _) => {
                match self.c.errors.iter().position(|e| e.name == code.text) {
                    Some(i) => Target::Error(Some(ErrorId(i as u32))),
                    None => {
                        self.diags.push(
                            Diagnostic::error(
                                Code::UnknownName,
                                format!(
                                    "controller `{}` has no error code `{}`",
                                    self.c.name, code.text
                                ),
                                code.span,
                                "not declared",
                            )
                            .with_help(format!("declare it: `error {}`", code.text)),
                        );
                        Target::Error(None)
                    }
                }
            }
            ast::Target::State(n) if n.text == "Done" => Target::Done,
            ast::Target::State(n) => Target::State(intern(states, n)),
        };
        let jobs = r.jobs.iter().filter_map(|j| self.job(j)).collect();
        Some(Row {
            position,
            label: r.label.map(|(n, _)| n.min(u32::MAX as u64) as u32),
            docs: r.docs.clone(),
            from,
            cond,
            is_entry,
            to,
            jobs,
            line: 0,
            span: r.span,
            from_span,
            cond_span: r.cond_span,
            to_span: r.target.span(),
            label_span: r.label.map(|(_, s)| s),
        })
    }

    fn job(&mut self, j: &ast::Job) -> Option<Job> {
        match j {
            ast::Job::Report(name, span) => {
                match self.c.statuses.iter().position(|s| s.name == name.text) {
                    Some(i) if i >= 4 => Some(Job::Report {
                        status: StatusId(i as u32),
                        span: *span,
                    }),
                    Some(_) => {
                        let target = match name.text.as_str() {
                            "DONE" => "end the row with `-> Done`",
                            "ERROR" => "end the row with `-> Error(CODE)`",
                            _ => "the runtime sets it; report a custom status instead",
                        };
                        self.diags.push(
                            Diagnostic::error(
                                Code::UnknownName,
                                format!(
                                    "`report` takes a custom status, and `{}` is built in",
                                    name.text
                                ),
                                name.span,
                                "built-in status",
                            )
                            .with_help(target.to_string()),
                        );
                        None
                    }
                    None => {
                        self.diags.push(
                            Diagnostic::error(
                                Code::UnknownName,
                                format!(
                                    "controller `{}` has no status `{}`",
                                    self.c.name, name.text
                                ),
                                name.span,
                                "not declared",
                            )
                            .with_help(format!("declare it: `status {}`", name.text)),
                        );
                        None
                    }
                }
            }
            ast::Job::Call(e) => {
                let (x, _) = self.infer(e, None);
                Some(Job::Call(x))
            }
            ast::Job::Assign {
                place,
                op,
                value,
                span,
            } => {
                let p = self.place(place)?;
                if *op != AssignOp::Set && !matches!(p.ty, Type::Int(_) | Type::Float(_)) {
                    self.mismatch(
                        *span,
                        format!(
                            "`{}` needs a number, but the target is `{}`",
                            if *op == AssignOp::Add { "+=" } else { "-=" },
                            self.type_name(&p.ty)
                        ),
                        "not a number".to_string(),
                    );
                    self.infer_untyped(value);
                    return None;
                }
                let v = self.check(value, &p.ty);
                Some(Job::Assign {
                    place: p,
                    op: *op,
                    value: v,
                    span: *span,
                })
            }
            ast::Job::Send {
                sub,
                verb,
                args,
                span,
            } => self.send(sub, verb, args, *span),
        }
    }

    fn send(
        &mut self,
        sub: &ast::Name,
        verb: &ast::Name,
        args: &[(ast::Name, ast::Expr)],
        span: Span,
    ) -> Option<Job> {
        let infer_all = |cx: &mut Self| {
            for (_, a) in args {
                cx.infer_untyped(a);
            }
        };
        let sid = match self
            .c
            .subordinates
            .iter()
            .find(|s| self.ir.controllers[s.index()].name == sub.text)
        {
            Some(s) => *s,
            None => {
                let help = if matches!(
                    self.g.names.get(sub.text.as_str()),
                    Some((ItemRef::Controller(_), _))
                ) {
                    format!(
                        "add `{}` to `{}`'s `subordinates` list",
                        sub.text, self.c.name
                    )
                } else {
                    "commands go only to controllers listed in `subordinates`".to_string()
                };
                self.diags.push(
                    Diagnostic::error(
                        Code::UnknownSubordinate,
                        format!("`{}` is not a subordinate of `{}`", sub.text, self.c.name),
                        sub.span,
                        "not a subordinate",
                    )
                    .with_help(help),
                );
                infer_all(self);
                return None;
            }
        };
        let target = &self.ir.controllers[sid.index()];
        let Some(ci) = target.commands.iter().position(|c| c.name == verb.text) else {
            self.diags.push(
                Diagnostic::error(
                    Code::UnknownCommand,
                    format!("`{}` has no command `{}`", target.name, verb.text),
                    verb.span,
                    "no such command",
                )
                .with_help(format!(
                    "`{}` accepts: {}",
                    target.name,
                    target
                        .commands
                        .iter()
                        .map(|c| c.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            );
            infer_all(self);
            return None;
        };
        let command = &target.commands[ci];
        let mut slots: Vec<Option<Expr>> = vec![None; command.params.len()];
        let mut seen: Vec<Option<Span>> = vec![None; command.params.len()];
        let mut ok = true;
        for (n, a) in args {
            match command.params.iter().position(|p| p.name == n.text) {
                None => {
                    self.diags.push(
                        Diagnostic::error(
                            Code::WrongArguments,
                            format!(
                                "command `{}` of `{}` has no parameter `{}`",
                                command.name, target.name, n.text
                            ),
                            n.span,
                            "unknown parameter",
                        )
                        .with_secondary(command.span, "command declared here"),
                    );
                    self.infer_untyped(a);
                    ok = false;
                }
                Some(pi) => {
                    if let Some(first) = seen[pi] {
                        self.diags.push(
                            Diagnostic::error(
                                Code::WrongArguments,
                                format!("parameter `{}` is given twice", n.text),
                                n.span,
                                "repeated argument",
                            )
                            .with_secondary(first, "first given here"),
                        );
                        self.infer_untyped(a);
                        ok = false;
                        continue;
                    }
                    seen[pi] = Some(n.span);
                    let ty = command.params[pi].ty.clone();
                    slots[pi] = Some(if ty == Type::Unit {
                        self.infer_untyped(a).0
                    } else {
                        self.check(a, &ty)
                    });
                }
            }
        }
        let missing: Vec<&str> = command
            .params
            .iter()
            .zip(&slots)
            .filter(|(_, s)| s.is_none())
            .map(|(p, _)| p.name.as_str())
            .collect();
        if !missing.is_empty() && ok {
            self.diags.push(
                Diagnostic::error(
                    Code::WrongArguments,
                    format!(
                        "command `{}` of `{}` is missing {}",
                        command.name,
                        target.name,
                        missing
                            .iter()
                            .map(|m| format!("`{m}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                    span,
                    "missing arguments",
                )
                .with_secondary(command.span, "command declared here")
                .with_help(format!(
                    "pass every parameter by name: `{} <- {}({})`",
                    target.name,
                    command.name,
                    command
                        .params
                        .iter()
                        .map(|p| format!("{}: …", p.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            );
            return None;
        }
        if !ok {
            return None;
        }
        Some(Job::Send {
            sub: sid,
            command: CommandId(ci as u32),
            args: slots.into_iter().map(|s| s.expect("all filled")).collect(),
            span,
        })
    }

    /// Resolve an assignment target, reporting `assign_to_input` for inputs.
    fn place(&mut self, e: &ast::Expr) -> Option<Place> {
        let input = |cx: &mut Self, what: String, help: &str| {
            cx.diags.push(
                Diagnostic::error(
                    Code::AssignToInput,
                    format!("cannot assign to {what}"),
                    e.span,
                    "an input of this controller",
                )
                .with_help(help.to_string()),
            );
            None
        };
        match &e.kind {
            ast::ExprKind::Paren(i) => self.place(i),
            ast::ExprKind::Path(None, n) => match self.value(&n.text) {
                Some(Value::Var(v)) => {
                    let ty = self.c.vars[v.index()].ty.clone();
                    (ty != Type::Unit).then_some(Place { root: PlaceRoot::Var(v), path: Vec::new(), ty, span: e.span })
                }
                Some(Value::Buffer(b, true)) => Some(Place { root: PlaceRoot::Buffer(b), path: Vec::new(), ty: Type::Buffer(self.ir.buffers[b.index()].ty), span: e.span }),
                Some(Value::Buffer(_, false)) => input(self, format!("`{}`, a buffer this controller reads", n.text), "only `writes` buffers and `var`s can be assigned; another controller or an external writer owns this one"),
                Some(Value::Sub) => input(self, format!("subordinate `{}`", n.text), "command a subordinate with `X <- VERB(…)`"),
                Some(Value::Hook(_)) => input(self, format!("hook `{}`", n.text), "hooks are functions; call them"),
                None => {
                    self.infer(e, None);
                    None
                }
            },
            ast::ExprKind::CmdParam(p) => input(self, format!("`cmd.{}`", p.text), "the command buffer belongs to the supervisor; copy the value into a `var`"),
            ast::ExprKind::Field(base, f) => {
                if let ast::ExprKind::Path(None, x) = &base.kind {
                    if let Some((ItemRef::Controller(_), _)) = self.g.names.get(x.text.as_str()) {
                        if self.value(&x.text).is_none() || matches!(self.value(&x.text), Some(Value::Sub)) {
                            return input(self, format!("`{}.{}`", x.text, f.text), "a subordinate's status is written by the subordinate");
                        }
                    }
                }
                let mut p = self.place(base)?;
                match &p.ty {
                    Type::Buffer(bid) => {
                        let bty = &self.ir.buffer_types[bid.index()];
                        match bty.fields.iter().position(|x| x.name == f.text) {
                            Some(fi) => {
                                p.ty = bty.fields[fi].ty.clone();
                                if p.ty == Type::Unit {
                                    return None; // its type did not resolve; already reported
                                }
                                p.path.push(Projection::Field(fi as u32));
                                p.span = e.span;
                                Some(p)
                            }
                            None => {
                                self.diags.push(Diagnostic::error(Code::UnknownName, format!("buffer type `{}` has no field `{}`", bty.name, f.text), f.span, "no such field")
                                    .with_help(format!("the fields are: {}", bty.fields.iter().map(|f| f.name.as_str()).collect::<Vec<_>>().join(", "))));
                                None
                            }
                        }
                    }
                    t => {
                        let t = self.type_name(t);
                        self.mismatch(f.span, format!("`{t}` has no fields"), format!("no field `{}`", f.text));
                        None
                    }
                }
            }
            ast::ExprKind::Index(base, idx) => {
                let mut p = self.place(base)?;
                let n = self.const_index(idx)?;
                match p.ty.clone() {
                    Type::Array(elem, len) => {
                        if n >= len as u64 {
                            self.mismatch(idx.span, format!("index {n} is out of bounds for an array of length {len}"), format!("valid indices are 0 to {}", len - 1));
                            return None;
                        }
                        p.ty = *elem;
                        p.path.push(Projection::Index(n as u32));
                        p.span = e.span;
                        Some(p)
                    }
                    t => {
                        let t = self.type_name(&t);
                        self.mismatch(base.span, format!("cannot index into `{t}`"), "not an array".to_string());
                        None
                    }
                }
            }
            _ => input(self, "this expression".to_string(), "assign to a `var`, a `writes` buffer, or a field or element of one"),
        }
    }
}

fn known(t: &Ty) -> Option<Type> {
    match t {
        Ty::Known(t) => Some(t.clone()),
        _ => None,
    }
}

fn is_arith(op: BinOp) -> bool {
    matches!(
        op,
        BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div | BinOp::Rem
    )
}

/// The common type of two operands, if they can meet.
fn unify(a: &Ty, b: &Ty) -> Option<Ty> {
    use Ty::*;
    Some(match (a, b) {
        (Err, _) | (_, Err) => Err,
        // Two typed operands meet only when their types are equal (the last
        // arm says `None` otherwise).
        (Known(x), Known(y)) if x == y => Known(x.clone()),
        (IntLit, Known(t @ (Type::Int(_) | Type::Float(_))))
        | (Known(t @ (Type::Int(_) | Type::Float(_))), IntLit) => Known(t.clone()),
        (FloatLit, Known(t @ Type::Float(_))) | (Known(t @ Type::Float(_)), FloatLit) => {
            Known(t.clone())
        }
        (IntLit, IntLit) => IntLit,
        (IntLit | FloatLit, IntLit | FloatLit) => FloatLit,
        _ => return None,
    })
}

/// Whether `new_command` is a top-level conjunct of a condition.
pub fn has_new_command_conjunct(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::NewCommand => true,
        ExprKind::Binary(BinOp::And, l, r) => {
            has_new_command_conjunct(l) || has_new_command_conjunct(r)
        }
        _ => false,
    }
}

/// A type as the user writes it.
pub fn type_name(ir: &Ir, t: &Type) -> String {
    match t {
        Type::Bool => "bool".to_string(),
        Type::Int(i) => i.name().to_string(),
        Type::Float(f) => f.name().to_string(),
        Type::Enum(e) => ir.enums[e.index()].name.clone(),
        Type::Buffer(b) => ir.buffer_types[b.index()].name.clone(),
        Type::Array(e, n) => format!("[{}; {n}]", type_name(ir, e)),
        Type::Status(c) => format!("status of {}", ir.controllers[c.index()].name),
        Type::Unit => "()".to_string(),
    }
}
