//! The interpreter's values by type: the zero every declaration starts
//! from, and a value from outside (a scenario, a driver) checked and
//! rounded to its declared type, as the generated code would hold it.

use super::round;
use crate::ir::*;
use rcs_runtime::driver::Value;

/// The zero value of a type: numbers 0, `false`, the first variant.
pub fn zero(ir: &Ir, t: &Type) -> Value {
    match t {
        Type::Bool => Value::Bool(false),
        Type::Int(_) => Value::Int(0),
        Type::Float(_) => Value::Float(0.0),
        Type::Enum(_) => Value::Enum(0),
        Type::Status(_) => Value::Status(0),
        // An error code is its runtime number; 0 is no error.
        Type::ErrorCode(_) => Value::Int(0),
        Type::Buffer(b) => Value::Buffer(
            ir.buffer_types[b.index()]
                .fields
                .iter()
                .map(|f| zero(ir, &f.ty))
                .collect(),
        ),
        Type::Array(e, n) => Value::Array(vec![zero(ir, e); *n as usize]),
        Type::Unit => Value::Unit,
    }
}

/// `v` as a value of type `t`, as the generated code would hold it (`f32`
/// rounded), or `None` when it has another shape or is out of range.
pub fn conform(ir: &Ir, t: &Type, v: &Value) -> Option<Value> {
    Some(match (t, v) {
        (Type::Bool, Value::Bool(b)) => Value::Bool(*b),
        (Type::Int(it), Value::Int(i)) => {
            let (lo, hi) = it.range();
            if *i < lo || *i > hi {
                return None;
            }
            Value::Int(*i)
        }
        (Type::Float(ft), Value::Float(f)) => Value::Float(round(*f, *ft)),
        (Type::Enum(e), Value::Enum(i)) if (*i as usize) < ir.enums[e.index()].variants.len() => {
            Value::Enum(*i)
        }
        (Type::Status(_), Value::Status(s)) => Value::Status(*s),
        // Only a code the controller has: none, a built-in or a declared one.
        (Type::ErrorCode(c), Value::Int(n)) => {
            let code = rcs_runtime::ErrorCode(u16::try_from(*n).ok()?);
            let declared = usize::from(code.0)
                .checked_sub(usize::from(rcs_runtime::ErrorCode::FIRST_CUSTOM))
                .is_some_and(|i| i < ir.controller(*c).errors.len());
            if !(code.is_none() || code.is_builtin() || declared) {
                return None;
            }
            Value::Int(*n)
        }
        (Type::Buffer(b), Value::Buffer(fs)) => {
            let bt = &ir.buffer_types[b.index()];
            if fs.len() != bt.fields.len() {
                return None;
            }
            Value::Buffer(
                bt.fields
                    .iter()
                    .zip(fs)
                    .map(|(f, x)| conform(ir, &f.ty, x))
                    .collect::<Option<_>>()?,
            )
        }
        (Type::Array(e, n), Value::Array(xs)) if xs.len() == *n as usize => Value::Array(
            xs.iter()
                .map(|x| conform(ir, e, x))
                .collect::<Option<_>>()?,
        ),
        (Type::Unit, Value::Unit) => Value::Unit,
        _ => return None,
    })
}
