//! The executive's cycle clock: per-controller execution times from the
//! CPU's time-stamp counter instead of the operating system's clock.
//!
//! The [`Executive`](crate::Executive) times every controller of every
//! cycle when measuring is on (§5.3.3's execution-time statistics). One
//! `Instant::now()` per controller cost 26–45 ns on the project's VM, four
//! times the rest of the executive's per-controller work; a TSC read costs
//! about 10 ns. So the per-controller reads go through [`CycleClock`], which
//! reads a [`quanta::Clock`]'s raw counter and scales differences to
//! nanoseconds.
//!
//! # Where the TSC is used, and where not
//!
//! `quanta` decides once, when the first clock is made (here:
//! [`CycleClock::new`], called by `Executive::new`), from CPUID, not at
//! compile time:
//!
//! * x86_64 with an **invariant TSC and `RDTSCP`** (CPUID leaf 0x8000_0007
//!   bit 8 and leaf 0x8000_0001): the counter is `RDTSC`. Invariant means
//!   it ticks at a constant rate across frequency changes and sleep states,
//!   so differences scale to nanoseconds with one factor. `quanta`
//!   calibrates that factor against `CLOCK_MONOTONIC` once per process
//!   (at least 500 rounds of 1 µs, at most 200 ms) and stores it as a
//!   multiply and a shift.
//! * aarch64 (not iOS): the generic timer's virtual count, `CNTVCT_EL0`.
//! * Anything else (no invariant TSC, e.g. some older or virtualised
//!   CPUs, 32-bit targets, wasm): the OS monotonic clock
//!   (`clock_gettime(CLOCK_MONOTONIC)` on Unix), which is what
//!   `std::time::Instant` reads — so the figures stay right, only the
//!   saving is lost.
//!
//! The calibration is global: the first executive made with measuring on
//! pays it, later ones reuse it. A difference is never negative: a raw
//! count at or below the previous one (the thread moved to a core whose
//! counter is behind) counts as 0 ns.
//!
//! # What stays on `std::time::Instant`
//!
//! [`CycleContext::now`](crate::CycleContext::now) stays a
//! `std::time::Instant`: plan timeouts and the bookkeeping compare it with
//! other `Instant`s. The executive reads `Instant::now()` once at the start
//! of each cycle and gives every controller that instant plus the TSC time
//! elapsed since, so a controller still sees when its own turn began, and
//! the TSC's calibration error cannot accumulate past one cycle. The
//! heartbeat ([`crate::Heartbeat`]) sleeps until absolute deadlines, which
//! the OS can only take as `Instant`s, and runs once per cycle, so it keeps
//! `Instant` too.

use std::time::{Duration, Instant};

/// A calibrated counter for timing the controllers of one cycle: a start
/// mark, then the nanoseconds since that mark at each controller's end.
/// Reading it takes no lock and allocates nothing.
#[derive(Debug, Clone)]
pub(crate) struct CycleClock {
    clock: quanta::Clock,
}

/// A point in a cycle as [`CycleClock`] sees it: the `Instant` the cycle
/// began and the raw counter read beside it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CycleStart {
    pub(crate) instant: Instant,
    raw: u64,
}

impl CycleClock {
    /// The process's clock; the first call calibrates it (see the module
    /// docs), so make it before the cycles start, not on the cycle path.
    pub(crate) fn new() -> Self {
        Self {
            clock: quanta::Clock::new(),
        }
    }

    /// Mark the start of a cycle.
    #[inline]
    pub(crate) fn start(&self) -> CycleStart {
        // The counter first: then the instant is read after it, and the
        // elapsed times measured from `raw` cover the instant's read too.
        let raw = self.clock.raw();
        CycleStart {
            instant: Instant::now(),
            raw,
        }
    }

    /// Nanoseconds from `start` to now (0 if the counter went back).
    #[inline]
    pub(crate) fn elapsed_ns(&self, start: &CycleStart) -> u64 {
        self.clock.delta_as_nanos(start.raw, self.clock.raw())
    }
}

impl CycleStart {
    /// The `Instant` `ns` nanoseconds after the start of the cycle.
    #[inline]
    pub(crate) fn after(&self, ns: u64) -> Instant {
        // `Duration::from_nanos` cannot overflow; `checked_add` fails only
        // past the end of the platform's time, then the start stands in.
        self.instant
            .checked_add(Duration::from_nanos(ns))
            .unwrap_or(self.instant)
    }
}

#[cfg(test)]
mod tests {
    use super::CycleClock;
    use std::time::{Duration, Instant};

    /// The scaled counter agrees with `Instant` over the same interval:
    /// the calibration turns counts into nanoseconds, not into counts. The
    /// counter's interval lies inside the `Instant`'s, so it can only be
    /// shorter (give or take the calibration's few-ns error), and it is at
    /// least the time slept. Generous bounds: a loaded machine lengthens
    /// both intervals alike.
    #[test]
    fn counts_scale_to_nanoseconds() {
        let clock = CycleClock::new();
        for _ in 0..3 {
            let outer = Instant::now();
            let start = clock.start();
            std::thread::sleep(Duration::from_millis(20));
            let ns = clock.elapsed_ns(&start);
            let outer_ns = u64::try_from(outer.elapsed().as_nanos()).unwrap();
            assert!(ns >= 19_000_000, "{ns} ns measured for a 20 ms sleep");
            assert!(
                ns <= outer_ns + outer_ns / 100 + 1_000,
                "{ns} ns measured inside an interval of {outer_ns} ns"
            );
        }
    }

    #[test]
    fn instants_follow_the_start() {
        let clock = CycleClock::new();
        let start = clock.start();
        assert_eq!(start.after(0), start.instant);
        assert_eq!(
            start.after(1_500_000_000) - start.instant,
            Duration::from_millis(1500)
        );
        // Elapsed readings never go back within a thread.
        let mut last = 0;
        for _ in 0..1000 {
            let ns = clock.elapsed_ns(&start);
            assert!(ns >= last, "{ns} after {last}");
            last = ns;
        }
    }
}
