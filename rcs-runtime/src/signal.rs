//! A wake-up call from the cycle path to a thread off it.
//!
//! Where it sits: between an [`Executive`](crate::Executive) and whoever
//! must act soon after a cycle's writes are done without polling for them —
//! the Zenoh bridge's export thread (feature `zenoh`), which publishes the
//! buffers whose generation changed. The executive [raises](CycleSignal::raise)
//! the signal at the end of every cycle; the waiting thread
//! [waits](CycleSignal::wait) on it with a timeout.
//!
//! Raising is what the cycle path may do: one atomic swap and, only when the
//! signal was not already raised, [`Thread::unpark`] (a futex wake on
//! Linux). No lock, no allocation. Raises that come while the waiter is busy
//! coalesce into one wake-up: the waiter looks at *everything* that changed
//! when it wakes, so nothing is lost.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};
use std::thread::Thread;
use std::time::{Duration, Instant};

#[derive(Debug, Default)]
struct Inner {
    raised: AtomicBool,
    /// The thread that waits: the first one that called `wait`.
    waiter: OnceLock<Thread>,
}

/// A shared "something was written" flag plus the thread to wake. Clones
/// share it. See the module docs.
#[derive(Debug, Clone, Default)]
pub struct CycleSignal {
    inner: Arc<Inner>,
}

impl CycleSignal {
    /// A signal nobody waits on yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Tell the waiter that new values are there. Lock-free and
    /// allocation-free: safe on the cycle path. Does nothing more while the
    /// waiter has not yet taken an earlier raise.
    #[inline]
    pub fn raise(&self) {
        // Release: the writes before the raise are visible to the waiter
        // once it takes the signal (Acquire).
        if !self.inner.raised.swap(true, Ordering::AcqRel) {
            if let Some(t) = self.inner.waiter.get() {
                t.unpark();
            }
        }
    }

    /// Take the signal: whether it was raised since the last take.
    pub fn take(&self) -> bool {
        self.inner.raised.swap(false, Ordering::AcqRel)
    }

    /// Wait until the signal is raised or `timeout` passes, then take it:
    /// true if it was raised. Only one thread waits on a signal: the first
    /// thread that calls `wait` is the one that raises wake; another thread that
    /// calls it just sleeps out its timeout (or returns at once if raised).
    pub fn wait(&self, timeout: Duration) -> bool {
        let me = std::thread::current();
        let waiter = self.inner.waiter.get_or_init(|| me.clone());
        if waiter.id() != me.id() {
            if self.take() {
                return true;
            }
            std::thread::sleep(timeout);
            return self.take();
        }
        // A raise between this check and `park_timeout` leaves the thread's
        // park token set, so the park returns at once: no lost wake-up.
        // Parks return early spuriously too: wait out the rest.
        let start = Instant::now();
        loop {
            if self.take() {
                return true;
            }
            let elapsed = start.elapsed();
            if elapsed >= timeout {
                return false;
            }
            std::thread::park_timeout(timeout - elapsed);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_raise_before_the_wait_is_kept() {
        let s = CycleSignal::new();
        s.raise();
        s.raise(); // coalesces
        assert!(s.wait(Duration::from_secs(3600)));
        assert!(!s.take(), "taken by the wait");
        assert!(!s.wait(Duration::ZERO));
    }

    #[test]
    fn a_raise_from_another_thread_wakes_the_waiter() {
        let s = CycleSignal::new();
        // Register this thread as the waiter before the other raises: an
        // hour-long wait can only end through the raise.
        assert!(!s.wait(Duration::ZERO));
        let raiser = {
            let s = s.clone();
            std::thread::spawn(move || {
                std::thread::sleep(Duration::from_millis(20));
                s.raise();
            })
        };
        assert!(s.wait(Duration::from_secs(3600)));
        raiser.join().expect("raiser");
    }

    #[test]
    fn a_second_thread_waiting_only_sees_the_flag() {
        let s = CycleSignal::new();
        assert!(!s.wait(Duration::ZERO)); // this thread is the waiter
        let other = {
            let s = s.clone();
            std::thread::spawn(move || {
                let first = s.wait(Duration::from_millis(1));
                s.raise();
                (first, s.wait(Duration::from_secs(3600)))
            })
        };
        assert_eq!(other.join().expect("other"), (false, true));
    }
}
