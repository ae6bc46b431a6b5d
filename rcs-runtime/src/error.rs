//! Setup errors: everything that can go wrong while a system is wired
//! together, before the first cycle. The cycle path itself has no errors to
//! return (it reports through status buffers and counters instead).

use thiserror::Error;

/// An error while setting up Global Memory or an executive.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum SetupError {
    /// A second writer handle was requested for a buffer (one writer only).
    #[error("buffer `{0}` already has a writer (one writer, many readers)")]
    WriterTaken(String),
    /// A reader or writer names a buffer that was never declared.
    #[error("unknown buffer `{0}`")]
    UnknownBuffer(String),
    /// A buffer is used with a type other than the one it was declared with.
    #[error("buffer `{name}` holds `{declared}`, not `{requested}`")]
    TypeMismatch {
        /// The buffer's name.
        name: String,
        /// The type it was declared with.
        declared: &'static str,
        /// The type that was asked for.
        requested: &'static str,
    },
    /// Two controllers of one executive share a name.
    #[error("controller `{0}` is already scheduled on executive `{1}`")]
    DuplicateController(String, String),
    /// An executive period of zero.
    #[error("executive `{0}` has a zero period")]
    ZeroPeriod(String),
    /// An executive period longer than [`MAX_PERIOD`](crate::exec::MAX_PERIOD).
    #[error("executive `{0}` has a period of {1:?}; the longest accepted is one hour")]
    PeriodTooLong(String, std::time::Duration),
    /// A heartbeat period of zero (every nanosecond would be a missed
    /// heartbeat) or above [`MAX_PERIOD`](crate::exec::MAX_PERIOD).
    #[error("a heartbeat period must be more than zero and at most one hour, not {0:?}")]
    HeartbeatPeriod(std::time::Duration),
    /// A controller was added to an executive that was never made.
    #[error("controller `{0}` is added to an executive that does not exist")]
    UnknownExecutive(String),
    /// Every error of a setup that met more than one
    /// ([`Setup::finish`](crate::Setup::finish)), in the order met.
    #[error("{}", several(.0))]
    Several(Vec<SetupError>),
}

/// "3 setup errors: A; B; C".
fn several(errors: &[SetupError]) -> String {
    let list: Vec<String> = errors.iter().map(ToString::to_string).collect();
    format!("{} setup errors: {}", errors.len(), list.join("; "))
}
