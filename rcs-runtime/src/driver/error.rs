//! What a driven controller refuses ([`DriveError`]): an unknown name, a
//! value of another type, a verb with the wrong number of arguments; and
//! the helpers generated `from_parts` and drivers build them with.

use super::{FromValue, Value};
use serde::{Deserialize, Serialize};

/// A name or value the driven controller does not accept.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum DriveError {
    /// The controller has nothing of this kind with this name.
    #[error("`{controller}` has no {kind} `{name}`")]
    Unknown {
        /// The controller.
        controller: String,
        /// `verb`, `read buffer`, `hook` or `subordinate`.
        kind: String,
        /// The name asked for.
        name: String,
    },
    /// A value of the wrong shape or range.
    #[error("`{controller}`: {what}: a value of another type")]
    Type {
        /// The controller.
        controller: String,
        /// What the value was for (`AHEAD.speed`, `ship`, …).
        what: String,
    },
    /// A verb given the wrong number of arguments.
    #[error("`{controller}`: {verb} takes {expected} argument(s), got {got}")]
    Arity {
        /// The controller.
        controller: String,
        /// The verb.
        verb: String,
        /// Its parameter count.
        expected: usize,
        /// The count given.
        got: usize,
    },
}

impl DriveError {
    /// The same error, for controller `name`: a command type shared by the
    /// instances of a controller type names the type; the instance's
    /// driver names the instance.
    pub fn for_controller(mut self, name: &str) -> DriveError {
        match &mut self {
            DriveError::Unknown { controller, .. }
            | DriveError::Type { controller, .. }
            | DriveError::Arity { controller, .. } => *controller = name.to_string(),
        }
        self
    }
}

/// The `index`-th argument of `verb`, typed. For generated `from_parts`.
pub fn arg<T: FromValue>(
    controller: &str,
    verb: &str,
    param: &str,
    args: &[Value],
    index: usize,
) -> Result<T, DriveError> {
    args.get(index)
        .and_then(T::from_value)
        .ok_or_else(|| DriveError::Type {
            controller: controller.to_string(),
            what: format!("{verb}.{param}"),
        })
}

/// `verb` must have exactly `expected` arguments. For generated `from_parts`.
pub fn arity(
    controller: &str,
    verb: &str,
    args: &[Value],
    expected: usize,
) -> Result<(), DriveError> {
    if args.len() == expected {
        Ok(())
    } else {
        Err(DriveError::Arity {
            controller: controller.to_string(),
            verb: verb.to_string(),
            expected,
            got: args.len(),
        })
    }
}

/// `name` is not one of `controller`'s `kind`s.
pub fn unknown(controller: &str, kind: &str, name: &str) -> DriveError {
    DriveError::Unknown {
        controller: controller.to_string(),
        kind: kind.to_string(),
        name: name.to_string(),
    }
}

/// `value` typed for `what`, or a [`DriveError::Type`].
pub fn typed<T: FromValue>(controller: &str, what: &str, value: &Value) -> Result<T, DriveError> {
    T::from_value(value).ok_or_else(|| DriveError::Type {
        controller: controller.to_string(),
        what: what.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_controller_and_the_name() {
        assert_eq!(
            unknown("PR", "hook", "nope").to_string(),
            "`PR` has no hook `nope`"
        );
        let e = arity("PR", "AHEAD", &[], 1).unwrap_err();
        assert_eq!(e.to_string(), "`PR`: AHEAD takes 1 argument(s), got 0");
        let e = arg::<f64>("PR", "AHEAD", "speed", &[Value::Bool(true)], 0).unwrap_err();
        assert_eq!(e.to_string(), "`PR`: AHEAD.speed: a value of another type");
    }
}
