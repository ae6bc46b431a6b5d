//! The arithmetic of the language, written once: what each operator, cast
//! and comparison does to run-time values — integers wrap at their declared
//! width, `/` and `%` by zero (or `MIN / -1`) give 0, `f32` results are
//! rounded to `f32`, float-to-integer `as` saturates (NaN gives 0), and a
//! comparison involving NaN is false. The reference interpreter and the
//! analysis of conditions both evaluate through these functions; the code
//! generator emits the same rules as Rust.

use crate::ast::{BinOp, UnOp};
use crate::ir::{FloatTy, IntTy, Type};
use rcs_runtime::driver::Value;

/// An integer wrapped into the range of its type (keeps the low bits).
pub fn wrap(v: i128, t: IntTy) -> i128 {
    let bits = match t {
        IntTy::I8 | IntTy::U8 => 8,
        IntTy::I16 | IntTy::U16 => 16,
        IntTy::I32 | IntTy::U32 => 32,
        IntTy::I64 | IntTy::U64 => 64,
    };
    let masked = (v as u128) & ((1u128 << bits) - 1);
    if t.signed() && masked >> (bits - 1) == 1 {
        masked as i128 - (1i128 << bits)
    } else {
        masked as i128
    }
}

/// A float as its type holds it (`f32` values are carried as `f64`).
pub fn round(v: f64, t: FloatTy) -> f64 {
    match t {
        FloatTy::F32 => v as f32 as f64,
        FloatTy::F64 => v,
    }
}

/// Rust's `as` from a float to an integer: truncate, saturate, NaN → 0.
pub fn float_to_int(v: f64, t: IntTy) -> i128 {
    if v.is_nan() {
        return 0;
    }
    let (lo, hi) = t.range();
    let t = v.trunc();
    if t <= lo as f64 {
        lo
    } else if t >= hi as f64 {
        hi
    } else {
        t as i128
    }
}

/// Integer division or remainder with Rust's checked semantics at width `t`.
pub fn checked(x: i128, y: i128, t: IntTy, f: fn(i128, i128) -> Option<i128>) -> i128 {
    let (lo, _) = t.range();
    if y == 0 || (t.signed() && x == lo && y == -1) {
        return 0;
    }
    f(x, y).unwrap_or(0)
}

/// A float literal's value in its type.
pub fn float_literal(v: f64, ty: &Type) -> f64 {
    match ty {
        Type::Float(t) => round(v, *t),
        _ => v,
    }
}

/// `x & y`, `x | y`, `x ^ y`, `x << y`, `x >> y` for `x` (and, but for
/// shifts, `y`) of type `t`. A shift by the type's width or more, or by a
/// negative amount, gives 0, never a panic (the generated code's
/// `checked_shl(..).unwrap_or(0)`); `>>` of a signed value is arithmetic.
pub fn bitwise(op: BinOp, x: i128, y: i128, t: IntTy) -> i128 {
    let bits = match t {
        IntTy::I8 | IntTy::U8 => 8,
        IntTy::I16 | IntTy::U16 => 16,
        IntTy::I32 | IntTy::U32 => 32,
        IntTy::I64 | IntTy::U64 => 64,
    };
    match op {
        BinOp::BitAnd => wrap(x & y, t),
        BinOp::BitOr => wrap(x | y, t),
        BinOp::BitXor => wrap(x ^ y, t),
        BinOp::Shl if (0..bits).contains(&y) => wrap(((x as u128) << y) as i128, t),
        BinOp::Shr if (0..bits).contains(&y) => wrap(x >> y, t),
        _ => 0,
    }
}

/// `!x` or `-x`, the result of type `ty`.
pub fn unary(op: UnOp, v: Value, ty: &Type) -> Value {
    match (op, v, ty) {
        (UnOp::Not, Value::Bool(b), _) => Value::Bool(!b),
        // Bitwise not, in the value's type.
        (UnOp::Not, Value::Int(i), Type::Int(t)) => Value::Int(wrap(!i, *t)),
        (UnOp::Neg, Value::Int(i), Type::Int(t)) => Value::Int(wrap(i.wrapping_neg(), *t)),
        (UnOp::Neg, Value::Float(f), _) => Value::Float(-f),
        (_, v, _) => v,
    }
}

/// `v as ty`.
pub fn cast(v: Value, ty: &Type) -> Value {
    match (v, ty) {
        (Value::Int(i), Type::Int(t)) => Value::Int(wrap(i, *t)),
        (Value::Int(i), Type::Float(t)) => Value::Float(round(i as f64, *t)),
        (Value::Float(f), Type::Int(t)) => Value::Int(float_to_int(f, *t)),
        (Value::Float(f), Type::Float(t)) => Value::Float(round(f, *t)),
        (v, _) => v,
    }
}

/// A binary operator other than `&&` and `||` (which short-circuit, so
/// their evaluator decides), the result of type `ty`.
pub fn binary(op: BinOp, a: Value, b: Value, ty: &Type) -> Value {
    match op {
        BinOp::Eq => Value::Bool(a == b),
        BinOp::Ne => Value::Bool(a != b),
        BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => {
            let ord = match (&a, &b) {
                (Value::Int(x), Value::Int(y)) => x.partial_cmp(y),
                (Value::Float(x), Value::Float(y)) => x.partial_cmp(y),
                _ => None,
            };
            Value::Bool(match (op, ord) {
                (_, None) => false,
                (BinOp::Lt, Some(o)) => o.is_lt(),
                (BinOp::Le, Some(o)) => o.is_le(),
                (BinOp::Gt, Some(o)) => o.is_gt(),
                (_, Some(o)) => o.is_ge(),
            })
        }
        BinOp::And => Value::Bool(truthy(&a) && truthy(&b)),
        BinOp::Or => Value::Bool(truthy(&a) || truthy(&b)),
        BinOp::BitAnd | BinOp::BitOr | BinOp::BitXor | BinOp::Shl | BinOp::Shr => {
            match (a, b, ty) {
                (Value::Int(x), Value::Int(y), Type::Int(t)) => Value::Int(bitwise(op, x, y, *t)),
                (a, _, _) => a,
            }
        }
        _ => match (a, b, ty) {
            (Value::Int(x), Value::Int(y), Type::Int(t)) => Value::Int(wrap(
                match op {
                    BinOp::Add => x.wrapping_add(y),
                    BinOp::Sub => x.wrapping_sub(y),
                    BinOp::Mul => x.wrapping_mul(y),
                    // The generated code's `checked_div(..).unwrap_or(0)`:
                    // zero for a zero divisor and for `MIN / -1`.
                    BinOp::Div => checked(x, y, *t, i128::checked_div),
                    _ => checked(x, y, *t, i128::checked_rem),
                },
                *t,
            )),
            (Value::Float(x), Value::Float(y), Type::Float(t)) => Value::Float(round(
                match op {
                    BinOp::Add => x + y,
                    BinOp::Sub => x - y,
                    BinOp::Mul => x * y,
                    BinOp::Div => x / y,
                    _ => x % y,
                },
                *t,
            )),
            (a, _, _) => a,
        },
    }
}

/// Whether a value is `true`.
pub fn truthy(v: &Value) -> bool {
    matches!(v, Value::Bool(true))
}
