//! Stage 1, the builder: expressions — operator chains folded by
//! precedence (with the depth limit), operands, postfix projections and
//! primaries.

use super::*;

/// The parts of one operand: `op_unary* postfix_expr (as T)*`.
#[derive(Default)]
struct Operand<'i> {
    /// Each prefix: whether it is `!` (else `-`), and its span.
    prefixes: Vec<(bool, Span)>,
    base: Option<Pair<'i, Rule>>,
    casts: Vec<Pair<'i, Rule>>,
}

impl Builder {
    pub(in crate::parser) fn expr(&mut self, p: Pair<Rule>) -> Expr {
        let e = self.expr_at(p, 0);
        self.bitwise_beside_comparison(&e);
        e
    }

    /// `w & 0x4F == 7` is `(w & 0x4F) == 7` in Rust but `w & (0x4F == 7)`
    /// in C: a bitwise operator and a comparison side by side without
    /// parentheses is refused, with the parenthesised form as help.
    fn bitwise_beside_comparison(&mut self, e: &Expr) {
        let mut stack = vec![e];
        while let Some(e) = stack.pop() {
            match &e.kind {
                ExprKind::Binary(op, operands) => {
                    for child in operands.iter() {
                        if let ExprKind::Binary(inner, _) = &child.kind {
                            let mixed = (op.is_comparison() && inner.is_bitwise())
                                || (op.is_bitwise() && inner.is_comparison());
                            if mixed {
                                self.mixed_bitwise(e, *op, *inner);
                            }
                        }
                    }
                    stack.extend(operands.iter());
                }
                ExprKind::Unary(_, x) | ExprKind::Cast(x, _) | ExprKind::Paren(x) => stack.push(x),
                ExprKind::Field(x, _) => stack.push(x),
                ExprKind::Index(x, i) => {
                    stack.push(x);
                    stack.push(i);
                }
                ExprKind::Call(_, args) => stack.extend(args.iter()),
                _ => {}
            }
        }
    }

    fn mixed_bitwise(&mut self, whole: &Expr, op: BinOp, inner_op: BinOp) {
        let (bitwise, comparison) = if op.is_bitwise() {
            (op, inner_op)
        } else {
            (inner_op, op)
        };
        self.error(
            whole.span,
            format!(
                "`{}` and `{}` side by side need parentheses",
                bitwise.symbol(),
                comparison.symbol()
            ),
            "bitwise operator beside a comparison",
        );
        let (b, c) = (bitwise.symbol(), comparison.symbol());
        self.diags.last_mut().expect("just pushed").help = Some(format!(
            "Rust and C read this in opposite orders: put the part meant first in parentheses, `(word {b} mask) {c} value`"
        ));
    }

    pub(in crate::parser) fn too_deep(&mut self, span: Span) -> Expr {
        self.error(
            span,
            format!("expression nested more than {MAX_EXPR_DEPTH} deep"),
            "too deep",
        );
        self.diags.last_mut().expect("just pushed").help = Some(
            "split it: compute parts in earlier rows' jobs into `var`s, or in a hook".to_string(),
        );
        Expr {
            kind: ExprKind::Bool(false),
            span,
        }
    }

    /// Build an expression whose root sits at tree depth `depth`. Operator
    /// chains are folded by precedence climbing with explicit stacks, and
    /// every node's depth is bounded by [`MAX_EXPR_DEPTH`], so no input can
    /// make this (or the type checker after it) recurse without limit.
    pub(in crate::parser) fn expr_at(&mut self, p: Pair<Rule>, depth: usize) -> Expr {
        let span = self.span(&p);
        if depth > MAX_EXPR_DEPTH {
            return self.too_deep(span);
        }
        let mut operands: Vec<(Expr, usize)> = Vec::new();
        let mut ops: Vec<BinOp> = Vec::new();
        let mut failed = false;
        let reduce = |operands: &mut Vec<(Expr, usize)>, op: BinOp| {
            let (r, dr) = operands.pop().expect("right operand");
            let (l, dl) = operands.pop().expect("left operand");
            let span = l.span.to(r.span);
            let d = dl.max(dr) + 1;
            operands.push((
                Expr {
                    kind: ExprKind::Binary(op, Box::new([l, r])),
                    span,
                },
                d,
            ));
            d
        };
        // The grammar's `operand` is silent (see grammar.pest), so its
        // parts arrive flat: `op_unary* postfix_expr
        // (as T)*`, then an operator or the end.
        let mut parts = Operand::default();
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::op_unary => parts
                    .prefixes
                    .push((c.as_str() == "!", self.token_span(&c))),
                Rule::postfix_expr => parts.base = Some(c),
                Rule::ident => parts.casts.push(c),
                Rule::infix => {
                    let operand = std::mem::take(&mut parts);
                    operands.push(self.operand(operand, depth));
                    let op = bin_op(c.as_str());
                    // Left-associative: reduce while the stacked operator binds at least as tightly.
                    while let Some(&top) = ops.last() {
                        if top.precedence() < op.precedence() {
                            break;
                        }
                        ops.pop();
                        if reduce(&mut operands, top) + depth > MAX_EXPR_DEPTH {
                            failed = true;
                        }
                    }
                    ops.push(op);
                    if failed {
                        break;
                    }
                }
                _ => {}
            }
        }
        if !failed && ops.is_empty() {
            // One operand and no operator (most arguments and assigned
            // values): no stack needed.
            return self.operand(parts, depth).0;
        }
        if !failed {
            operands.push(self.operand(parts, depth));
        }
        if failed {
            return self.too_deep(span);
        }
        while let Some(op) = ops.pop() {
            if reduce(&mut operands, op) + depth > MAX_EXPR_DEPTH {
                return self.too_deep(span);
            }
        }
        operands.pop().expect("an expression has an operand").0
    }

    /// `op_unary* postfix (as T)*`; returns the node and its height.
    fn operand(&mut self, parts: Operand, depth: usize) -> (Expr, usize) {
        let Operand {
            prefixes,
            base,
            casts,
        } = parts;
        let wrappers = prefixes.len() + casts.len();
        let base = base.expect("operand has a base");
        if wrappers + depth > MAX_EXPR_DEPTH {
            let span = self.span(&base);
            return (self.too_deep(span), 1);
        }
        let (mut e, mut h) = self.postfix(base, depth + wrappers);
        for ty in casts {
            let ty = self.name(ty);
            let span = e.span.to(ty.span);
            e = Expr {
                kind: ExprKind::Cast(Box::new(e), ty),
                span,
            };
            h += 1;
        }
        for (not, op_span) in prefixes.into_iter().rev() {
            let span = op_span.to(e.span);
            let op = if not { UnOp::Not } else { UnOp::Neg };
            e = Expr {
                kind: ExprKind::Unary(op, Box::new(e)),
                span,
            };
            h += 1;
        }
        (e, h)
    }

    pub(in crate::parser) fn postfix(&mut self, p: Pair<Rule>, depth: usize) -> (Expr, usize) {
        let mut inner = p.into_inner();
        let first = inner.next().expect("primary");
        // A name's arguments or `::VARIANT` belong to the primary (the
        // grammar's `name_expr` is silent), not to its suffixes.
        let tail = match inner.peek() {
            Some(t)
                if first.as_rule() == Rule::ident
                    && matches!(t.as_rule(), Rule::call_args | Rule::path_tail) =>
            {
                inner.next()
            }
            _ => None,
        };
        // Counted on a copy of the iterator (cheap) rather than collected:
        // most operands have a suffix, and collecting allocated for each.
        let count = inner.clone().count();
        if count + depth > MAX_EXPR_DEPTH {
            let span = self.span(&first);
            return (self.too_deep(span), 1);
        }
        let (mut e, mut h) = self.primary(first, tail, depth + count);
        let mut suffixes = inner.peekable();
        // `cmd.P`: the command parameter, not a field of something named `cmd`.
        if matches!(&e.kind, ExprKind::Path(None, n) if n.text == "cmd") {
            let param = suffixes.next_if(|s| s.as_rule() == Rule::ident && !is_field_keyword(s));
            match param {
                Some(p) => {
                    let span = e.span.to(self.span(&p));
                    e = Expr {
                        kind: ExprKind::CmdParam(self.name(p)),
                        span,
                    };
                }
                None => {
                    let span = e.span;
                    self.error(
                        span,
                        "`cmd` alone is not a value",
                        "expected `cmd.PARAMETER`",
                    );
                    self.diags.last_mut().expect("just pushed").help =
                        Some("read a parameter of the current command as `cmd.NAME`".to_string());
                }
            }
        }
        // A field arrives as its name (`field_access` is silent), an index
        // as an `index` pair.
        for c in suffixes {
            let span = e.span.to(self.token_span(&c));
            e = match c.as_rule() {
                // `status` and `error` are keywords but valid after a dot.
                Rule::ident if is_field_keyword(&c) => Expr {
                    kind: ExprKind::Field(
                        Box::new(e),
                        Name {
                            text: c.as_str().into(),
                            span: self.token_span(&c),
                        },
                    ),
                    span,
                },
                Rule::ident => Expr {
                    kind: ExprKind::Field(Box::new(e), self.name(c)),
                    span,
                },
                _ => {
                    let c = c.into_inner().next().expect("an index expression");
                    let idx = self.expr_at(c, depth + 1);
                    Expr {
                        kind: ExprKind::Index(Box::new(e), Box::new(idx)),
                        span,
                    }
                }
            };
            h += 1;
        }
        (e, h)
    }

    /// A number, a parenthesis, or a name with its `tail` (call arguments
    /// or `::VARIANT`).
    pub(in crate::parser) fn primary(
        &mut self,
        p: Pair<Rule>,
        tail: Option<Pair<Rule>>,
        depth: usize,
    ) -> (Expr, usize) {
        // Each ends in a token: no whitespace to trim.
        let span = match &tail {
            Some(t) => self.token_span(&p).to(self.token_span(t)),
            None => self.token_span(&p),
        };
        let mut height = 1;
        let kind = match p.as_rule() {
            Rule::number if !crate::time::split_unit(p.as_str()).1.is_empty() => {
                self.duration_literal(p.as_str(), span)
            }
            Rule::number
                if !p.as_str().starts_with("0x") && p.as_str().contains(['.', 'e', 'E']) =>
            {
                match without_underscores(p.as_str()).parse::<f64>() {
                    Ok(v) if v.is_finite() => ExprKind::Float(v),
                    _ => {
                        self.error(span, "float literal is out of range", "not a finite f64");
                        ExprKind::Float(0.0)
                    }
                }
            }
            Rule::number => match parse_int(p.as_str()) {
                Ok(v) => ExprKind::Int(v),
                _ => {
                    self.error(
                        span,
                        "integer literal is too large",
                        "does not fit in 64 bits",
                    );
                    ExprKind::Int(0)
                }
            },
            Rule::ident => {
                let first = p;
                match (first.as_str(), tail.as_ref().map(|c| c.as_rule())) {
                    ("true", None) => ExprKind::Bool(true),
                    ("false", None) => ExprKind::Bool(false),
                    ("new_command", None) => ExprKind::NewCommand,
                    ("state_cycles", None) => ExprKind::StateCycles,
                    ("plan_cycles", None) => ExprKind::PlanCycles,
                    ("state_time", None) => ExprKind::StateTime,
                    ("plan_time", None) => ExprKind::PlanTime,
                    // Left for `postfix`, which turns `cmd.P` into a parameter.
                    ("cmd", None) => ExprKind::Path(
                        None,
                        Name {
                            text: "cmd".into(),
                            span,
                        },
                    ),
                    (_, Some(Rule::call_args)) => {
                        let name = self.name(first);
                        let args = tail
                            .expect("arguments")
                            .into_inner()
                            .map(|a| self.expr_at(a, depth + 1))
                            .collect();
                        height = 2;
                        ExprKind::Call(Box::new(name), args)
                    }
                    (_, Some(_)) => {
                        let qualifier = self.name(first);
                        let variant = tail.expect("`::VARIANT`").into_inner().next();
                        let name = self.name(variant.expect("variant"));
                        ExprKind::Path(Some(Box::new(qualifier)), name)
                    }
                    (_, None) => ExprKind::Path(None, self.name(first)),
                }
            }
            Rule::paren => {
                let e = self.expr_at(p.into_inner().next().expect("inner"), depth + 1);
                height = 2;
                ExprKind::Paren(Box::new(e))
            }
            _ => unreachable!("primary alternatives are listed in the grammar"),
        };
        (Expr { kind, span }, height)
    }
}

/// `status` or `error` after a dot: a subordinate's status or error code,
/// not a user-chosen name (so not refused as a reserved word).
fn is_field_keyword(p: &Pair<Rule>) -> bool {
    matches!(p.as_str(), "status" | "error")
}

impl Builder {
    /// A number with letters after it: a duration (`50ms`, `1.5s`), or a
    /// `syntax` error that names what is wrong and shows the right spelling.
    fn duration_literal(&mut self, text: &str, span: Span) -> ExprKind {
        use crate::time::{parse_literal, split_unit, LiteralError};
        let (number, unit) = split_unit(text);
        if number == "0" && (unit.starts_with('x') || unit.starts_with('b')) {
            let what = if unit.starts_with('x') {
                "hex"
            } else {
                "binary"
            };
            self.error(
                span,
                format!("`{text}` is not a {what} literal"),
                "no digits after the prefix",
            );
            self.help_last(if what == "hex" {
                "write the digits after `0x`: `0x6F`"
            } else {
                "write the digits after `0b`: `0b0110_1111`"
            });
            return ExprKind::Int(0);
        }
        let (message, label, help) = match parse_literal(number, unit) {
            Ok(ns) => return ExprKind::Duration(ns),
            Err(LiteralError::UnknownUnit(u)) => (
                format!("unknown unit `{u}` in `{text}`"),
                "not a unit".to_string(),
                match u.as_str() {
                    "sec" | "secs" | "second" | "seconds" => format!("write `{number}s`"),
                    "msec" | "msecs" | "millis" => format!("write `{number}ms`"),
                    "usec" | "usecs" | "micros" | "µs" => format!("write `{number}us`"),
                    "min" | "mins" | "minute" | "minutes" | "h" | "hour" | "hours" => {
                        "write minutes and hours in seconds: `60s`, `3600s`".to_string()
                    }
                    _ => "a duration is a decimal number and a unit: `250us`, `50ms`, `1.5s` \
                          (a number takes no letters otherwise)"
                        .to_string(),
                },
            ),
            Err(LiteralError::NotDecimal) => (
                format!("`{text}`: a duration is written in decimal"),
                "hex or binary duration".to_string(),
                "write it in decimal: `16ms` (hex and binary are for integer words)".to_string(),
            ),
            Err(LiteralError::Exponent) => (
                format!("`{text}`: a duration has no exponent"),
                "exponent in a duration".to_string(),
                "write it with a smaller unit: `1e3ms` is `1s`, `1.5e-3s` is `1.5ms`".to_string(),
            ),
            Err(LiteralError::TooFine) => (
                format!("`{text}` is finer than a nanosecond"),
                "not a whole number of nanoseconds".to_string(),
                "durations are exact in integer nanoseconds; drop the extra decimals".to_string(),
            ),
            Err(LiteralError::TooLong) => (
                format!("`{text}` is too long a duration"),
                "beyond 2^64 nanoseconds".to_string(),
                "a duration holds at most 18446744073s (about 584 years)".to_string(),
            ),
        };
        self.error(span, message, label);
        self.help_last(&help);
        ExprKind::Duration(0)
    }

    fn help_last(&mut self, help: &str) {
        if let Some(d) = self.diags.last_mut() {
            d.help = Some(help.to_string());
        }
    }
}
