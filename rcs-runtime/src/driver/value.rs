//! The dynamic values that cross the driver interface ([`Value`]) and the
//! conversions of the generated types to and from them ([`ToValue`],
//! [`FromValue`]) for every plan type: scalars, statuses, error codes,
//! arrays (buffers and enums convert in generated code).

use crate::handshake::{ErrorCode, Status};
use serde::{Deserialize, Serialize};

/// A value of any plan type, as the interpreter computes it and as the
/// generated types convert to and from it ([`ToValue`], [`FromValue`]).
///
/// Integers hold every width (range is the type's business); `f32` values
/// are held as the `f64` of the same number.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Value {
    /// `bool`.
    Bool(bool),
    /// Any integer type.
    Int(i128),
    /// `f32` or `f64`.
    Float(f64),
    /// An enum variant by its declaration index.
    Enum(u32),
    /// A status code ([`Status`]).
    Status(u16),
    /// A buffer's fields in declaration order.
    Buffer(Vec<Value>),
    /// An array's elements.
    Array(Vec<Value>),
    /// No value (hooks returning nothing).
    Unit,
}

/// A typed value as a [`Value`].
pub trait ToValue {
    /// The dynamic value.
    fn to_value(&self) -> Value;
}

/// A typed value from a [`Value`]: `None` when the value has another shape
/// or is out of the type's range.
pub trait FromValue: Sized {
    /// The typed value.
    fn from_value(v: &Value) -> Option<Self>;
}

impl ToValue for bool {
    fn to_value(&self) -> Value {
        Value::Bool(*self)
    }
}

impl FromValue for bool {
    fn from_value(v: &Value) -> Option<Self> {
        match v {
            Value::Bool(b) => Some(*b),
            _ => None,
        }
    }
}

macro_rules! int_values {
    ($($t:ty),*) => {$(
        impl ToValue for $t {
            fn to_value(&self) -> Value {
                Value::Int(i128::from(*self))
            }
        }
        impl FromValue for $t {
            fn from_value(v: &Value) -> Option<Self> {
                match v {
                    Value::Int(i) => <$t>::try_from(*i).ok(),
                    _ => None,
                }
            }
        }
    )*};
}

int_values!(i8, i16, i32, i64, u8, u16, u32, u64);

impl ToValue for f64 {
    fn to_value(&self) -> Value {
        Value::Float(*self)
    }
}

impl FromValue for f64 {
    fn from_value(v: &Value) -> Option<Self> {
        match v {
            Value::Float(f) => Some(*f),
            _ => None,
        }
    }
}

impl ToValue for f32 {
    fn to_value(&self) -> Value {
        Value::Float(f64::from(*self))
    }
}

impl FromValue for f32 {
    /// Rounds to the nearest `f32`, as the generated arithmetic does.
    fn from_value(v: &Value) -> Option<Self> {
        match v {
            Value::Float(f) => Some(*f as f32),
            _ => None,
        }
    }
}

impl ToValue for Status {
    fn to_value(&self) -> Value {
        Value::Status(self.0)
    }
}

impl FromValue for Status {
    fn from_value(v: &Value) -> Option<Self> {
        match v {
            Value::Status(s) => Some(Status(*s)),
            _ => None,
        }
    }
}

/// An error code travels as its number (`rcs_dsl` gives it the name).
impl ToValue for ErrorCode {
    fn to_value(&self) -> Value {
        Value::Int(i128::from(self.0))
    }
}

impl FromValue for ErrorCode {
    fn from_value(v: &Value) -> Option<Self> {
        match v {
            Value::Int(n) => u16::try_from(*n).ok().map(ErrorCode),
            _ => None,
        }
    }
}

impl ToValue for () {
    fn to_value(&self) -> Value {
        Value::Unit
    }
}

impl FromValue for () {
    fn from_value(v: &Value) -> Option<Self> {
        matches!(v, Value::Unit).then_some(())
    }
}

impl<T: ToValue, const N: usize> ToValue for [T; N] {
    fn to_value(&self) -> Value {
        Value::Array(self.iter().map(ToValue::to_value).collect())
    }
}

impl<T: FromValue, const N: usize> FromValue for [T; N] {
    fn from_value(v: &Value) -> Option<Self> {
        let Value::Array(items) = v else {
            return None;
        };
        let items: Vec<T> = items.iter().map(T::from_value).collect::<Option<_>>()?;
        items.try_into().ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_refuse_values_out_of_their_range() {
        assert_eq!(u8::from_value(&Value::Int(255)), Some(255));
        assert_eq!(u8::from_value(&Value::Int(256)), None);
        assert_eq!(i8::from_value(&Value::Int(-129)), None);
        assert_eq!(i64::from_value(&Value::Float(1.0)), None);
    }

    #[test]
    fn arrays_round_trip_and_check_their_length() {
        let a = [1.5f32, -2.0, 0.25];
        let v = a.to_value();
        assert_eq!(<[f32; 3]>::from_value(&v), Some(a));
        assert_eq!(<[f32; 2]>::from_value(&v), None);
    }

    #[test]
    fn f32_values_round_to_f32() {
        assert_eq!(f32::from_value(&Value::Float(0.1)), Some(0.1f32));
        assert_eq!(0.1f32.to_value(), Value::Float(f64::from(0.1f32)));
    }
}
