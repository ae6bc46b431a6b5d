//! Executives driven from a program's own loop rather than
//! [`Executive::run`]: the split submarine's processes, say, run each
//! cycle from a main loop that also steps a simulator and prints. Pause,
//! single step and go (an [`ExecutiveHandle`](super::ExecutiveHandle),
//! a remote console's controls) and the heartbeat figures a console shows
//! work for them through these two calls.

use std::sync::atomic::Ordering;
use std::time::Duration;

use super::{nanos, Executive};
use crate::fault::CycleFault;

impl Executive {
    /// Run one cycle now unless an operator paused this executive through
    /// its [`ExecutiveHandle`](super::ExecutiveHandle) (a pending single
    /// step runs it, and is used up): for programs that drive their
    /// executives from a heartbeat loop of their own rather than
    /// [`run`](Self::run), so that pause / step / go work for them too.
    /// `Ok(false)`: paused, no cycle ran.
    pub fn step_unless_paused(&mut self) -> Result<bool, CycleFault> {
        if !self.may_run() {
            return Ok(false);
        }
        self.run_one();
        self.take_fault().map(|()| true)
    }

    /// Record a heartbeat of the program's own loop: how late it woke and
    /// how many it has missed so far (what [`Heartbeat::wait`] and
    /// [`Heartbeat::missed`] say), into the statistics, the monitor and
    /// the handle, as [`run`](Self::run) records its own. No lock, no
    /// allocation.
    ///
    /// [`Heartbeat::wait`]: crate::Heartbeat::wait
    /// [`Heartbeat::missed`]: crate::Heartbeat::missed
    pub fn note_heartbeat(&mut self, late: Duration, missed: u64) {
        self.stats.lateness_ns.record(nanos(late));
        self.stats.missed_heartbeats = missed;
        self.publish_executive();
        self.shared.missed.store(missed, Ordering::Release);
    }

    /// Whether the next heartbeat runs a cycle: not paused, or paused with
    /// a single step pending (which this call uses up).
    pub(super) fn may_run(&self) -> bool {
        let paused = self.shared.paused.load(Ordering::Acquire);
        !paused
            || self
                .shared
                .steps
                .fetch_update(Ordering::AcqRel, Ordering::Acquire, |s| s.checked_sub(1))
                .is_ok()
    }
}
