//! The built-in functions of the language (`abs min max clamp` on any
//! numeric type; `sqrt sin … hypot` on floats; `is_nan`): their names,
//! arities and what they compute on run-time values. `lower` resolves a
//! call by name to a [`Builtin`] (the names are reserved), the reference
//! interpreter, the constant folder and the analysis's concrete evaluator
//! compute through [`apply`], and the code generator emits calls of the same
//! functions (`rcs_runtime::math` for floats, Rust's wrapping integer
//! methods for integers), so every backend agrees bit for bit.

use crate::arith::{round, wrap};
use crate::ir::Type;
use rcs_runtime::driver::Value;
use rcs_runtime::math;
use serde::Serialize;

/// A built-in function.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Builtin {
    Abs,
    Min,
    Max,
    Clamp,
    Sqrt,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Exp,
    Ln,
    Floor,
    Ceil,
    Round,
    Hypot,
    IsNan,
}

/// What arguments a built-in takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Signature {
    /// Arguments of one numeric type (integer or float); the result has it.
    Numeric,
    /// Arguments of one float type; the result has it.
    Float,
    /// One float argument; the result is `bool`.
    FloatPredicate,
}

impl Builtin {
    pub const ALL: [Builtin; 19] = [
        Builtin::Abs,
        Builtin::Min,
        Builtin::Max,
        Builtin::Clamp,
        Builtin::Sqrt,
        Builtin::Sin,
        Builtin::Cos,
        Builtin::Tan,
        Builtin::Asin,
        Builtin::Acos,
        Builtin::Atan,
        Builtin::Atan2,
        Builtin::Exp,
        Builtin::Ln,
        Builtin::Floor,
        Builtin::Ceil,
        Builtin::Round,
        Builtin::Hypot,
        Builtin::IsNan,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Builtin::Abs => "abs",
            Builtin::Min => "min",
            Builtin::Max => "max",
            Builtin::Clamp => "clamp",
            Builtin::Sqrt => "sqrt",
            Builtin::Sin => "sin",
            Builtin::Cos => "cos",
            Builtin::Tan => "tan",
            Builtin::Asin => "asin",
            Builtin::Acos => "acos",
            Builtin::Atan => "atan",
            Builtin::Atan2 => "atan2",
            Builtin::Exp => "exp",
            Builtin::Ln => "ln",
            Builtin::Floor => "floor",
            Builtin::Ceil => "ceil",
            Builtin::Round => "round",
            Builtin::Hypot => "hypot",
            Builtin::IsNan => "is_nan",
        }
    }

    pub fn from_name(name: &str) -> Option<Builtin> {
        Builtin::ALL.into_iter().find(|b| b.name() == name)
    }

    pub fn arity(self) -> usize {
        match self {
            Builtin::Min | Builtin::Max | Builtin::Atan2 | Builtin::Hypot => 2,
            Builtin::Clamp => 3,
            _ => 1,
        }
    }

    pub fn signature(self) -> Signature {
        match self {
            Builtin::Abs | Builtin::Min | Builtin::Max | Builtin::Clamp => Signature::Numeric,
            Builtin::IsNan => Signature::FloatPredicate,
            _ => Signature::Float,
        }
    }

    /// The float function of `rcs_runtime::math` it calls, by name (every
    /// built-in but `is_nan` has one).
    pub fn math_fn(self) -> &'static str {
        self.name()
    }
}

/// `b(args)` on run-time values; `ty` is the type of the arguments (all
/// arguments have one type). Integers: `abs` wraps (`abs(i8::MIN)` is
/// `i8::MIN`, as Rust's `wrapping_abs`), `clamp(x, lo, hi)` is
/// `max(min(x, hi), lo)`. Floats: [`rcs_runtime::math`], rounded to `f32`
/// for `f32` arguments.
pub fn apply(b: Builtin, args: &[Value], ty: &Type) -> Value {
    match ty {
        Type::Int(t) => {
            let ints: Vec<i128> = args
                .iter()
                .map(|a| match a {
                    Value::Int(i) => *i,
                    _ => 0,
                })
                .collect();
            let arg = |i: usize| ints.get(i).copied().unwrap_or(0);
            Value::Int(match b {
                Builtin::Abs => wrap(arg(0).abs(), *t),
                Builtin::Min => arg(0).min(arg(1)),
                Builtin::Max => arg(0).max(arg(1)),
                Builtin::Clamp => arg(0).min(arg(2)).max(arg(1)),
                // Float-only built-ins never get integer arguments (lower
                // refuses them).
                _ => arg(0),
            })
        }
        Type::Float(t) => {
            let floats: Vec<f64> = args
                .iter()
                .map(|a| match a {
                    Value::Float(f) => *f,
                    _ => f64::NAN,
                })
                .collect();
            let x = floats.first().copied().unwrap_or(f64::NAN);
            let y = floats.get(1).copied().unwrap_or(f64::NAN);
            let r = match b {
                Builtin::IsNan => return Value::Bool(x.is_nan()),
                Builtin::Abs => math::abs(x),
                Builtin::Min => math::min(x, y),
                Builtin::Max => math::max(x, y),
                Builtin::Clamp => math::clamp(x, y, floats.get(2).copied().unwrap_or(f64::NAN)),
                Builtin::Sqrt => math::sqrt(x),
                Builtin::Sin => math::sin(x),
                Builtin::Cos => math::cos(x),
                Builtin::Tan => math::tan(x),
                Builtin::Asin => math::asin(x),
                Builtin::Acos => math::acos(x),
                Builtin::Atan => math::atan(x),
                Builtin::Atan2 => math::atan2(x, y),
                Builtin::Exp => math::exp(x),
                Builtin::Ln => math::ln(x),
                Builtin::Floor => math::floor(x),
                Builtin::Ceil => math::ceil(x),
                Builtin::Round => math::round(x),
                Builtin::Hypot => math::hypot(x, y),
            };
            Value::Float(round(r, *t))
        }
        _ => Value::Unit,
    }
}

/// The built-in whose name is closest to `name` (for "did you mean"), if
/// any is close: at most two edits away.
pub fn closest(name: &str) -> Option<Builtin> {
    Builtin::ALL
        .into_iter()
        .map(|b| (edit_distance(name, b.name()), b))
        .filter(|(d, _)| *d <= 2)
        .min_by_key(|(d, _)| *d)
        .map(|(_, b)| b)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur.push(sub.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ir::{FloatTy, IntTy};

    #[test]
    fn integer_abs_of_min_wraps() {
        let t = Type::Int(IntTy::I8);
        assert_eq!(
            apply(Builtin::Abs, &[Value::Int(-128)], &t),
            Value::Int(-128)
        );
        assert_eq!(apply(Builtin::Abs, &[Value::Int(-5)], &t), Value::Int(5));
        assert_eq!(
            apply(
                Builtin::Clamp,
                &[Value::Int(9), Value::Int(3), Value::Int(1)],
                &t
            ),
            Value::Int(3)
        );
    }

    #[test]
    fn f32_results_are_rounded_and_nan_propagates() {
        let t = Type::Float(FloatTy::F32);
        let Value::Float(r) = apply(Builtin::Sin, &[Value::Float(1.0)], &t) else {
            panic!("a float")
        };
        assert_eq!(r, 1f64.sin() as f32 as f64);
        let f = Type::Float(FloatTy::F64);
        assert_eq!(
            apply(
                Builtin::IsNan,
                &[apply(Builtin::Sqrt, &[Value::Float(-1.0)], &f)],
                &f
            ),
            Value::Bool(true)
        );
    }

    #[test]
    fn did_you_mean() {
        assert_eq!(closest("sqr"), Some(Builtin::Sqrt));
        assert_eq!(closest("isnan"), Some(Builtin::IsNan));
        assert_eq!(closest("frobnicate"), None);
    }
}
