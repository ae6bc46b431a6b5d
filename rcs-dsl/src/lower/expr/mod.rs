//! Stage 2, second half: the expression type checker, over the checking
//! context of one controller ([`Cx`]). Types flow both ways: an expected
//! type (from an assignment target, a parameter or the other operand) fixes
//! integer and float literals and resolves bare enum variants and statuses.
//! Names, paths and calls are in [`names`], operators in [`operators`]; the
//! declarations and plans that use the checker are in `lower::declarations`
//! and `lower::plans`.

mod builtins;
mod names;
mod operators;

use super::index::{ControllerNames, Index};

use super::{primitive, Globals, ItemRef};
use crate::ast::{self, BinOp, UnOp};
use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use crate::ir::*;
use crate::source::Span;

/// A type during checking: literals stay flexible until something fixes them.
#[derive(Clone, Debug, PartialEq)]
pub(in crate::lower) enum Ty {
    Known(Type),
    IntLit,
    FloatLit,
    /// Already reported: fits everywhere and reports nothing more.
    Err,
}

/// What a bare name in a controller stands for.
#[derive(Clone, Copy, Debug)]
pub(in crate::lower) enum Value {
    Var(VarId),
    Buffer(BufferId, bool),
    Hook(HookId),
    Sub,
}

/// The checking context of one controller (and, inside a plan, its verb).
pub(in crate::lower) struct Cx<'a, 'g> {
    pub(in crate::lower) g: &'a Globals<'g>,
    pub(in crate::lower) ir: &'a Ir,
    pub(in crate::lower) ctrl: CtrlId,
    /// Every declared name, indexed.
    pub(in crate::lower) ix: &'a Index,
    pub(in crate::lower) c: &'a Controller,
    pub(in crate::lower) plan_cmd: Option<CommandId>,
    /// In a var initialiser: only constants are allowed.
    pub(in crate::lower) const_ctx: bool,
    /// Hooks whose return type did not resolve: their calls fit everywhere.
    pub(in crate::lower) unresolved_hooks: Vec<String>,
    pub(in crate::lower) diags: &'a mut Diagnostics,
    /// Inside a plan: all its verbs (`plan A | B`), for `X <- cmd`.
    pub(in crate::lower) plan_verbs: Vec<CommandId>,
    /// In an `accept when` condition: no hook calls, no plan quantities.
    pub(in crate::lower) accept_ctx: bool,
    /// The CPU period, and the comparisons of times with durations lowered.
    pub(in crate::lower) time: super::time::TimeCx,
}

/// A lowered array index.
pub(in crate::lower) enum Subscript {
    /// An integer literal, checked against the array's length.
    Const(u64),
    /// A run-time integer value.
    Value(Expr),
}

pub(in crate::lower) fn err_expr(span: Span) -> Expr {
    Expr {
        kind: ExprKind::Bool(false),
        ty: Type::Bool,
        span,
    }
}

impl Cx<'_, '_> {
    /// `what` written in an `accept when` condition, which may not have it.
    pub(in crate::lower) fn not_in_accept(
        &mut self,
        span: Span,
        what: &str,
        help: &str,
    ) -> (Expr, Ty) {
        self.diags.push(
            Diagnostic::error(
                Code::AcceptCondition,
                format!("{what} in an `accept when` condition"),
                span,
                "not allowed in `accept when`",
            )
            .with_help(help.to_string()),
        );
        (err_expr(span), Ty::Err)
    }

    pub(in crate::lower) fn type_name(&self, t: &Type) -> String {
        type_name(self.ir, t)
    }

    pub(in crate::lower) fn ty_name(&self, t: &Ty) -> String {
        match t {
            Ty::Known(t) => format!("`{}`", self.type_name(t)),
            Ty::IntLit => "an integer literal".to_string(),
            Ty::FloatLit => "a float literal".to_string(),
            Ty::Err => "an unknown type".to_string(),
        }
    }

    pub(in crate::lower) fn mismatch(&mut self, span: Span, message: String, label: String) {
        self.diags
            .push(Diagnostic::error(Code::TypeMismatch, message, span, label));
    }

    pub(in crate::lower) fn value(&self, name: &str) -> Option<Value> {
        self.names().values.get(name).copied()
    }

    /// The names of this controller's subordinates (for "did you mean").
    pub(in crate::lower) fn subordinate_names(&self) -> impl Iterator<Item = &str> {
        let ir = self.ir;
        self.c
            .subordinates
            .iter()
            .map(move |s| ir.controllers[s.index()].name.as_str())
    }

    /// This controller's names, indexed.
    pub(in crate::lower) fn names(&self) -> &ControllerNames {
        &self.ix.controllers[self.ctrl.index()]
    }

    pub(in crate::lower) fn not_const(&mut self, span: Span, what: &str) -> (Expr, Ty) {
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
    pub(in crate::lower) fn help_last(&mut self, help: &str) {
        if let Some(d) = self.diags.last_mut() {
            d.help = Some(help.to_string());
        }
    }

    // ------------------------------------------------------------ types

    /// Check `e` against an expected type.
    pub(in crate::lower) fn check(&mut self, e: &ast::Expr, expected: &Type) -> Expr {
        let (mut ir, ty) = self.infer(e, Some(expected));
        self.expect(&mut ir, ty, expected, e.span);
        ir
    }

    /// Make an inferred expression have type `expected`, or report.
    pub(in crate::lower) fn expect(&mut self, ir: &mut Expr, ty: Ty, expected: &Type, span: Span) {
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
    pub(in crate::lower) fn fix_literals(&mut self, e: &mut Expr, ty: &Type) {
        let literal = match &e.kind {
            ExprKind::Int(_) | ExprKind::Float(_) => true,
            ExprKind::Unary(UnOp::Neg, _) | ExprKind::Binary(..) => e.ty != *ty,
            // `!0x0F` beside an integer: bitwise not, typed by its context.
            ExprKind::Unary(UnOp::Not, _) => e.ty != *ty && matches!(e.ty, Type::Int(_)),
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
            (ExprKind::Unary(UnOp::Neg | UnOp::Not, inner), _) => self.fix_literals(inner, ty),
            (ExprKind::Binary(op, operands), _) if is_arith(*op) || is_bit_logic(*op) => {
                let [l, r] = &mut **operands;
                self.fix_literals(l, ty);
                self.fix_literals(r, ty);
            }
            // A shift takes the type of its left side; its amount keeps its own.
            (ExprKind::Binary(BinOp::Shl | BinOp::Shr, operands), _) => {
                let [l, _] = &mut **operands;
                self.fix_literals(l, ty);
            }
            _ => {}
        }
        if matches!(
            e.kind,
            ExprKind::Int(_) | ExprKind::Float(_) | ExprKind::Unary(..)
        ) || matches!(&e.kind, ExprKind::Binary(op, ..) if is_arith(*op) || op.is_bitwise())
        {
            e.ty = ty.clone();
        }
    }

    /// Give a still-flexible root its default type (`i64` / `f64`).
    pub(in crate::lower) fn settle(&mut self, e: &mut Expr, ty: &Ty) -> Ty {
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

    pub(in crate::lower) fn infer(&mut self, e: &ast::Expr, hint: Option<&Type>) -> (Expr, Ty) {
        let span = e.span;
        let mk = |kind: ExprKind, ty: Type| Expr { kind, ty, span };
        match &e.kind {
            ast::ExprKind::Paren(inner) => self.infer(inner, hint),
            ast::ExprKind::Duration(_) | ast::ExprKind::StateTime | ast::ExprKind::PlanTime => {
                self.time_out_of_place(e)
            }
            ast::ExprKind::Path(None, n) if self.duration_const(&n.text).is_some() => {
                self.time_out_of_place(e)
            }
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
                if self.accept_ctx {
                    return self.not_in_accept(
                        span,
                        "a plan quantity",
                        "the condition is judged before the command replaces the running plan, so `new_command`, `state_cycles` and `plan_cycles` would be the arriving command's; keep what the condition needs in a var of the running plan (`var may_hold: bool`, set in its rows) and write `accept when may_hold`",
                    );
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
                    if !self.const_ctx {
                        return self.current_param(span, &p.text);
                    }
                    return self.not_const(span, "a command parameter");
                };
                let command = &self.c.commands[cmd.index()];
                match self.names().params[cmd.index()].get(&p.text) {
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
                            .with_help(have)
                            .suggest(&p.text, command.params.iter().map(|p| p.name.as_str())),
                        );
                        (err_expr(span), Ty::Err)
                    }
                }
            }
            ast::ExprKind::Path(qual, name) => self.path(qual.as_deref(), name, hint, span),
            ast::ExprKind::Call(name, args) => match crate::builtin::Builtin::from_name(&name.text)
            {
                Some(b) => self.builtin(b, args, hint, span),
                None => self.call(name, args, span),
            },
            ast::ExprKind::Field(base, field) => self.field(base, field, span),
            ast::ExprKind::Index(base, idx) => {
                let (b, bt) = self.infer(base, None);
                // A subscript that did not check is already reported.
                let Some(sub) = self.index(idx) else {
                    return (err_expr(span), Ty::Err);
                };
                let (elem, len) = match bt {
                    Ty::Known(Type::Array(elem, len)) => (elem, len),
                    Ty::Err => return (err_expr(span), Ty::Err),
                    t => {
                        let t = self.ty_name(&t);
                        self.mismatch(
                            base.span,
                            format!("cannot index into {t}"),
                            "not an array".to_string(),
                        );
                        return (err_expr(span), Ty::Err);
                    }
                };
                let kind = match sub {
                    Subscript::Value(i) => ExprKind::IndexBy(Box::new(b), Box::new(i)),
                    Subscript::Const(n) if n >= len as u64 => {
                        self.mismatch(
                            idx.span,
                            format!("index {n} is out of bounds for an array of length {len}"),
                            format!("valid indices are 0 to {}", len - 1),
                        );
                        return (err_expr(span), Ty::Err);
                    }
                    Subscript::Const(n) => ExprKind::Index(Box::new(b), n as u32),
                };
                (mk(kind, (*elem).clone()), Ty::Known(*elem))
            }
            ast::ExprKind::Unary(op, inner) => self.unary(*op, inner, span),
            ast::ExprKind::Binary(op, operands) => {
                let [l, r] = &**operands;
                self.binary(*op, l, r, span)
            }
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
}

pub(in crate::lower) fn known(t: &Ty) -> Option<Type> {
    match t {
        Ty::Known(t) => Some(t.clone()),
        _ => None,
    }
}

/// `&`, `|`, `^`: both operands and the result of one integer type.
pub(in crate::lower) fn is_bit_logic(op: BinOp) -> bool {
    matches!(op, BinOp::BitAnd | BinOp::BitOr | BinOp::BitXor)
}

pub(in crate::lower) fn is_arith(op: BinOp) -> bool {
    matches!(
        op,
        BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div | BinOp::Rem
    )
}

/// The common type of two operands, if they can meet.
pub(in crate::lower) fn unify(a: &Ty, b: &Ty) -> Option<Ty> {
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
        Type::ErrorCode(c) => format!("error code of {}", ir.controllers[c.index()].name),
        Type::Unit => "()".to_string(),
    }
}
