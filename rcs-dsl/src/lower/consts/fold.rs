//! Stage 2, constants: folding one expression — literals, names of other
//! constants and enum variants, operators, casts and built-in calls — with
//! the run-time arithmetic (see the parent module).

use super::*;

impl Folder<'_, '_> {
    /// Fold `e`; a literal-only result gets the hint's type if numeric,
    /// else the default (`i64`, `f64`).
    pub(super) fn settled(
        &mut self,
        scope: Scope,
        e: &ast::Expr,
        hint: Option<&Type>,
    ) -> Option<Folded> {
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
            ast::ExprKind::NewCommand
            | ast::ExprKind::StateCycles
            | ast::ExprKind::PlanCycles
            | ast::ExprKind::StateTime
            | ast::ExprKind::PlanTime => self.not_constant(e.span, "a plan quantity"),
            ast::ExprKind::Duration(_) => {
                self.diags
                    .push(super::super::time::duration_not_number(e.span, hint));
                None
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
                        self.diags.push(
                            d.with_help(format!("the variants are: {}", all.join(", ")))
                                .suggest(&v.text, all.iter().copied()),
                        );
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
                let target = match crate::lower::primitive(&to.text) {
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
            ast::ExprKind::Binary(op, operands) => {
                let [l, r] = &**operands;
                self.binary(scope, *op, l, r, hint, e.span)
            }
        }
    }

    fn name(&mut self, scope: Scope, n: &ast::Name, hint: Option<&Type>) -> Option<Folded> {
        if self.durations.get(scope, &n.text).is_some() {
            self.diags
                .push(super::super::time::duration_not_number(n.span, hint));
            return None;
        }
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
            })
            .suggest(
                &n.text,
                self.defs
                    .keys()
                    .filter(|(s, _)| s.is_none() || *s == scope)
                    .map(|(_, name)| name.as_str())
                    .chain(self.g.consts_table.names(scope)),
            ),
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
        ) || op.is_bitwise();
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
                        BinOp::BitAnd => x & y,
                        BinOp::BitOr => x | y,
                        BinOp::BitXor => x ^ y,
                        BinOp::Shl => u32::try_from(y)
                            .ok()
                            .filter(|y| *y < 64)
                            .map_or(0, |y| x << y),
                        BinOp::Shr => u32::try_from(y)
                            .ok()
                            .filter(|y| *y < 64)
                            .map_or(0, |y| x >> y),
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
        let int = |t: &Type| matches!(t, Type::Int(_));
        let fits = match op {
            // A shift's amount has a type of its own.
            BinOp::Shl | BinOp::Shr => int(ta) && int(tb),
            _ => {
                ta == tb
                    && match op {
                        BinOp::And | BinOp::Or => *ta == Type::Bool,
                        BinOp::BitAnd | BinOp::BitOr | BinOp::BitXor => int(ta),
                        BinOp::Eq | BinOp::Ne => true,
                        BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => {
                            matches!(ta, Type::Int(_) | Type::Float(_))
                        }
                        _ => matches!(ta, Type::Int(_) | Type::Float(_)),
                    }
            }
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
