//! The statuses and error codes every generated controller has, as the
//! typed items a controller module exports (`status`, `error`, [`Status`],
//! [`Error`]). A controller that declares no status, no error code and no
//! refusable verb re-exports these instead of generating its own copies, so
//! that a plan set of many such controllers does not compile the same
//! conversions once per controller (issue 30). A controller with codes of
//! its own gets generated items with the same names and methods. The same
//! holds for an empty record ([`NoFields`]) and the name tables' lookups.

use crate::handshake::{ErrorCode, Status as RawStatus};

/// The built-in statuses as runtime values.
pub mod status {
    use crate::handshake::Status;
    /// No command yet.
    pub const NOT_READY: Status = Status::NOT_READY;
    /// A plan is running.
    pub const EXECUTING: Status = Status::EXECUTING;
    /// The plan ended in `Done`.
    pub const DONE: Status = Status::DONE;
    /// The plan ended in `Error`.
    pub const ERROR: Status = Status::ERROR;
}

/// The built-in error codes as runtime values.
pub mod error {
    use crate::handshake::ErrorCode;
    /// No error.
    pub const NONE: ErrorCode = ErrorCode::NONE;
    /// A command whose verb has no plan (only from an outside writer).
    pub const UNKNOWN_COMMAND: ErrorCode = ErrorCode::UNKNOWN_COMMAND;
    /// An index by a run-time value outside its array (the cycle ended the plan).
    pub const INDEX_RANGE: ErrorCode = ErrorCode::INDEX_RANGE;
    /// A hook panicked; the executive caught it and ended the plan.
    pub const HOOK_PANIC: ErrorCode = ErrorCode::HOOK_PANIC;
}

/// A status of a controller that has only the built-in ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// No command yet.
    NotReady,
    /// A plan is running.
    Executing,
    /// The plan ended in `Done`.
    Done,
    /// The plan ended in `Error`.
    Error,
}

impl Status {
    /// The typed status of a runtime value, if it is a built-in one.
    pub const fn from_raw(raw: RawStatus) -> Option<Self> {
        match raw {
            status::NOT_READY => Some(Self::NotReady),
            status::EXECUTING => Some(Self::Executing),
            status::DONE => Some(Self::Done),
            status::ERROR => Some(Self::Error),
            _ => None,
        }
    }

    /// The runtime value.
    pub const fn raw(self) -> RawStatus {
        match self {
            Self::NotReady => status::NOT_READY,
            Self::Executing => status::EXECUTING,
            Self::Done => status::DONE,
            Self::Error => status::ERROR,
        }
    }

    /// The name as written in the plans.
    pub const fn name(self) -> &'static str {
        match self {
            Self::NotReady => "NOT_READY",
            Self::Executing => "EXECUTING",
            Self::Done => "DONE",
            Self::Error => "ERROR",
        }
    }
}

/// An error code of a controller that has only the built-in ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error {
    /// A command whose verb has no plan (only from an outside writer).
    UnknownCommand,
    /// An index by a run-time value outside its array.
    IndexRange,
    /// A hook panicked.
    HookPanic,
}

impl Error {
    /// The typed error of a runtime code (`None` for no error).
    pub const fn from_raw(raw: ErrorCode) -> Option<Self> {
        match raw {
            error::UNKNOWN_COMMAND => Some(Self::UnknownCommand),
            error::INDEX_RANGE => Some(Self::IndexRange),
            error::HOOK_PANIC => Some(Self::HookPanic),
            _ => None,
        }
    }

    /// The runtime code.
    pub const fn raw(self) -> ErrorCode {
        match self {
            Self::UnknownCommand => error::UNKNOWN_COMMAND,
            Self::IndexRange => error::INDEX_RANGE,
            Self::HookPanic => error::HOOK_PANIC,
        }
    }

    /// The name as written in the plans.
    pub const fn name(self) -> &'static str {
        match self {
            Self::UnknownCommand => "UNKNOWN_COMMAND",
            Self::IndexRange => "INDEX_RANGE",
            Self::HookPanic => "HOOK_PANIC",
        }
    }
}

/// What a controller's `Reads`, `Writes` or `Subs` is when it has none:
/// one type with its derives compiled once, instead of an empty struct
/// and five derived impls per controller. `Writes {}` still builds one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoFields {}

/// Entry `i` of a generated table of names (verbs, or the states of one
/// plan), `None` past its end: what a controller's `verb_name` and
/// `state_name` look up, one function for every controller.
pub const fn name_at(names: &[&'static str], i: u16) -> Option<&'static str> {
    let i = i as usize;
    if i < names.len() {
        Some(names[i])
    } else {
        None
    }
}

/// The name of state `state` of the plan of verb `verb`, from a
/// controller's table of each verb's state names (empty for a verb
/// without a plan).
pub const fn state_name_at(
    plans: &[&[&'static str]],
    verb: u16,
    state: u16,
) -> Option<&'static str> {
    let verb = verb as usize;
    if verb < plans.len() {
        name_at(plans[verb], state)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_codes_convert_both_ways_and_keep_their_names() {
        for s in [
            Status::NotReady,
            Status::Executing,
            Status::Done,
            Status::Error,
        ] {
            assert_eq!(Status::from_raw(s.raw()), Some(s));
        }
        assert_eq!(Status::from_raw(RawStatus::custom(0)), None);
        assert_eq!(Status::Done.name(), "DONE");
        for e in [Error::UnknownCommand, Error::IndexRange, Error::HookPanic] {
            assert_eq!(Error::from_raw(e.raw()), Some(e));
        }
        assert_eq!(Error::from_raw(ErrorCode::NONE), None);
        assert_eq!(Error::from_raw(ErrorCode::REFUSED), None);
        assert_eq!(Error::from_raw(ErrorCode::custom(0)), None);
        assert_eq!(Error::HookPanic.name(), "HOOK_PANIC");
    }

    #[test]
    fn name_tables_answer_none_past_their_ends() {
        const PLANS: [&[&str]; 2] = [&["S0", "S1"], &[]];
        assert_eq!(name_at(&["A", "B"], 1), Some("B"));
        assert_eq!(name_at(&["A", "B"], 2), None);
        assert_eq!(state_name_at(&PLANS, 0, 1), Some("S1"));
        assert_eq!(state_name_at(&PLANS, 0, 2), None);
        assert_eq!(state_name_at(&PLANS, 1, 0), None);
        assert_eq!(state_name_at(&PLANS, 2, 0), None);
        assert_eq!(state_name_at(&PLANS, u16::MAX, u16::MAX), None);
    }
}
