//! Stage 2, the expression checker: what names, paths, calls, buffer
//! fields and subordinate properties stand for, with constant indices
//! checked against array lengths and run-time indices of integer type.

use super::*;
use crate::ast;
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::*;
use crate::source::Span;

impl Cx<'_, '_> {
    /// An array index: an integer literal or constant expression stays a
    /// constant (checked against the array's length at compile time);
    /// anything else is a run-time value of an integer type.
    pub(in crate::lower) fn index(&mut self, idx: &ast::Expr) -> Option<Subscript> {
        match &idx.kind {
            ast::ExprKind::Int(n) => Some(Subscript::Const(*n)),
            ast::ExprKind::Paren(inner) => self.index(inner),
            _ => {
                let (mut x, t) = self.infer(idx, None);
                match self.settle(&mut x, &t) {
                    // A constant expression (`AXES - 1`) is a constant index.
                    Ty::Known(Type::Int(_)) => match crate::analysis::eval::eval(&x, &|_| None) {
                        Some(crate::interp::Value::Int(n)) if n >= 0 => {
                            Some(Subscript::Const(u64::try_from(n).unwrap_or(u64::MAX)))
                        }
                        Some(crate::interp::Value::Int(n)) => {
                            self.mismatch(
                                idx.span,
                                format!("index {n} is negative"),
                                "indices start at 0".to_string(),
                            );
                            None
                        }
                        _ => Some(Subscript::Value(x)),
                    },
                    Ty::Err => None,
                    t => {
                        let t = self.ty_name(&t);
                        self.mismatch(
                            idx.span,
                            format!("an array index must be an integer, not {t}"),
                            "not an integer".to_string(),
                        );
                        self.help_last("convert it with `as i64` (or another integer type)");
                        None
                    }
                }
            }
        }
    }

    pub(in crate::lower) fn path(
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
                    match self.ix.variants[eid.index()].get(&name.text) {
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
                                ))
                                .suggest(&name.text, en.variants.iter().map(|v| v.name.as_str())),
                            );
                            (err_expr(span), Ty::Err)
                        }
                    }
                }
                Some((ItemRef::Controller(cid), _)) => {
                    let ctrl = &self.ir.controllers[cid.index()];
                    match self.ix.controllers[cid.index()].statuses.get(&name.text) {
                        Some(si) => (
                            mk(ExprKind::Status(StatusId(si as u32)), Type::Status(*cid)),
                            Ty::Known(Type::Status(*cid)),
                        ),
                        None => {
                            self.diags.push(
                                Diagnostic::error(
                                    Code::UnknownName,
                                    format!(
                                        "controller `{}` has no status `{}`",
                                        ctrl.name, name.text
                                    ),
                                    name.span,
                                    "no such status",
                                )
                                .suggest(&name.text, ctrl.statuses.iter().map(|s| s.name.as_str())),
                            );
                            (err_expr(span), Ty::Err)
                        }
                    }
                }
                _ => {
                    self.diags.push(
                        Diagnostic::error(
                            Code::UnknownName,
                            format!("unknown enum `{}`", q.text),
                            q.span,
                            "not an enum or controller",
                        )
                        .suggest(&q.text, self.g.names.keys().copied()),
                    );
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
        if let Some(c) = self.g.consts_table.get(Some(self.ctrl.index()), &name.text) {
            return self.constant(c, span);
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
                if let Some(si) = self.ix.controllers[cid.index()].statuses.get(&name.text) {
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
                    ))
                    .suggest(&name.text, ctrl.statuses.iter().map(|s| s.name.as_str())),
                );
                return (err_expr(span), Ty::Err);
            }
            Some(Type::ErrorCode(cid)) => return self.error_name(*cid, name, span),
            _ => {}
        }
        let owners = crate::lower::consts::variant_owners(
            self.ir
                .enums
                .iter()
                .map(|en| en.variants.iter().map(|v| v.name.as_str())),
            &name.text,
        );
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
                        d = d
                            .with_help(
                                "declare it as a `var`, a `reads`/`writes` buffer, or an enum variant",
                            )
                            .suggest(
                                &name.text,
                                self.names()
                                    .values
                                    .keys()
                                    .map(String::as_str)
                                    .chain(self.g.consts_table.names(Some(self.ctrl.index())))
                                    .chain(self.ir.enums.iter().flat_map(|en| {
                                        en.variants.iter().map(|v| v.name.as_str())
                                    })),
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

    pub(in crate::lower) fn call(
        &mut self,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
    ) -> (Expr, Ty) {
        if self.const_ctx {
            return self.not_const(span, "a hook call");
        }
        if self.accept_ctx {
            return self.not_in_accept(
                span,
                "a hook call",
                "the condition decides whether a command is taken and must not act on the world; call the hook in `pre` into a var (`pre { ready = drive_ready() }`) and write `accept when ready`",
            );
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
                    .with_help(match (super::super::time::timer_spelling(&name.text), crate::builtin::closest(&name.text)) {
                        (Some(help), _) => help,
                        (None, Some(b)) => format!(
                            "did you mean the built-in function `{}`? Else declare a hook: `hook {}(…) -> T`",
                            b.name(),
                            name.text
                        ),
                        (None, None) => format!("declare it: `hook {}(…) -> T`", name.text),
                    })
                    .suggest(
                        &name.text,
                        self.names().values.iter().filter_map(|(k, v)| {
                            matches!(v, Value::Hook(_)).then_some(k.as_str())
                        }),
                    ),
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

    pub(in crate::lower) fn field(
        &mut self,
        base: &ast::Expr,
        field: &ast::Name,
        span: Span,
    ) -> (Expr, Ty) {
        if field.text == "stale_time" {
            let whole = ast::Expr {
                kind: ast::ExprKind::Field(Box::new(base.clone()), field.clone()),
                span,
            };
            return self.time_out_of_place(&whole);
        }
        if let Some(watchdog) = self.buffer_watchdog(base, field, span) {
            return watchdog;
        }
        // `X.prop` on a controller name: the handshake view of a subordinate.
        if let ast::ExprKind::Path(None, x) = &base.kind {
            if self.value(&x.text).is_none() || matches!(self.value(&x.text), Some(Value::Sub)) {
                if let Some((ItemRef::Controller(cid), _)) = self.g.names.get(x.text.as_str()) {
                    return self.sub_prop(*cid, x, field, span);
                }
                let sub_prop = ["status", "done", "executing", "error", "stale_cycles"];
                if field.text == "stale_cycles" && self.value(&x.text).is_none() {
                    if let Some(d) = super::super::time::unread_buffer(self, x) {
                        self.diags.push(d);
                        return (err_expr(span), Ty::Err);
                    }
                }
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
                        ))
                        .suggest(
                            &x.text,
                            self.subordinate_names(),
                        ),
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
                match self.ix.fields[bid.index()].get(&field.text) {
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
                            .with_secondary(bty.name_span, format!("`{}` declared here", bty.name))
                            .suggest(&field.text, bty.fields.iter().map(|f| f.name.as_str())),
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

    pub(in crate::lower) fn sub_prop(
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
                .suggest(&x.text, self.subordinate_names())
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
            "error_code" => (SubProp::ErrorCode, Type::ErrorCode(cid)),
            other => {
                if let Some(read) = self.sub_field(cid, span, other) {
                    return read;
                }
                let help = self.sub_offers(cid, other);
                self.diags.push(
                    Diagnostic::error(
                        Code::UnknownName,
                        format!("subordinate `{}` has no property `{other}`", x.text),
                        field.span,
                        "unknown property",
                    )
                    .with_help(help),
                );
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
}

impl Cx<'_, '_> {
    /// A bare error name where an error code of controller `cid` is
    /// expected (beside `X.error_code`, assigned to a var of type `error`):
    /// one `cid` declares, or a built-in one it can have.
    fn error_name(&mut self, cid: CtrlId, name: &ast::Name, span: Span) -> (Expr, Ty) {
        let ctrl = &self.ir.controllers[cid.index()];
        let refuses = ctrl.can_refuse();
        let code = crate::error_codes::code_of(ctrl, &name.text)
            .filter(|c| *c != rcs_runtime::ErrorCode::REFUSED || refuses);
        if let Some(code) = code {
            let ty = Type::ErrorCode(cid);
            return (
                Expr {
                    kind: ExprKind::ErrorCode(code.0),
                    ty: ty.clone(),
                    span,
                },
                Ty::Known(ty),
            );
        }
        let codes: Vec<&str> = crate::error_codes::BUILTIN
            .iter()
            .map(|(n, _)| *n)
            .filter(|n| *n != "REFUSED" || refuses)
            .chain(ctrl.errors.iter().map(|e| e.name.as_str()))
            .collect();
        let help = if name.text == "REFUSED" {
            format!(
                "`{}` refuses no command: REFUSED comes only from a verb declared with `accept when`; its codes are {}",
                ctrl.name,
                codes.join(", ")
            )
        } else {
            format!(
                "the error codes of `{}` are: {}",
                ctrl.name,
                codes.join(", ")
            )
        };
        self.diags.push(
            Diagnostic::error(
                Code::UnknownName,
                format!(
                    "controller `{}` has no error code `{}`",
                    ctrl.name, name.text
                ),
                name.span,
                "no such error code",
            )
            .with_help(help)
            .suggest(&name.text, codes.iter().copied()),
        );
        (err_expr(span), Ty::Err)
    }
}
