//! IR expressions and jobs → Rust tokens for the inside of a controller
//! module. Parentheses are inserted only where Rust's precedence needs them
//! (rustc warns about the others). Integer arithmetic wraps and division by
//! zero yields 0, so no generated operation can panic; the interpreter
//! implements the same rules.

use super::names::Names;
use crate::ident::prefixed;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use rcs_dsl::ast::{AssignOp, BinOp, UnOp};
use rcs_dsl::ir::*;

/// Rust binding strengths (larger binds tighter).
const OR: u8 = 1;
const AND: u8 = 2;
const CMP: u8 = 3;
const BIT_OR: u8 = 4;
const BIT_XOR: u8 = 5;
const BIT_AND: u8 = 6;
const ADD: u8 = 8;
const MUL: u8 = 9;
const CAST: u8 = 10;
const UNARY: u8 = 11;
const ATOM: u8 = 12;

/// Generated code with its strength, and whether it holds a block
/// (a hoisted nested hook call), which cannot stand in an `if` condition.
pub(crate) struct Code {
    pub ts: TokenStream,
    pub prec: u8,
    pub has_block: bool,
}

impl Code {
    pub(crate) const ATOM: u8 = ATOM;
    pub(crate) const AND: u8 = AND;
    pub(crate) const CAST: u8 = CAST;

    pub(crate) fn new(ts: TokenStream, prec: u8, has_block: bool) -> Code {
        Code {
            ts,
            prec,
            has_block,
        }
    }

    fn atom(ts: TokenStream) -> Code {
        Code {
            ts,
            prec: ATOM,
            has_block: false,
        }
    }

    /// The tokens, parenthesised if they bind looser than `min`.
    pub fn at(&self, min: u8) -> TokenStream {
        let ts = &self.ts;
        if self.prec < min {
            quote!((#ts))
        } else {
            ts.clone()
        }
    }
}

/// Where an expression is generated.
pub(crate) struct Gen<'a> {
    pub ir: &'a Ir,
    pub names: &'a Names,
    pub ctrl: &'a Controller,
    pub ci: usize,
    /// In a plan's conditions: its distinct hook calls, each read through
    /// its lazily filled local (empty for jobs and constants).
    pub cached: &'a [CachedCall],
}

impl<'a> Gen<'a> {
    /// The generator of controller `ci`'s jobs, initialisers and constants:
    /// no cached hook calls (those belong to a plan's conditions only).
    pub(crate) fn new(ir: &'a Ir, names: &'a Names, ci: usize) -> Self {
        Gen {
            ir,
            names,
            ctrl: &ir.controllers[ci],
            ci,
            cached: &[],
        }
    }
}

/// A distinct hook call (same hook, syntactically equal arguments) of a
/// plan's conditions: evaluated at most once per cycle, on first use, into
/// `local: Option<T>`.
pub(crate) struct CachedCall {
    pub hook: HookId,
    pub args: Vec<Expr>,
    pub local: proc_macro2::Ident,
}

impl CachedCall {
    /// The distinct hook calls of these conditions, inner calls first;
    /// each hook's locals are numbered `<hook>_0`, `<hook>_1`, …
    pub fn collect<'e>(
        names: &Names,
        ci: usize,
        conds: impl Iterator<Item = &'e Expr>,
    ) -> Vec<CachedCall> {
        let mut calls: Vec<CachedCall> = Vec::new();
        for c in conds {
            collect_calls(c, &mut |h, args| {
                if calls.iter().any(|k| k.hook == h && k.args == args) {
                    return;
                }
                let nth = calls.iter().filter(|k| k.hook == h).count();
                let hook = names.ctrls[ci].hooks[h.index()].to_string();
                calls.push(CachedCall {
                    hook: h,
                    args: args.to_vec(),
                    local: format_ident!("{}_{nth}", hook.trim_start_matches("r#")),
                });
            });
        }
        calls
    }
}

/// Every hook call in `e`, arguments before the call that takes them.
fn collect_calls(e: &Expr, f: &mut dyn FnMut(HookId, &[Expr])) {
    match &e.kind {
        ExprKind::Field(x, _)
        | ExprKind::Index(x, _)
        | ExprKind::Unary(_, x)
        | ExprKind::Cast(x) => collect_calls(x, f),
        ExprKind::Binary(_, operands) => operands.iter().for_each(|x| collect_calls(x, f)),
        ExprKind::IndexBy(l, r) => {
            collect_calls(l, f);
            collect_calls(r, f);
        }
        ExprKind::Call(h, args) => {
            args.iter().for_each(|a| collect_calls(a, f));
            f(*h, args);
        }
        ExprKind::Builtin(_, args) => args.iter().for_each(|a| collect_calls(a, f)),
        _ => {}
    }
}

pub(crate) fn rust_type(names: &Names, t: &Type) -> TokenStream {
    match t {
        Type::Bool => quote!(bool),
        Type::Int(i) => {
            let id = format_ident!("{}", i.name());
            quote!(#id)
        }
        Type::Float(f) => {
            let id = format_ident!("{}", f.name());
            quote!(#id)
        }
        Type::Enum(e) => {
            let id = &names.enums[e.index()].ty;
            quote!(super::types::#id)
        }
        Type::Buffer(b) => {
            let id = &names.buffers[b.index()].ty;
            quote!(super::types::#id)
        }
        Type::Array(elem, n) => {
            let elem = rust_type(names, elem);
            let n = proc_macro2::Literal::usize_unsuffixed(*n as usize);
            quote!([#elem; #n])
        }
        Type::Status(_) => quote!(rt::Status),
        Type::ErrorCode(_) => quote!(rt::ErrorCode),
        Type::Unit => quote!(()),
    }
}

/// The zero value of a type, as a constant expression.
pub(crate) fn zero(names: &Names, t: &Type) -> TokenStream {
    match t {
        Type::Bool => quote!(false),
        Type::Int(_) => int_lit(0, t).ts,
        Type::Float(_) => float_lit(0.0, t).ts,
        Type::Enum(_) | Type::Buffer(_) => {
            let ty = rust_type(names, t);
            quote!(<#ty as ::core::default::Default>::default())
        }
        Type::Array(elem, n) => {
            let z = zero(names, elem);
            let n = proc_macro2::Literal::usize_unsuffixed(*n as usize);
            quote!([#z; #n])
        }
        Type::Status(_) => quote!(rt::Status::NOT_READY),
        Type::ErrorCode(_) => quote!(rt::ErrorCode::NONE),
        Type::Unit => quote!(()),
    }
}

fn int_lit(v: i128, t: &Type) -> Code {
    let suffix = match t {
        Type::Int(i) => i.name(),
        _ => "i64",
    };
    let lit: TokenStream = format!("{}{suffix}", v.unsigned_abs())
        .parse()
        .expect("integer literal");
    signed(lit, v < 0)
}

fn float_lit(v: f64, t: &Type) -> Code {
    let text = match t {
        Type::Float(FloatTy::F32) => format!("{:?}f32", (v.abs()) as f32),
        _ => format!("{:?}f64", v.abs()),
    };
    let lit: TokenStream = text.parse().expect("float literal");
    signed(lit, v.is_sign_negative() && v != 0.0)
}

/// A literal of the magnitude, negated when `negative` (a unary minus
/// expression, so that it is parenthesised where precedence needs it).
fn signed(magnitude: TokenStream, negative: bool) -> Code {
    if negative {
        Code {
            ts: quote!(-#magnitude),
            prec: UNARY,
            has_block: false,
        }
    } else {
        Code::atom(magnitude)
    }
}

/// Fold a cast of a literal at generation time (clippy dislikes `1i64 as f32`).
fn fold_cast(e: &Expr, to: &Type) -> Option<Code> {
    // The interpreter's `as` is the reference; folding must agree with it.
    use rcs_dsl::interp::{float_to_int, wrap};
    match (&e.kind, to) {
        (ExprKind::Int(v), Type::Int(it)) => Some(int_lit(wrap(*v, *it), to)),
        (ExprKind::Int(v), Type::Float(_)) => Some(float_lit(*v as f64, to)),
        (ExprKind::Float(v), Type::Float(_)) => Some(float_lit(*v, to)),
        (ExprKind::Float(v), Type::Int(it)) => Some(int_lit(float_to_int(*v, *it), to)),
        _ => None,
    }
}

impl Gen<'_> {
    pub(super) fn cn(&self) -> &super::names::CtrlNames {
        &self.names.ctrls[self.ci]
    }

    pub fn expr(&self, e: &Expr) -> Code {
        if let Some(slots) = &self.names.slots {
            if let Some(i) = slots.slot_of.get(&(e as *const Expr as usize)) {
                let prefix = &slots.prefix;
                let field = super::names::SlotNames::field(*i);
                return Code::atom(quote!(#prefix.#field));
            }
        }
        match &e.kind {
            ExprKind::Int(v) => int_lit(*v, &e.ty),
            ExprKind::Float(v) => float_lit(*v, &e.ty),
            ExprKind::Bool(b) => Code::atom(if *b { quote!(true) } else { quote!(false) }),
            ExprKind::Variant(en, v) => {
                let n = &self.names.enums[en.index()];
                let (ty, var) = (&n.ty, &n.variants[*v as usize]);
                Code::atom(quote!(super::types::#ty::#var))
            }
            ExprKind::Status(s) => {
                let Type::Status(owner) = e.ty else {
                    unreachable!("a status has a status type")
                };
                let module = &self.names.ctrls[owner.index()].module;
                let c = &self.names.ctrls[owner.index()].status_consts[s.index()];
                Code::atom(quote!(super::#module::status::#c))
            }
            // An error code by its runtime number (the owner's `error::NAME`
            // holds the same; a built-in has no constant in every module).
            ExprKind::ErrorCode(code) => {
                let raw = proc_macro2::Literal::u16_suffixed(*code);
                Code::atom(quote!(rt::ErrorCode(#raw)))
            }
            ExprKind::NewCommand => Code::atom(quote!(self.bk.new_command())),
            ExprKind::StateCycles => Code::atom(quote!(self.bk.state_cycles())),
            ExprKind::PlanCycles => Code::atom(quote!(self.bk.plan_cycles())),
            ExprKind::CmdParam(c, p) => {
                let local = prefixed("cmd", &self.cn().params[c.index()][p.index()]);
                Code::atom(quote!(#local))
            }
            // `cmd.P` in `pre`/`post`: the running verb's P, else zero
            // (`data.command` is the default command, of zeros, before the
            // first one arrives).
            ExprKind::CurrentParam(verbs) => {
                let n = self.cn();
                let arms = verbs.iter().map(|(c, p)| {
                    let v = &n.commands[c.index()];
                    let f = &n.params[c.index()][p.index()];
                    quote!(Command::#v { #f: value, .. })
                });
                let rest = if verbs.len() < self.ctrl.commands.len() {
                    let z = zero(self.names, &e.ty);
                    quote!(_ => #z,)
                } else {
                    quote!()
                };
                Code::atom(quote!(match self.data.command { #(#arms)|* => value, #rest }))
            }
            ExprKind::Var(v) => {
                let id = &self.cn().vars[v.index()];
                Code::atom(quote!(self.data.vars.#id))
            }
            ExprKind::Buffer(b) => {
                let id = self.cn().buffers[b.index()]
                    .as_ref()
                    .expect("buffer of this controller");
                if self.ctrl.writes.contains(b) {
                    Code::atom(quote!(self.data.writes.#id))
                } else {
                    Code::atom(quote!(self.data.reads.#id))
                }
            }
            ExprKind::Field(base, f) => {
                let b = self.expr(base);
                let Type::Buffer(bt) = base.ty else {
                    unreachable!("fields are on buffers")
                };
                let field = &self.names.buffers[bt.index()].fields[*f as usize];
                let base = b.at(ATOM);
                Code {
                    ts: quote!(#base.#field),
                    prec: ATOM,
                    has_block: b.has_block,
                }
            }
            ExprKind::Index(base, i) => {
                let b = self.expr(base);
                let base = b.at(ATOM);
                let i = proc_macro2::Literal::usize_unsuffixed(*i as usize);
                Code {
                    ts: quote!(#base[#i]),
                    prec: ATOM,
                    has_block: b.has_block,
                }
            }
            ExprKind::IndexBy(base, i) => self.index_by(base, i, &e.ty),
            ExprKind::Call(h, args) => self.call(*h, args),
            // The controller's watch on the buffer, fed by each cycle's read.
            ExprKind::BufferStale(b) => {
                let id = self.cn().buffers[b.index()]
                    .as_ref()
                    .expect("buffer of this controller");
                let watch = crate::ident::prefixed("watch", id);
                Code::atom(quote!(self.#watch.stale_cycles()))
            }
            ExprKind::Sub(c, prop) => {
                let i = self.ctrl.subordinate_index(*c).expect("a subordinate");
                let id = &self.cn().subs[i];
                Code::atom(match prop {
                    // `subs`: the cycle's local copy (see the controller's `cycle`).
                    SubProp::Status => quote!(subs.#id.status),
                    SubProp::Done => quote!(subs.#id.done()),
                    SubProp::Executing => quote!(subs.#id.executing()),
                    SubProp::Error => quote!(subs.#id.error()),
                    SubProp::StaleCycles => quote!(subs.#id.stale_cycles),
                    SubProp::ErrorCode => quote!(subs.#id.error),
                })
            }
            ExprKind::SubField(sub, var) => Code::atom(super::every_cycle::sub_field(
                self.names, self.ctrl, self.ci, *sub, *var,
            )),
            ExprKind::Unary(op, x) => {
                let c = self.expr(x);
                match (op, &x.ty) {
                    (UnOp::Neg, Type::Int(_)) => {
                        let r = c.at(ATOM);
                        Code {
                            ts: quote!(#r.wrapping_neg()),
                            prec: ATOM,
                            has_block: c.has_block,
                        }
                    }
                    (UnOp::Neg, _) => {
                        let r = c.at(UNARY);
                        Code {
                            ts: quote!(-#r),
                            prec: UNARY,
                            has_block: c.has_block,
                        }
                    }
                    (UnOp::Not, _) => {
                        let r = c.at(UNARY);
                        Code {
                            ts: quote!(!#r),
                            prec: UNARY,
                            has_block: c.has_block,
                        }
                    }
                }
            }
            ExprKind::Cast(x) => {
                if x.ty == e.ty {
                    return self.expr(x);
                }
                if let Some(folded) = fold_cast(x, &e.ty) {
                    return folded;
                }
                let c = self.expr(x);
                let inner = c.at(CAST);
                let ty = rust_type(self.names, &e.ty);
                Code {
                    ts: quote!(#inner as #ty),
                    prec: CAST,
                    has_block: c.has_block,
                }
            }
            ExprKind::Binary(op, operands) => {
                let [l, r] = &**operands;
                self.binary(*op, l, r)
            }
            ExprKind::Builtin(b, args) => {
                let codes: Vec<Code> = args.iter().map(|a| self.expr(a)).collect();
                let ty = args.first().map_or(&e.ty, |a| &a.ty);
                super::builtins::call(*b, ty, &codes)
            }
        }
    }

    fn binary(&self, op: BinOp, l: &Expr, r: &Expr) -> Code {
        // `x == true` and friends: clippy prefers the plain boolean.
        if matches!(op, BinOp::Eq | BinOp::Ne) {
            for (lit, other) in [(l, r), (r, l)] {
                if let ExprKind::Bool(b) = lit.kind {
                    let o = self.expr(other);
                    if b == (op == BinOp::Eq) {
                        return o;
                    }
                    let inner = o.at(UNARY);
                    return Code {
                        ts: quote!(!#inner),
                        prec: UNARY,
                        has_block: o.has_block,
                    };
                }
            }
        }
        let a = self.expr(l);
        let b = self.expr(r);
        let has_block = a.has_block || b.has_block;
        let int = matches!(l.ty, Type::Int(_));
        let method = |m: &str| {
            let m = format_ident!("{m}");
            let recv = a.at(ATOM);
            let arg = &b.ts;
            quote!(#recv.#m(#arg))
        };
        let (ts, prec) = match op {
            BinOp::Add if int => (method("wrapping_add"), ATOM),
            BinOp::Sub if int => (method("wrapping_sub"), ATOM),
            BinOp::Mul if int => (method("wrapping_mul"), ATOM),
            BinOp::Div if int => {
                let m = method("checked_div");
                (quote!(#m.unwrap_or(0)), ATOM)
            }
            BinOp::Rem if int => {
                let m = method("checked_rem");
                (quote!(#m.unwrap_or(0)), ATOM)
            }
            // A shift by the width or more (or by a negative amount) is 0,
            // as the interpreter's `arith::bitwise` says: never a panic.
            BinOp::Shl | BinOp::Shr => {
                let m = format_ident!(
                    "{}",
                    if op == BinOp::Shl {
                        "checked_shl"
                    } else {
                        "checked_shr"
                    }
                );
                let recv = a.at(ATOM);
                let amount = &b.ts;
                let ts = match r.ty {
                    Type::Int(IntTy::U32) => quote!(#recv.#m(#amount).unwrap_or(0)),
                    Type::Int(IntTy::U8 | IntTy::U16) => {
                        quote!(#recv.#m(u32::from(#amount)).unwrap_or(0))
                    }
                    _ => quote!(match u32::try_from(#amount) {
                        Ok(s) => #recv.#m(s).unwrap_or(0),
                        Err(_) => 0,
                    }),
                };
                (ts, ATOM)
            }
            _ => {
                let p = match op {
                    BinOp::Or => OR,
                    BinOp::And => AND,
                    BinOp::BitOr => BIT_OR,
                    BinOp::BitXor => BIT_XOR,
                    BinOp::BitAnd => BIT_AND,
                    BinOp::Add | BinOp::Sub => ADD,
                    BinOp::Mul | BinOp::Div | BinOp::Rem => MUL,
                    _ => CMP,
                };
                // Comparisons do not chain in Rust, and `a as T < b` parses
                // `T<` as generics: both need parentheses.
                let lmin = if p == CMP { CMP + 1 } else { p };
                let mut lt = a.at(lmin);
                if p == CMP && a.prec == CAST && matches!(op, BinOp::Lt | BinOp::Le) {
                    let inner = &a.ts;
                    lt = quote!((#inner));
                }
                let rt = b.at(p + 1);
                let sym: TokenStream = op.symbol().parse().expect("operator");
                (quote!(#lt #sym #rt), p)
            }
        };
        Code {
            ts,
            prec,
            has_block,
        }
    }

    /// A hook call; in a condition, read through its cache local (see
    /// [`CachedCall`]), so that it runs at most once per cycle.
    fn call(&self, h: HookId, args: &[Expr]) -> Code {
        let code = self.direct_call(h, args);
        match self.cached.iter().find(|k| k.hook == h && k.args == args) {
            Some(k) => {
                let local = &k.local;
                let inner = &code.ts;
                Code {
                    ts: quote!(*#local.get_or_insert_with(|| #inner)),
                    prec: UNARY,
                    has_block: code.has_block,
                }
            }
            None => code,
        }
    }

    /// `self.hooks.name(&self.data, args…)`. Arguments that call hooks
    /// themselves are evaluated first into locals (a block), because the
    /// outer call already borrows the hooks mutably.
    fn direct_call(&self, h: HookId, args: &[Expr]) -> Code {
        let name = &self.cn().hooks[h.index()];
        let codes: Vec<Code> = args.iter().map(|a| self.expr(a)).collect();
        let nested = args.iter().any(contains_call);
        if !nested {
            let ts: Vec<&TokenStream> = codes.iter().map(|c| &c.ts).collect();
            let has_block = codes.iter().any(|c| c.has_block);
            return Code {
                ts: quote!(self.hooks.#name(&self.data #(, #ts)*)),
                prec: ATOM,
                has_block,
            };
        }
        let locals: Vec<_> = (0..codes.len()).map(|i| format_ident!("arg{i}")).collect();
        let ts: Vec<&TokenStream> = codes.iter().map(|c| &c.ts).collect();
        Code {
            ts: quote!({ #(let #locals = #ts;)* self.hooks.#name(&self.data #(, #locals)*) }),
            prec: ATOM,
            has_block: true,
        }
    }

    pub fn place(&self, p: &Place) -> TokenStream {
        let (mut ts, mut ty) = self.place_root(p);
        for proj in &p.path {
            match (proj, &ty) {
                (Projection::Field(f), Type::Buffer(bt)) => {
                    let field = &self.names.buffers[bt.index()].fields[*f as usize];
                    ts = quote!(#ts.#field);
                    ty = self.ir.buffer_types[bt.index()].fields[*f as usize]
                        .ty
                        .clone();
                }
                (Projection::Index(i), Type::Array(elem, _)) => {
                    let i = proc_macro2::Literal::usize_unsuffixed(*i as usize);
                    ts = quote!(#ts[#i]);
                    ty = (**elem).clone();
                }
                _ => unreachable!("run-time indices are generated by `checked_assign`"),
            }
        }
        ts
    }

    /// A place's var or buffer, and its type.
    pub(super) fn place_root(&self, p: &Place) -> (TokenStream, Type) {
        let ts = match p.root {
            PlaceRoot::Var(v) => {
                let id = &self.cn().vars[v.index()];
                quote!(self.data.vars.#id)
            }
            PlaceRoot::Buffer(b) => {
                let id = self.cn().buffers[b.index()]
                    .as_ref()
                    .expect("buffer of this controller");
                quote!(self.data.writes.#id)
            }
        };
        let ty = match p.root {
            PlaceRoot::Var(v) => self.ctrl.vars[v.index()].ty.clone(),
            PlaceRoot::Buffer(b) => Type::Buffer(self.ir.buffers[b.index()].ty),
        };
        (ts, ty)
    }

    /// `place = place OP rhs` with an arithmetic OP: the operator and `rhs`.
    fn self_update<'e>(&self, place: &Place, value: &'e Expr) -> Option<(BinOp, &'e Expr)> {
        let ExprKind::Binary(
            op @ (BinOp::Add
            | BinOp::Sub
            | BinOp::Mul
            | BinOp::Div
            | BinOp::Rem
            | BinOp::BitAnd
            | BinOp::BitOr
            | BinOp::BitXor),
            operands,
        ) = &value.kind
        else {
            return None;
        };
        let [l, r] = &**operands;
        same_place(place, l).then_some((*op, r))
    }

    pub fn job(&self, j: &Job) -> TokenStream {
        if let Some(code) = self.checked_job(j) {
            return code;
        }
        match j {
            Job::Assign {
                place, op, value, ..
            } => {
                let target = self.place(place);
                let v = self.expr(value);
                let vt = &v.ts;
                match (op, &place.ty) {
                    // `x = x / k` on floats reads better (and passes clippy) as `x /= k`.
                    // So does `w = w | 0x80` on integers as `w |= 0x80`.
                    (AssignOp::Set, Type::Float(_) | Type::Int(_))
                        if self.self_update(place, value).is_some_and(|(op, _)| {
                            place.ty != Type::Bool
                                && (op.is_bitwise() || matches!(place.ty, Type::Float(_)))
                        }) =>
                    {
                        let (op, rhs) = self.self_update(place, value).expect("checked");
                        let rhs = self.expr(rhs).ts;
                        let op: TokenStream =
                            format!("{}=", op.symbol()).parse().expect("operator");
                        quote!(#target #op #rhs;)
                    }
                    (AssignOp::Set, _) => quote!(#target = #vt;),
                    (AssignOp::Add, Type::Int(_)) => quote!(#target = #target.wrapping_add(#vt);),
                    (AssignOp::Sub, Type::Int(_)) => quote!(#target = #target.wrapping_sub(#vt);),
                    (AssignOp::Add, _) => quote!(#target += #vt;),
                    (AssignOp::Sub, _) => quote!(#target -= #vt;),
                }
            }
            Job::Send {
                sub, command, args, ..
            } => {
                let vals: Vec<TokenStream> = args.iter().map(|a| self.expr(a).ts).collect();
                self.send(*sub, *command, &vals)
            }
            Job::Report {
                error: Some(code), ..
            } => {
                let c = &self.cn().error_consts[code.index()];
                quote!(self.bk.report_error(error::#c);)
            }
            Job::Report {
                error_of: Some(v), ..
            } => {
                let id = &self.cn().vars[v.index()];
                quote!(self.bk.report_error(self.data.vars.#id);)
            }
            Job::Report { status, .. } => {
                let c = &self.cn().status_consts[status.index()];
                quote!(self.bk.report(status::#c);)
            }
            Job::Call(e) => {
                let c = self.expr(e);
                let ts = &c.ts;
                quote!(#ts;)
            }
            Job::Forward { sub, commands, .. } => self.forward(*sub, commands),
        }
    }

    /// `sub`'s `command`, with `vals` in its parameter order, sent under a
    /// new serial.
    pub(super) fn send(
        &self,
        sub: CtrlId,
        command: CommandId,
        vals: &[TokenStream],
    ) -> TokenStream {
        let i = self.ctrl.subordinate_index(sub).expect("a subordinate");
        let field = prefixed("sub", &self.cn().subs[i]);
        let target = &self.names.ctrls[sub.index()];
        let module = &target.module;
        let variant = &target.commands[command.index()];
        if vals.is_empty() {
            quote!(self.#field.send(super::#module::Command::#variant);)
        } else {
            let params = &target.params[command.index()];
            quote!(self.#field.send(super::#module::Command::#variant { #(#params: #vals),* });)
        }
    }
}

/// Whether an expression reads exactly the given place.
fn same_place(place: &Place, e: &Expr) -> bool {
    let mut path = Vec::new();
    let mut cur = e;
    loop {
        match &cur.kind {
            ExprKind::Field(base, f) => {
                path.push(Projection::Field(*f));
                cur = base;
            }
            ExprKind::Index(base, i) => {
                path.push(Projection::Index(*i));
                cur = base;
            }
            ExprKind::Var(v) => {
                path.reverse();
                return place.root == PlaceRoot::Var(*v) && path == place.path;
            }
            ExprKind::Buffer(b) => {
                path.reverse();
                return place.root == PlaceRoot::Buffer(*b) && path == place.path;
            }
            _ => return false,
        }
    }
}

fn contains_call(e: &Expr) -> bool {
    let mut found = false;
    e.visit(&mut |x| found |= matches!(x.kind, ExprKind::Call(..)));
    found
}
