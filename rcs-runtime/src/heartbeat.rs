//! The executive's clock ([`crate::exec`]): absolute deadlines at a fixed
//! period, and how to wait for them. Apart from the executive because
//! simulations step it themselves (the submarine example runs the cycles and
//! the plant between heartbeats on one thread).

use std::time::{Duration, Instant};

use crate::error::SetupError;

/// How the executive waits for the next deadline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wait {
    /// Sleep until the deadline (the OS decides how late it wakes up).
    Sleep,
    /// Sleep until `spin` before the deadline, then spin on the clock.
    SleepSpin(Duration),
    /// Spin on the clock the whole time (burns the core).
    Spin,
}

impl Default for Wait {
    fn default() -> Self {
        Wait::SleepSpin(Duration::from_micros(200))
    }
}

/// The longest heartbeat period an executive accepts: an hour. Deadlines
/// are instants `start + k × period`; a bound keeps that arithmetic far from
/// overflow however long the system runs, and no RCS level plans slower.
pub const MAX_PERIOD: Duration = Duration::from_secs(3600);

/// A periodic clock with absolute deadlines: deadline `k` is `start + k ×
/// period`, so lateness does not accumulate. Deadlines that have already
/// passed when a wait begins are *missed*: they are skipped (counted in
/// [`missed`](Self::missed)), and the schedule restarts from now.
#[derive(Debug, Clone)]
pub struct Heartbeat {
    period: Duration,
    wait: Wait,
    next: Option<Instant>,
    missed: u64,
}

impl Heartbeat {
    /// A heartbeat of `period`, waiting with `wait`. A zero period (which
    /// would count every nanosecond as a missed heartbeat) or one above
    /// [`MAX_PERIOD`] is refused.
    pub fn new(period: Duration, wait: Wait) -> Result<Self, SetupError> {
        if period.is_zero() || period > MAX_PERIOD {
            return Err(SetupError::HeartbeatPeriod(period));
        }
        Ok(Self {
            period,
            wait,
            next: None,
            missed: 0,
        })
    }

    /// Deadlines skipped so far because a cycle (or the machine) ran past
    /// them: a cycle that overran by three periods misses two heartbeats.
    pub fn missed(&self) -> u64 {
        self.missed
    }

    /// Start the schedule: the first deadline is one period after `now`.
    pub fn start(&mut self, now: Instant) {
        self.next = Some(now + self.period);
    }

    /// Wait for the next deadline and return how late it woke (zero or
    /// more). Starts the schedule if [`start`](Self::start) was not called.
    pub fn wait(&mut self) -> Duration {
        let deadline = match self.next {
            Some(d) => d,
            None => {
                let d = Instant::now() + self.period;
                self.next = Some(d);
                d
            }
        };
        let spin = match self.wait {
            Wait::Sleep => Duration::ZERO,
            Wait::SleepSpin(s) => s,
            Wait::Spin => self.period,
        };
        let now = Instant::now();
        if let Some(left) = deadline.checked_duration_since(now) {
            if left > spin {
                std::thread::sleep(left - spin);
            }
        }
        let mut woke = Instant::now();
        while woke < deadline {
            std::hint::spin_loop();
            woke = Instant::now();
        }
        let mut next = deadline + self.period;
        if next <= woke {
            // Every deadline in (deadline, woke] was missed.
            let behind = woke.saturating_duration_since(deadline).as_nanos();
            let missed = behind / self.period.as_nanos().max(1);
            self.missed = self
                .missed
                .saturating_add(u64::try_from(missed).unwrap_or(u64::MAX));
            next = woke + self.period;
        }
        self.next = Some(next);
        woke.saturating_duration_since(deadline)
    }

    /// The period.
    pub fn period(&self) -> Duration {
        self.period
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_zero_or_absurd_heartbeat_period_is_refused() {
        for period in [
            Duration::ZERO,
            MAX_PERIOD + Duration::from_nanos(1),
            Duration::MAX,
        ] {
            let hb = Heartbeat::new(period, Wait::Sleep);
            assert_eq!(hb.err(), Some(SetupError::HeartbeatPeriod(period)));
        }
        let shortest = Duration::from_nanos(1);
        for period in [shortest, MAX_PERIOD] {
            assert_eq!(
                Heartbeat::new(period, Wait::Sleep).map(|h| h.period()),
                Ok(period)
            );
        }
    }

    #[test]
    fn deadlines_already_past_are_counted_as_missed() -> Result<(), SetupError> {
        // Started 50 ms ago with a 1 ms period: the first deadline is 49 ms
        // past when the wait begins, and every deadline up to now is missed.
        let period = Duration::from_millis(1);
        let mut hb = Heartbeat::new(period, Wait::Sleep)?;
        let Some(start) = Instant::now().checked_sub(Duration::from_millis(50)) else {
            return Ok(());
        };
        hb.start(start);
        hb.wait();
        assert!(hb.missed() >= 48, "missed {}", hb.missed());
        Ok(())
    }

    #[test]
    fn heartbeat_deadlines_are_absolute() -> Result<(), SetupError> {
        for wait in [Wait::Sleep, Wait::default(), Wait::Spin] {
            let period = Duration::from_millis(2);
            let mut hb = Heartbeat::new(period, wait)?;
            let start = Instant::now();
            hb.start(start);
            for _ in 0..10 {
                let _late = hb.wait();
            }
            // Never early: the 10th deadline is 10 periods after the start.
            assert!(start.elapsed() >= period * 10, "{wait:?}");
            assert_eq!(hb.period(), period);
        }
        Ok(())
    }

    #[test]
    fn heartbeat_skips_missed_deadlines() -> Result<(), SetupError> {
        let period = Duration::from_millis(1);
        let mut hb = Heartbeat::new(period, Wait::Sleep)?;
        let start = Instant::now();
        hb.start(start);
        std::thread::sleep(Duration::from_millis(5));
        let late = hb.wait();
        let after = Instant::now();
        assert!(late >= Duration::from_millis(3));
        // The schedule restarted from the wake-up, one period on: not the
        // missed deadlines (start + 2 ms, + 3 ms, …) to catch up on. Checked
        // on the schedule itself, not on how long a wait took.
        let next = hb.next.expect("started");
        assert!(
            next > start + Duration::from_millis(5),
            "{:?}",
            next - start
        );
        assert!(next <= after + period, "{:?}", next - start);
        Ok(())
    }
}
