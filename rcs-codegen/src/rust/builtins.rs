//! Built-in function calls → Rust, inside a controller module. Integers
//! use Rust's own non-panicking methods (`wrapping_abs`, `min`, `max`) and
//! `rcs_runtime::math::clamp_int` (`x.min(hi).max(lo)`, which never panics,
//! unlike `Ord::clamp`); floats call `rcs_runtime::math`, the functions the
//! interpreter calls too, on `f64` — an `f32` argument is widened with
//! `f64::from` and the result narrowed with `as f32`, exactly as the
//! interpreter carries `f32` values — so both backends agree bit for bit.

use super::expr::Code;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use rcs_dsl::builtin::Builtin;
use rcs_dsl::ir::{FloatTy, Type};

/// `b(args)` with arguments of type `ty`.
pub(crate) fn call(b: Builtin, ty: &Type, args: &[Code]) -> Code {
    let has_block = args.iter().any(|c| c.has_block);
    let atom = |ts: TokenStream| Code::new(ts, Code::ATOM, has_block);
    let recv = args.first().map(|c| c.at(Code::ATOM)).unwrap_or_default();
    let arg = |i: usize| args.get(i).map(|c| c.ts.clone()).unwrap_or_default();
    match ty {
        Type::Int(it) => match b {
            Builtin::Abs if it.signed() => atom(quote!(#recv.wrapping_abs())),
            Builtin::Min | Builtin::Max => {
                let m = format_ident!("{}", b.name());
                let other = arg(1);
                atom(quote!(#recv.#m(#other)))
            }
            Builtin::Clamp => {
                let (x, lo, hi) = (arg(0), arg(1), arg(2));
                atom(quote!(rt::math::clamp_int(#x, #lo, #hi)))
            }
            // `abs` of an unsigned value is the value.
            _ => match args.first() {
                Some(c) => Code::new(c.ts.clone(), c.prec, c.has_block),
                None => atom(quote!(0)),
            },
        },
        Type::Float(ft) => {
            if b == Builtin::IsNan {
                return atom(quote!(#recv.is_nan()));
            }
            let f = format_ident!("{}", b.math_fn());
            let widened: Vec<TokenStream> = args
                .iter()
                .map(|c| match ft {
                    FloatTy::F32 => {
                        let ts = &c.ts;
                        quote!(f64::from(#ts))
                    }
                    FloatTy::F64 => c.ts.clone(),
                })
                .collect();
            let call = quote!(rt::math::#f(#(#widened),*));
            match ft {
                FloatTy::F32 => Code::new(quote!(#call as f32), Code::CAST, has_block),
                FloatTy::F64 => atom(call),
            }
        }
        _ => atom(quote!(())),
    }
}
