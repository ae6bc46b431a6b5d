//! Stage 2, first: constants. Every `const NAME: TYPE = EXPR` (file and
//! controller level) is folded to its value here, before buffer types and
//! controllers are lowered, so that array lengths can use them and every
//! later stage sees a constant as the literal it stands for (`lower::expr`
//! substitutes the value: the IR has no constants, and each backend and
//! the analysis treat them exactly as literals).
//!
//! Folding follows the language's arithmetic ([`crate::arith`],
//! [`crate::builtin`]) exactly as a run-time evaluation would: integer
//! literals take the type their context fixes and the arithmetic wraps in
//! that type. Names in a constant expression are other constants (of the
//! controller, then of the file; a file-level constant sees only file-level
//! ones), enum variants and built-in functions; constants may be declared
//! in any order, and a cycle among them is an error (`const_cycle`).

use super::Globals;
use crate::arith;
use crate::ast::{self, BinOp, UnOp};
use crate::builtin::{apply, Builtin, Signature};
use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use crate::ir::{EnumId, FloatTy, IntTy, Type};
use crate::source::Span;
use rcs_runtime::driver::Value;
use std::collections::BTreeMap;

/// A folded constant.
#[derive(Clone, Debug)]
pub(crate) struct Const {
    pub ty: Type,
    pub value: Value,
}

/// Every constant's value: file level, and per controller (in `Globals`
/// order). A constant whose definition has an error has type `()`.
#[derive(Default)]
pub(crate) struct ConstTable {
    file: BTreeMap<String, Const>,
    ctrl: Vec<BTreeMap<String, Const>>,
}

impl ConstTable {
    /// The constant `name` as seen from controller `ctrl` (its own first,
    /// then the file's) or from file level (`None`).
    pub fn get(&self, ctrl: Option<usize>, name: &str) -> Option<&Const> {
        ctrl.and_then(|c| self.ctrl.get(c))
            .and_then(|m| m.get(name))
            .or_else(|| self.file.get(name))
    }

    /// Whether a file-level constant has this name.
    pub fn is_file_const(&self, name: &str) -> bool {
        self.file.contains_key(name)
    }
}

/// A constant's scope: file level (`None`) or a controller.
type Scope = Option<usize>;

/// A value being folded: typed, or a literal still waiting for its type.
#[derive(Clone, Debug)]
enum Ty {
    Known(Type),
    IntLit,
    FloatLit,
}

struct Folded {
    value: Value,
    ty: Ty,
}

/// Fold every constant of the plan set.
pub(super) fn fold_all(g: &Globals, diags: &mut Diagnostics) -> ConstTable {
    let mut defs: BTreeMap<(Scope, String), &ast::ConstDef> = BTreeMap::new();
    for c in &g.consts {
        defs.entry((None, c.name.text.to_string())).or_insert(c);
    }
    for (i, ctrl) in g.controllers.iter().enumerate() {
        for e in &ctrl.entries {
            if let ast::EntryKind::Const(c) = &e.kind {
                defs.entry((Some(i), c.name.text.to_string())).or_insert(c);
            }
        }
    }
    let mut f = Folder {
        g,
        defs,
        table: ConstTable {
            file: BTreeMap::new(),
            ctrl: vec![BTreeMap::new(); g.controllers.len()],
        },
        done: BTreeMap::new(),
        busy: Vec::new(),
        diags,
    };
    let keys: Vec<(Scope, String)> = f.defs.keys().cloned().collect();
    for k in keys {
        f.constant(&k);
    }
    f.table
}

/// An array length written as a constant expression: an integer from 1 to
/// 65536, or `None` after a diagnostic.
pub(super) fn array_len(
    g: &Globals,
    scope: Option<usize>,
    e: &ast::Expr,
    diags: &mut Diagnostics,
) -> Option<u64> {
    let mut f = Folder {
        g,
        defs: BTreeMap::new(),
        table: ConstTable::default(),
        done: BTreeMap::new(),
        busy: Vec::new(),
        diags,
    };
    let v = f.settled(scope, e, None)?;
    match (v.value, v.ty) {
        (Value::Int(n), _) if (1..=65_536).contains(&n) => Some(n as u64),
        (Value::Int(n), _) => {
            f.diags.push(
                Diagnostic::error(
                    Code::TypeMismatch,
                    format!("array length {n} is out of range"),
                    e.span,
                    "length must be 1 to 65536",
                )
                .with_help("Global Memory buffers are fixed-size plain data"),
            );
            None
        }
        (_, ty) => {
            let found = f.ty_name(&ty);
            f.diags.push(Diagnostic::error(
                Code::TypeMismatch,
                format!("an array length must be an integer, found {found}"),
                e.span,
                "not an integer",
            ));
            None
        }
    }
}

struct Folder<'a, 'g> {
    g: &'a Globals<'g>,
    /// Definitions not folded yet (empty when folding an array length:
    /// every constant is in `g.consts_table` by then).
    defs: BTreeMap<(Scope, String), &'g ast::ConstDef>,
    table: ConstTable,
    /// Folded definitions: `false` for those with an error.
    done: BTreeMap<(Scope, String), bool>,
    /// The constants being folded, outermost first (to report cycles).
    busy: Vec<(Scope, String)>,
    diags: &'a mut Diagnostics,
}

impl Folder<'_, '_> {
    fn lookup(&self, key: &(Scope, String)) -> Option<&Const> {
        let own = match key.0 {
            Some(c) => self.table.ctrl.get(c).and_then(|m| m.get(&key.1)),
            None => self.table.file.get(&key.1),
        };
        own.or_else(|| self.g.consts_table.get(key.0, &key.1))
    }

    /// Fold the definition `key`; `false` if it has an error.
    fn constant(&mut self, key: &(Scope, String)) -> bool {
        if let Some(ok) = self.done.get(key) {
            return *ok;
        }
        let Some(def) = self.defs.get(key).copied() else {
            return self.lookup(key).is_some_and(|c| c.ty != Type::Unit);
        };
        self.busy.push(key.clone());
        let ok = self.define(key.0, def);
        self.busy.pop();
        self.done.insert(key.clone(), ok.is_some());
        // A constant with an error stays declared, typed `()`, so that its
        // uses report nothing more.
        let c = ok.unwrap_or(Const {
            ty: Type::Unit,
            value: Value::Unit,
        });
        match key.0 {
            Some(i) => self.table.ctrl[i].insert(key.1.clone(), c),
            None => self.table.file.insert(key.1.clone(), c),
        };
        self.done[key]
    }

    fn define(&mut self, scope: Scope, def: &ast::ConstDef) -> Option<Const> {
        let ty = self.const_type(&def.ty)?;
        let v = self.settled(scope, &def.value, Some(&ty))?;
        let Ty::Known(found) = &v.ty else {
            return None;
        };
        if *found != ty {
            let (want, found) = (self.type_name(&ty), self.type_name(found));
            self.diags.push(Diagnostic::error(
                Code::TypeMismatch,
                format!("expected `{want}`, found `{found}`"),
                def.value.span,
                format!("expected `{want}`"),
            ));
            return None;
        }
        if let Value::Float(f) = v.value {
            if !f.is_finite() {
                self.diags.push(
                    Diagnostic::error(
                        Code::NotConstant,
                        format!(
                            "constant `{}` is {}",
                            def.name.text,
                            crate::pretty::float(f)
                        ),
                        def.value.span,
                        "not a finite number",
                    )
                    .with_help(
                        "a constant must be a finite number; compute NaN or infinity at run time",
                    ),
                );
                return None;
            }
        }
        Some(Const { ty, value: v.value })
    }

    /// The declared type of a constant: `bool`, a number or an enum.
    fn const_type(&mut self, t: &ast::TypeExpr) -> Option<Type> {
        let ty = super::resolve_type(self.g, t, self.diags)?;
        if matches!(
            ty,
            Type::Bool | Type::Int(_) | Type::Float(_) | Type::Enum(_)
        ) {
            return Some(ty);
        }
        self.diags.push(
            Diagnostic::error(
                Code::TypeMismatch,
                format!("a constant cannot have type `{}`", self.type_name(&ty)),
                t.span(),
                "not a constant type",
            )
            .with_help("constants are `bool`, numbers or enums"),
        );
        None
    }

    fn type_name(&self, t: &Type) -> String {
        match t {
            Type::Enum(e) => self.g.enums[e.index()].name.text.to_string(),
            Type::Bool => "bool".to_string(),
            Type::Int(i) => i.name().to_string(),
            Type::Float(f) => f.name().to_string(),
            _ => "a non-constant type".to_string(),
        }
    }

    fn ty_name(&self, t: &Ty) -> String {
        match t {
            Ty::Known(t) => format!("`{}`", self.type_name(t)),
            Ty::IntLit => "an integer literal".to_string(),
            Ty::FloatLit => "a float literal".to_string(),
        }
    }

    fn not_constant(&mut self, span: Span, what: &str) -> Option<Folded> {
        self.diags.push(
            Diagnostic::error(
                Code::NotConstant,
                format!("{what} is not a constant"),
                span,
                "not a constant",
            )
            .with_help("a constant expression uses literals, other constants, enum variants, operators, `as` and built-in functions"),
        );
        None
    }

    fn mismatch(&mut self, span: Span, message: String, label: &str) -> Option<Folded> {
        self.diags
            .push(Diagnostic::error(Code::TypeMismatch, message, span, label));
        None
    }

    /// Fold `e`; a literal-only result gets the hint's type if numeric,
    /// else the default (`i64`, `f64`).
    fn settled(&mut self, scope: Scope, e: &ast::Expr, hint: Option<&Type>) -> Option<Folded> {
        let v = self.fold(scope, e, hint)?;
        match v.ty {
            Ty::Known(_) => Some(v),
            Ty::IntLit => self.fold(scope, e, Some(&Type::Int(IntTy::I64))),
            Ty::FloatLit => self.fold(scope, e, Some(&Type::Float(FloatTy::F64))),
        }
    }

    /// Fold operands that must share one type: literals take the type of a
    /// typed operand, else the hint.
    fn operands(
        &mut self,
        scope: Scope,
        es: &[&ast::Expr],
        hint: Option<&Type>,
    ) -> Option<Vec<Folded>> {
        let mut out = Vec::new();
        for e in es {
            out.push(self.fold(scope, e, hint)?);
        }
        let typed = out.iter().find_map(|v| match &v.ty {
            Ty::Known(t) => Some(t.clone()),
            _ => None,
        });
        if let Some(t) = typed {
            for (i, e) in es.iter().enumerate() {
                if !matches!(out[i].ty, Ty::Known(_)) {
                    out[i] = self.fold(scope, e, Some(&t))?;
                }
            }
        }
        Some(out)
    }

    fn fold(&mut self, scope: Scope, e: &ast::Expr, hint: Option<&Type>) -> Option<Folded> {
        let known = |value: Value, t: Type| Folded {
            value,
            ty: Ty::Known(t),
        };
        match &e.kind {
            ast::ExprKind::Paren(x) => self.fold(scope, x, hint),
            ast::ExprKind::Int(n) => {
                let n = *n as i128;
                match hint {
                    Some(Type::Int(t)) => {
                        let (lo, hi) = t.range();
                        if n < lo || n > hi {
                            return self.mismatch(
                                e.span,
                                format!("literal `{n}` does not fit in `{}`", t.name()),
                                "out of range",
                            );
                        }
                        Some(known(Value::Int(n), Type::Int(*t)))
                    }
                    Some(Type::Float(t)) => Some(known(
                        Value::Float(arith::round(n as f64, *t)),
                        Type::Float(*t),
                    )),
                    _ => Some(Folded {
                        value: Value::Int(n),
                        ty: Ty::IntLit,
                    }),
                }
            }
            ast::ExprKind::Float(f) => match hint {
                Some(Type::Float(t)) => {
                    Some(known(Value::Float(arith::round(*f, *t)), Type::Float(*t)))
                }
                _ => Some(Folded {
                    value: Value::Float(*f),
                    ty: Ty::FloatLit,
                }),
            },
            ast::ExprKind::Bool(b) => Some(known(Value::Bool(*b), Type::Bool)),
            ast::ExprKind::NewCommand | ast::ExprKind::StateCycles | ast::ExprKind::PlanCycles => {
                self.not_constant(e.span, "a plan quantity")
            }
            ast::ExprKind::CmdParam(_) => self.not_constant(e.span, "a command parameter"),
            ast::ExprKind::Field(..) => self.not_constant(e.span, "a field"),
            ast::ExprKind::Index(..) => self.not_constant(e.span, "an array element"),
            ast::ExprKind::Path(Some(q), v) => {
                let Some((eid, en)) = self
                    .g
                    .enums
                    .iter()
                    .enumerate()
                    .find(|(_, en)| en.name.text == q.text)
                else {
                    return self.not_constant(e.span, &format!("`{}::{}`", q.text, v.text));
                };
                match en.variants.iter().position(|(_, n)| n.text == v.text) {
                    Some(vi) => Some(known(
                        Value::Enum(vi as u32),
                        Type::Enum(EnumId(eid as u32)),
                    )),
                    None => {
                        let all: Vec<&str> =
                            en.variants.iter().map(|(_, n)| n.text.as_str()).collect();
                        let d = Diagnostic::error(
                            Code::UnknownName,
                            format!("enum `{}` has no variant `{}`", q.text, v.text),
                            v.span,
                            "no such variant",
                        );
                        self.diags
                            .push(d.with_help(format!("the variants are: {}", all.join(", "))));
                        None
                    }
                }
            }
            ast::ExprKind::Path(None, n) => self.name(scope, n, hint),
            ast::ExprKind::Call(name, args) => match Builtin::from_name(&name.text) {
                Some(b) => self.builtin(scope, b, args, hint, e.span),
                None => self.not_constant(e.span, &format!("a call of `{}`", name.text)),
            },
            ast::ExprKind::Unary(op, x) => {
                let v = self.fold(scope, x, hint)?;
                match (op, &v.ty, v.value) {
                    (UnOp::Not, Ty::Known(Type::Bool), Value::Bool(b)) => {
                        Some(known(Value::Bool(!b), Type::Bool))
                    }
                    (UnOp::Neg, Ty::Known(t @ (Type::Int(_) | Type::Float(_))), value) if !matches!(t, Type::Int(i) if !i.signed()) => {
                        Some(known(arith::unary(UnOp::Neg, value, t), t.clone()))
                    }
                    (UnOp::Neg, Ty::IntLit, Value::Int(i)) => Some(Folded {
                        value: Value::Int(-i),
                        ty: Ty::IntLit,
                    }),
                    (UnOp::Neg, Ty::FloatLit, Value::Float(f)) => Some(Folded {
                        value: Value::Float(-f),
                        ty: Ty::FloatLit,
                    }),
                    (_, ty, _) => {
                        let found = self.ty_name(ty);
                        let op = if *op == UnOp::Not { "!" } else { "-" };
                        self.mismatch(
                            x.span,
                            format!("`{op}` cannot be applied to {found}"),
                            "wrong operand type",
                        )
                    }
                }
            }
            ast::ExprKind::Cast(x, to) => {
                let target = match super::primitive(&to.text) {
                    Some(t @ (Type::Int(_) | Type::Float(_))) => t,
                    _ => {
                        return self.mismatch(
                            to.span,
                            format!("cannot cast to `{}`", to.text),
                            "`as` converts between numeric types only",
                        )
                    }
                };
                let v = self.settled(scope, x, None)?;
                match v.ty {
                    Ty::Known(Type::Int(_) | Type::Float(_)) => {
                        Some(known(arith::cast(v.value, &target), target))
                    }
                    ty => {
                        let found = self.ty_name(&ty);
                        self.mismatch(x.span, format!("cannot cast {found}"), "not a number")
                    }
                }
            }
            ast::ExprKind::Binary(op, l, r) => self.binary(scope, *op, l, r, hint, e.span),
        }
    }

    fn name(&mut self, scope: Scope, n: &ast::Name, hint: Option<&Type>) -> Option<Folded> {
        let mut key = (scope, n.text.to_string());
        if scope.is_some() && !self.has(&key) {
            key.0 = None;
        }
        if self.has(&key) {
            if let Some(at) = self.busy.iter().position(|b| *b == key) {
                let chain: Vec<&str> = self.busy[at..]
                    .iter()
                    .map(|(_, n)| n.as_str())
                    .chain(std::iter::once(n.text.as_str()))
                    .collect();
                self.diags.push(
                    Diagnostic::error(
                        Code::ConstCycle,
                        format!("constant `{}` is defined in terms of itself", n.text),
                        n.span,
                        "used in its own definition",
                    )
                    .with_help(format!(
                        "the cycle is {}; give one of them a literal value",
                        chain.join(" → ")
                    )),
                );
                return None;
            }
            if !self.constant(&key) {
                return None; // its definition has an error, already reported
            }
            let c = self.lookup(&key)?.clone();
            return Some(Folded {
                value: c.value,
                ty: Ty::Known(c.ty),
            });
        }
        if Builtin::from_name(&n.text).is_some() {
            return self.mismatch(
                n.span,
                format!("built-in function `{}` must be called", n.text),
                "a function, not a value",
            );
        }
        // A bare enum variant: the hint's enum first, else the only enum
        // that has it.
        let owners = variant_owners(
            self.g
                .enums
                .iter()
                .map(|en| en.variants.iter().map(|(_, v)| v.text.as_str())),
            &n.text,
        );
        let pick = match hint {
            Some(Type::Enum(h)) => owners.iter().find(|(ei, _)| *ei == h.index()),
            _ => None,
        }
        .or(if owners.len() == 1 {
            owners.first()
        } else {
            None
        });
        if let Some(&(ei, vi)) = pick {
            return Some(Folded {
                value: Value::Enum(vi as u32),
                ty: Ty::Known(Type::Enum(EnumId(ei as u32))),
            });
        }
        let declared_here = scope.is_some_and(|c| {
            self.g.controllers[c].entries.iter().any(|e| match &e.kind {
                ast::EntryKind::Var { name, .. } | ast::EntryKind::Hook { name, .. } => {
                    name.text == n.text
                }
                ast::EntryKind::Reads(name, _) | ast::EntryKind::Writes(name, _) => {
                    name.text == n.text
                }
                _ => false,
            })
        });
        if declared_here {
            return self.not_constant(n.span, &format!("`{}`", n.text));
        }
        self.diags.push(
            Diagnostic::error(
                Code::UnknownName,
                format!("cannot find constant `{}`", n.text),
                n.span,
                "not declared",
            )
            .with_help(if scope.is_none() {
                "a file-level constant may use file-level constants, enum variants and built-in functions"
            } else {
                "declare it with `const NAME: TYPE = VALUE`"
            }),
        );
        None
    }

    /// Whether `key` names a constant (folded or still to fold).
    fn has(&self, key: &(Scope, String)) -> bool {
        self.defs.contains_key(key)
            || match key.0 {
                Some(c) => self
                    .g
                    .consts_table
                    .ctrl
                    .get(c)
                    .is_some_and(|m| m.contains_key(&key.1)),
                None => self.g.consts_table.file.contains_key(&key.1),
            }
    }

    fn builtin(
        &mut self,
        scope: Scope,
        b: Builtin,
        args: &[ast::Expr],
        hint: Option<&Type>,
        span: Span,
    ) -> Option<Folded> {
        if args.len() != b.arity() {
            self.diags.push(arity(b, args.len(), span));
            return None;
        }
        let hint = match (b.signature(), hint) {
            (Signature::Numeric, Some(t @ (Type::Int(_) | Type::Float(_)))) => Some(t),
            (Signature::Float, Some(t @ Type::Float(_))) => Some(t),
            _ => None,
        };
        let refs: Vec<&ast::Expr> = args.iter().collect();
        let mut vals = self.operands(scope, &refs, hint)?;
        if !matches!(vals[0].ty, Ty::Known(_)) {
            let default = match (b.signature(), &vals[0].ty) {
                (Signature::Numeric, Ty::IntLit)
                    if vals.iter().all(|v| matches!(v.ty, Ty::IntLit)) =>
                {
                    Type::Int(IntTy::I64)
                }
                _ => Type::Float(FloatTy::F64),
            };
            vals = self.operands(scope, &refs, Some(&default))?;
        }
        let Ty::Known(t) = vals[0].ty.clone() else {
            return None;
        };
        let ok = match b.signature() {
            Signature::Numeric => matches!(t, Type::Int(_) | Type::Float(_)),
            _ => matches!(t, Type::Float(_)),
        };
        if !ok
            || vals
                .iter()
                .any(|v| !matches!(&v.ty, Ty::Known(u) if *u == t))
        {
            let found: Vec<String> = vals.iter().map(|v| self.ty_name(&v.ty)).collect();
            self.diags.push(arguments(b, &found, span));
            return None;
        }
        let values: Vec<Value> = vals.into_iter().map(|v| v.value).collect();
        let value = apply(b, &values, &t);
        let ty = if b == Builtin::IsNan { Type::Bool } else { t };
        Some(Folded {
            value,
            ty: Ty::Known(ty),
        })
    }

    fn binary(
        &mut self,
        scope: Scope,
        op: BinOp,
        l: &ast::Expr,
        r: &ast::Expr,
        hint: Option<&Type>,
        span: Span,
    ) -> Option<Folded> {
        let logic = matches!(op, BinOp::And | BinOp::Or);
        let arith_op = matches!(
            op,
            BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div | BinOp::Rem
        );
        let operand_hint = if logic {
            Some(&Type::Bool)
        } else if arith_op {
            hint.filter(|t| matches!(t, Type::Int(_) | Type::Float(_)))
        } else {
            None
        };
        let mut vals = self.operands(scope, &[l, r], operand_hint)?;
        let lit = |v: &Folded| !matches!(v.ty, Ty::Known(_));
        if lit(&vals[0]) && !arith_op {
            // A comparison of literals: settle them to the default type.
            let default = if vals.iter().any(|v| matches!(v.ty, Ty::FloatLit)) {
                Type::Float(FloatTy::F64)
            } else {
                Type::Int(IntTy::I64)
            };
            vals = self.operands(scope, &[l, r], Some(&default))?;
        }
        let (b, a) = (vals.pop()?, vals.pop()?);
        if lit(&a) || lit(&b) {
            // Literal arithmetic whose type is not fixed yet: exact for
            // now; folded again in its type once the context fixes one.
            return Some(match (a.value, b.value) {
                (Value::Int(x), Value::Int(y)) => Folded {
                    value: Value::Int(match op {
                        BinOp::Add => x.wrapping_add(y),
                        BinOp::Sub => x.wrapping_sub(y),
                        BinOp::Mul => x.wrapping_mul(y),
                        BinOp::Div => x.checked_div(y).unwrap_or(0),
                        _ => x.checked_rem(y).unwrap_or(0),
                    }),
                    ty: if matches!((a.ty, b.ty), (Ty::IntLit, Ty::IntLit)) {
                        Ty::IntLit
                    } else {
                        Ty::FloatLit
                    },
                },
                (x, _) => Folded {
                    value: x,
                    ty: Ty::FloatLit,
                },
            });
        }
        let (Ty::Known(ta), Ty::Known(tb)) = (&a.ty, &b.ty) else {
            return None;
        };
        let fits = ta == tb
            && match op {
                BinOp::And | BinOp::Or => *ta == Type::Bool,
                BinOp::Eq | BinOp::Ne => true,
                BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => {
                    matches!(ta, Type::Int(_) | Type::Float(_))
                }
                _ => matches!(ta, Type::Int(_) | Type::Float(_)),
            };
        if !fits {
            let (x, y) = (self.type_name(ta), self.type_name(tb));
            return self.mismatch(
                span,
                format!("`{}` cannot be applied to `{x}` and `{y}`", op.symbol()),
                "mismatched operands",
            );
        }
        let ty = if arith_op { ta.clone() } else { Type::Bool };
        Some(Folded {
            value: arith::binary(op, a.value, b.value, &ty),
            ty: Ty::Known(ty),
        })
    }
}

/// The enums (by index) that have a variant `name`, with its index in each.
pub(super) fn variant_owners<'a, V: Iterator<Item = &'a str>>(
    enums: impl Iterator<Item = V>,
    name: &str,
) -> Vec<(usize, usize)> {
    enums
        .enumerate()
        .filter_map(|(ei, mut variants)| variants.position(|v| v == name).map(|vi| (ei, vi)))
        .collect()
}

/// `wrong_arguments`: a built-in called with the wrong number of arguments.
pub(super) fn arity(b: Builtin, given: usize, span: Span) -> Diagnostic {
    let n = b.arity();
    Diagnostic::error(
        Code::WrongArguments,
        format!(
            "`{}` takes {n} argument{} but {given} {} given",
            b.name(),
            if n == 1 { "" } else { "s" },
            if given == 1 { "was" } else { "were" }
        ),
        span,
        format!("expected {n} argument{}", if n == 1 { "" } else { "s" }),
    )
}

/// `type_mismatch`: a built-in's arguments are not of one allowed type.
pub(super) fn arguments(b: Builtin, found: &[String], span: Span) -> Diagnostic {
    let wants = match b.signature() {
        Signature::Numeric => "arguments of one numeric type",
        _ => "float arguments of one type",
    };
    Diagnostic::error(
        Code::TypeMismatch,
        format!(
            "`{}` takes {wants}, found {}",
            b.name(),
            found.join(" and ")
        ),
        span,
        "wrong argument types",
    )
    .with_help(match b.signature() {
        Signature::Numeric => "convert the arguments to one type with `as`",
        _ => "convert integers with `as f64` (or `as f32`)",
    })
}

/// `reserved_name`: a declaration takes a built-in function's name.
pub(super) fn reserved(name: &ast::Name) -> Option<Diagnostic> {
    Builtin::from_name(&name.text).map(|b| {
        Diagnostic::error(
            Code::ReservedName,
            format!("`{}` is the name of a built-in function", b.name()),
            name.span,
            "reserved for the built-in function",
        )
        .with_help("choose another name")
    })
}
