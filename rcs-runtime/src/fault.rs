//! Panics caught by the executive ([`crate::exec`]): what
//! [`Executive::step`](crate::Executive::step) and
//! [`Executive::run_cycles`](crate::Executive::run_cycles) return when a
//! controller's cycle panicked. Kept apart from the executive because it is
//! the error side of it, built only when something went wrong (it
//! allocates; the cycle path does not).

use std::any::Any;

/// One caught panic: which controller, in which cycle, with what message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ControllerPanic {
    /// The executive it runs on.
    pub executive: String,
    /// The controller's name.
    pub controller: String,
    /// The executive's cycle count when it panicked.
    pub cycle: u64,
    /// The panic's message (`"a panic without a message"` if it had none).
    pub message: String,
}

/// The panics caught while [`Executive::step`] or [`Executive::run_cycles`]
/// ran: every controller still ran its cycles (the faulty ones were ended
/// with `HOOK_PANIC`), but the caller should know.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CycleFault {
    /// The first panics, in the order they happened (at most
    /// [`CycleFault::LISTED`]).
    pub panics: Vec<ControllerPanic>,
    /// How many panics there were in all.
    pub total: u64,
}

impl CycleFault {
    /// How many panics a fault lists; the rest are only counted.
    pub const LISTED: usize = 16;

    pub(crate) fn record(&mut self, panic: ControllerPanic) {
        self.total = self.total.saturating_add(1);
        if self.panics.len() < Self::LISTED {
            self.panics.push(panic);
        }
    }

    /// Add `later`'s panics after these (e.g. those of the next executive
    /// of a system run cycle by cycle), keeping the list's bound.
    pub fn merge(&mut self, later: CycleFault) {
        let listed = later.panics.len() as u64;
        for p in later.panics {
            if self.panics.len() < Self::LISTED {
                self.panics.push(p);
            }
        }
        self.total = self.total.saturating_add(later.total.max(listed));
    }
}

impl std::fmt::Display for CycleFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (i, p) in self.panics.iter().enumerate() {
            if i > 0 {
                f.write_str("; ")?;
            }
            write!(
                f,
                "controller `{}` (executive `{}`) panicked in cycle {}: {}",
                p.controller, p.executive, p.cycle, p.message
            )?;
        }
        let more = self.total.saturating_sub(self.panics.len() as u64);
        if more > 0 {
            write!(f, " (and {more} more panics)")?;
        }
        Ok(())
    }
}

impl std::error::Error for CycleFault {}

/// The message of a panic payload.
pub(crate) fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic without a message".to_string()
    }
}
