//! The executive: the seed's main program template (§5.4, Appendix B) for
//! one CPU.
//!
//! An [`Executive`] owns a fixed list of [`Controller`]s and runs them in that
//! order once per heartbeat. It keeps the cycle count, waits for absolute
//! deadlines (sleep, then spin the last stretch), counts overruns, and keeps
//! per-controller execution time statistics. Modes: run on the heartbeat
//! ([`Executive::run`]), pause / single-step / go through an
//! [`ExecutiveHandle`] from any thread, and run N cycles as fast as possible
//! ([`Executive::run_cycles`]) for tests and simulation.
//!
//! Several executives, each on its own thread with its own period, can share
//! one [`GlobalMemory`](crate::GlobalMemory); the handshake keeps them
//! correct without synchronising their cycles (§5.5).
//!
//! A controller whose cycle panics (a hand-written hook, say) is contained:
//! each cycle runs inside [`std::panic::catch_unwind`], the faulty
//! controller is told through [`Controller::fault`] (generated controllers
//! end their plan with the built-in error `HOOK_PANIC` and publish their
//! status), the panic is counted ([`ControllerStats::panics`],
//! [`Executive::last_panic`]) and the other controllers run on.
//! [`Executive::step`] and [`Executive::run_cycles`] report the panics as a
//! [`CycleFault`]; on the heartbeat ([`Executive::run`]) the statistics keep
//! them.
//!
//! Nothing here allocates or locks once the controllers are added, unless a
//! trace sink is attached ([`Executive::set_trace`]) or a controller panics.
//! A [`CycleSignal`] attached with [`Executive::set_cycle_signal`] is raised
//! at the end of every cycle (lock- and allocation-free): the Zenoh bridge
//! publishes the cycle's writes then instead of polling for them.
//! An [`ExecutiveMonitor`] attached with [`Executive::attach_monitor`]
//! publishes each controller's figures in atomics for a console on another
//! thread (no lock, no allocation on the cycle path).

use std::any::Any;
use std::io;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::clock::CycleClock;
use crate::error::SetupError;
use crate::fault::{panic_message, ControllerPanic, CycleFault};
use crate::handshake::ErrorCode;
pub use crate::heartbeat::{Heartbeat, Wait, MAX_PERIOD};
use crate::plan::{Bookkeeping, SampleStats, Tick};
use crate::signal::CycleSignal;
use crate::trace::{TraceDetail, TraceRecord, TraceSink};

/// What the executive tells a controller about the cycle it runs in.
#[derive(Debug, Clone, Copy)]
pub struct CycleContext {
    /// The executive's cycle count (0 on the first cycle). Stamp writes with it.
    pub cycle: u64,
    /// When this controller's turn began (with measuring off, when the
    /// cycle began). The executive reads `Instant::now()` once per cycle
    /// and adds the TSC time elapsed since for each later controller.
    pub now: Instant,
    /// The executive's period.
    pub period: Duration,
}

impl CycleContext {
    /// The cycle count and start instant as a [`Tick`] for [`Bookkeeping`].
    #[inline]
    pub fn tick(&self) -> Tick {
        Tick {
            cycle: self.cycle,
            now: self.now,
        }
    }
}

/// A controller module (or simulator, or driver) that an executive runs once
/// per cycle. A controller only talks to others through Global Memory.
///
/// Controllers are `'static` ([`Any`]), so that whoever added one can get
/// it back as its own type: [`Executive::controller_as`].
pub trait Controller: Any + Send {
    /// The controller's name, for statistics and traces.
    fn name(&self) -> &str;

    /// One read/compute/write cycle. Must not block.
    fn cycle(&mut self, ctx: &CycleContext);

    /// The controller's plan bookkeeping, if it has one: the executive reads
    /// it for traces and per-verb statistics.
    fn bookkeeping(&self) -> Option<&Bookkeeping> {
        None
    }

    /// The executive caught a panic out of [`cycle`](Self::cycle) (a
    /// hand-written hook, say): end the running plan with `code`
    /// ([`ErrorCode::HOOK_PANIC`]) and publish the status as step 5 would,
    /// so that the supervisor sees ERROR instead of a status frozen at
    /// EXECUTING. The next command must start normally. The default does
    /// nothing (a controller without plans).
    fn fault(&mut self, code: ErrorCode, ctx: &CycleContext) {
        let _ = (code, ctx);
    }

    /// Each subordinate's name with the cycles in which it answered with an
    /// older serial than the last command sent
    /// ([`SubordinateLink::old_echoes`](crate::SubordinateLink::old_echoes)),
    /// given to `f` one by one. For the timing report, not the cycle path.
    fn old_echoes(&self, f: &mut dyn FnMut(&str, u64)) {
        let _ = f;
    }
}

/// Execution-time statistics of one controller (§5.3.3: last, min, max,
/// mean), in nanoseconds, and how often it alone took longer than a period.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct ControllerStats {
    /// Execution time per cycle, nanoseconds.
    pub exec_ns: SampleStats,
    /// Cycles in which this controller alone took longer than the period.
    pub overruns: u64,
    /// Cycles in which this controller panicked (the executive caught the
    /// panic and ended its plan with `HOOK_PANIC`).
    pub panics: u64,
}

/// Statistics of an executive.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct ExecutiveStats {
    /// Cycles run.
    pub cycles: u64,
    /// Cycles whose controllers together took longer than the period.
    pub overruns: u64,
    /// Heartbeats skipped because a cycle (or the machine) ran past their
    /// deadline (only in [`Executive::run`]): a cycle that takes three
    /// periods is one overrun and two missed heartbeats.
    pub missed_heartbeats: u64,
    /// Duration of a whole cycle (all controllers), nanoseconds.
    pub cycle_ns: SampleStats,
    /// How late each heartbeat woke after its deadline, nanoseconds (only
    /// in [`Executive::run`]).
    pub lateness_ns: SampleStats,
}

/// Settings of an executive.
#[derive(Debug, Clone)]
pub struct ExecutiveConfig {
    /// The name of this executive ("CPU").
    pub name: String,
    /// The heartbeat period.
    pub period: Duration,
    /// How to wait for deadlines (default: sleep, then spin the last 200 µs).
    pub wait: Wait,
    /// Measure per-controller execution time (default true): one read of
    /// the CPU's time-stamp counter per controller per cycle (the OS clock
    /// where there is no invariant TSC; see the `clock` module). Turning it
    /// off saves those reads; overruns are then judged on the whole cycle
    /// only, and every controller's [`CycleContext::now`] is the start of
    /// the cycle.
    pub measure: bool,
}

impl ExecutiveConfig {
    /// An executive called `name` with heartbeat `period`, sleep+spin waits
    /// and timing on.
    pub fn new(name: impl Into<String>, period: Duration) -> Self {
        Self {
            name: name.into(),
            period,
            wait: Wait::default(),
            measure: true,
        }
    }

    /// The same with another wait strategy.
    pub fn with_wait(mut self, wait: Wait) -> Self {
        self.wait = wait;
        self
    }

    /// The same with per-controller timing on or off.
    pub fn with_measure(mut self, measure: bool) -> Self {
        self.measure = measure;
        self
    }
}

#[derive(Debug, Default)]
struct Shared {
    paused: AtomicBool,
    steps: AtomicU64,
    stop: AtomicBool,
    cycle: AtomicU64,
    overruns: AtomicU64,
    missed: AtomicU64,
}

/// Remote control of an executive, usable from any thread (the operator's
/// pause / step / go, Appendix B). Lock-free: the executive polls it with an
/// atomic load between cycles.
#[derive(Debug, Clone)]
pub struct ExecutiveHandle {
    shared: Arc<Shared>,
}

impl ExecutiveHandle {
    /// Stop running controllers (the heartbeat keeps ticking).
    pub fn pause(&self) {
        self.shared.paused.store(true, Ordering::SeqCst);
    }
    /// Pause, and run exactly one more cycle on the next heartbeat.
    pub fn step(&self) {
        self.shared.paused.store(true, Ordering::SeqCst);
        self.shared.steps.fetch_add(1, Ordering::SeqCst);
    }
    /// Pause, and run exactly `n` more cycles, one per heartbeat (run N;
    /// `step_by(1)` is [`step`](Self::step)).
    pub fn step_by(&self, n: u64) {
        self.shared.paused.store(true, Ordering::SeqCst);
        let _ = self
            .shared
            .steps
            .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |s| {
                Some(s.saturating_add(n))
            });
    }
    /// Run freely again.
    pub fn go(&self) {
        self.shared.steps.store(0, Ordering::SeqCst);
        self.shared.paused.store(false, Ordering::SeqCst);
    }
    /// Make [`Executive::run`] return after the current cycle.
    pub fn stop(&self) {
        self.shared.stop.store(true, Ordering::SeqCst);
    }
    /// Withdraw a stop request, so that [`Executive::run`] can be entered
    /// again.
    pub fn clear_stop(&self) {
        self.shared.stop.store(false, Ordering::SeqCst);
    }
    /// Whether the executive is paused.
    pub fn is_paused(&self) -> bool {
        self.shared.paused.load(Ordering::SeqCst)
    }
    /// Cycles run so far.
    pub fn cycle(&self) -> u64 {
        self.shared.cycle.load(Ordering::Acquire)
    }
    /// Overruns counted so far.
    pub fn overruns(&self) -> u64 {
        self.shared.overruns.load(Ordering::Acquire)
    }
    /// Heartbeats missed so far (see [`ExecutiveStats::missed_heartbeats`]).
    pub fn missed_heartbeats(&self) -> u64 {
        self.shared.missed.load(Ordering::Acquire)
    }
    /// Single steps requested and not yet run.
    pub fn pending_steps(&self) -> u64 {
        self.shared.steps.load(Ordering::SeqCst)
    }
}

struct Slot {
    name: String,
    ctrl: Box<dyn Controller>,
    stats: ControllerStats,
    last_panic: Option<String>,
}

/// The main program of one CPU. See the module docs.
pub struct Executive {
    name: String,
    period: Duration,
    period_ns: u64,
    /// The per-controller timing clock; `None` with measuring off.
    clock: Option<CycleClock>,
    heartbeat: Heartbeat,
    slots: Vec<Slot>,
    cycle: u64,
    stats: ExecutiveStats,
    shared: Arc<Shared>,
    trace: Option<TraceSink>,
    /// Panics caught since the last `step`/`run_cycles` reported them.
    fault: Option<CycleFault>,
    signal: Option<CycleSignal>,
    /// Figures published for a console ([`Executive::attach_monitor`]).
    monitor: Option<Arc<ExecutiveMonitor>>,
}

impl std::fmt::Debug for Executive {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Executive")
            .field("name", &self.name)
            .field("period", &self.period)
            .field("controllers", &self.controller_names().collect::<Vec<_>>())
            .field("cycle", &self.cycle)
            .finish()
    }
}

fn nanos(d: Duration) -> u64 {
    u64::try_from(d.as_nanos()).unwrap_or(u64::MAX)
}

impl Executive {
    /// A new executive with no controllers.
    pub fn new(config: ExecutiveConfig) -> Result<Self, SetupError> {
        if config.period.is_zero() {
            return Err(SetupError::ZeroPeriod(config.name));
        }
        if config.period > MAX_PERIOD {
            return Err(SetupError::PeriodTooLong(config.name, config.period));
        }
        Ok(Self {
            heartbeat: Heartbeat::new(config.period, config.wait)?,
            period_ns: nanos(config.period),
            period: config.period,
            // Calibrated here (once per process), not on the first cycle.
            clock: config.measure.then(CycleClock::new),
            name: config.name,
            slots: Vec::new(),
            cycle: 0,
            stats: ExecutiveStats::default(),
            shared: Arc::default(),
            trace: None,
            fault: None,
            signal: None,
            monitor: None,
        })
    }

    /// Append a controller to the fixed execution order.
    pub fn add(&mut self, ctrl: Box<dyn Controller>) -> Result<(), SetupError> {
        let name = ctrl.name().to_owned();
        if self.slots.iter().any(|s| s.name == name) {
            return Err(SetupError::DuplicateController(name, self.name.clone()));
        }
        self.slots.push(Slot {
            name,
            ctrl,
            stats: ControllerStats::default(),
            last_panic: None,
        });
        Ok(())
    }

    /// Attach a trace sink: from now on every controller's verb, state,
    /// status, error and fired row is written as one JSON line per controller
    /// per cycle. **This allocates and does I/O on the cycle path**; it is
    /// for debugging and replay, not for production timing.
    pub fn set_trace(&mut self, sink: TraceSink) {
        self.trace = Some(sink);
    }

    /// Raise `signal` at the end of every cycle, once all controllers have
    /// written (the generated `System::process` attaches its bridge's
    /// `Bridge::signal()` to each executive, feature `zenoh`, so that the
    /// cycle's writes are published at once). Replaces an earlier one.
    /// Raising takes no lock and allocates nothing.
    pub fn set_cycle_signal(&mut self, signal: CycleSignal) {
        self.signal = Some(signal);
    }

    /// Detach and return the cycle signal.
    pub fn take_cycle_signal(&mut self) -> Option<CycleSignal> {
        self.signal.take()
    }

    /// Detach and return the trace sink.
    pub fn take_trace(&mut self) -> Option<TraceSink> {
        self.trace.take()
    }

    /// A handle to pause, step, resume and stop this executive from anywhere.
    pub fn handle(&self) -> ExecutiveHandle {
        ExecutiveHandle {
            shared: Arc::clone(&self.shared),
        }
    }

    /// Run exactly one cycle now, without waiting (single step for tests and
    /// simulation; ignores pause). A controller that panicked was contained
    /// (see the module docs) and is reported in the error.
    pub fn step(&mut self) -> Result<(), CycleFault> {
        self.run_one();
        self.take_fault()
    }

    /// Run `n` cycles back to back, as fast as possible (ignores pause).
    /// All `n` cycles run even if controllers panic; the panics are
    /// reported in the error.
    pub fn run_cycles(&mut self, n: u64) -> Result<(), CycleFault> {
        for _ in 0..n {
            self.run_one();
        }
        self.take_fault()
    }

    fn take_fault(&mut self) -> Result<(), CycleFault> {
        match self.fault.take() {
            None => Ok(()),
            Some(f) => Err(f),
        }
    }

    /// Run on the heartbeat until [`ExecutiveHandle::stop`] is called.
    /// Honours pause / step / go. A stop requested before `run` makes it
    /// return at once. Runs the first cycle immediately, then waits for each
    /// deadline after the cycle (Appendix B's order).
    pub fn run(&mut self) {
        self.run_heartbeats(None);
    }

    /// Run on the heartbeat for `beats` heartbeats (or until stopped). A
    /// paused heartbeat counts as a beat but runs no cycle.
    pub fn run_for(&mut self, beats: u64) {
        self.run_heartbeats(Some(beats));
    }

    fn run_heartbeats(&mut self, limit: Option<u64>) {
        self.heartbeat.start(Instant::now());
        let mut beats = 0u64;
        loop {
            if self.shared.stop.load(Ordering::Acquire) {
                break;
            }
            if limit.is_some_and(|l| beats >= l) {
                break;
            }
            beats += 1;
            if self.may_run() {
                self.run_one();
                // On the heartbeat, panics live on in the statistics
                // (`panics`, `last_panic`) rather than piling up here.
                self.fault = None;
            }
            let late = self.heartbeat.wait();
            self.stats.lateness_ns.record(nanos(late));
            self.stats.missed_heartbeats = self.heartbeat.missed();
            self.publish_executive();
            self.shared
                .missed
                .store(self.heartbeat.missed(), Ordering::Release);
        }
    }

    /// Spawn this executive on its own thread, running on the heartbeat
    /// until stopped; the thread returns the executive (with its statistics).
    pub fn spawn(mut self) -> io::Result<(ExecutiveHandle, JoinHandle<Executive>)> {
        let handle = self.handle();
        let join = std::thread::Builder::new()
            .name(format!("rcs-exec-{}", self.name))
            .spawn(move || {
                self.run();
                self
            })?;
        Ok((handle, join))
    }

    #[inline]
    fn run_one(&mut self) {
        let cycle = self.cycle;
        let period = self.period;
        // One `Instant` per cycle; with measuring on, each controller's
        // `now` and execution time come from the TSC (see `crate::clock`).
        let start = self.clock.as_ref().map(CycleClock::start);
        let start_instant = start.map_or_else(Instant::now, |s| s.instant);
        let mut t0 = start_instant;
        let mut t0_ns = 0u64;
        for (index, slot) in self.slots.iter_mut().enumerate() {
            let ctx = CycleContext {
                cycle,
                now: t0,
                period,
            };
            // No allocation unless a panic happens.
            if let Err(payload) = catch_unwind(AssertUnwindSafe(|| slot.ctrl.cycle(&ctx))) {
                let message = panic_message(payload.as_ref());
                // The fault handler is contained too: a controller that
                // cannot even fault must not take the others down.
                let _ = catch_unwind(AssertUnwindSafe(|| {
                    slot.ctrl.fault(ErrorCode::HOOK_PANIC, &ctx)
                }));
                slot.stats.panics = slot.stats.panics.saturating_add(1);
                slot.last_panic = Some(message.clone());
                self.fault
                    .get_or_insert_with(|| CycleFault {
                        panics: Vec::new(),
                        total: 0,
                    })
                    .record(ControllerPanic {
                        executive: self.name.clone(),
                        controller: slot.name.clone(),
                        cycle,
                        message,
                    });
            }
            let mut cycle_ns = None;
            if let (Some(clock), Some(start)) = (&self.clock, &start) {
                // `max`: a counter read behind the last one (the thread
                // moved to a core whose TSC lags) counts as 0 ns and keeps
                // each controller's `now` at or after the one before.
                let t1_ns = clock.elapsed_ns(start).max(t0_ns);
                let ns = t1_ns - t0_ns;
                slot.stats.exec_ns.record(ns);
                cycle_ns = Some(ns);
                if ns > self.period_ns {
                    slot.stats.overruns = slot.stats.overruns.saturating_add(1);
                }
                t0_ns = t1_ns;
                t0 = start.after(t1_ns);
            }
            if let Some(c) = self
                .monitor
                .as_ref()
                .and_then(|m| m.controllers().get(index))
            {
                c.publish(slot, cycle);
            }
            if let Some(trace) = &mut self.trace {
                let bk = slot.ctrl.bookkeeping();
                let detail = TraceDetail {
                    cycle_ns,
                    serial: bk.map(|b| b.echo_serial()),
                    ..TraceDetail::default()
                };
                trace.write_with(
                    &TraceRecord {
                        executive: &self.name,
                        cycle,
                        controller: &slot.name,
                        verb: bk.map(|b| b.verb()),
                        state: bk.map(|b| b.state()),
                        status: bk.map(|b| b.status().0),
                        error: bk.map(|b| b.error().0),
                        fired: bk.and_then(|b| b.fired()),
                        new_command: bk.is_some_and(|b| b.new_command()),
                    },
                    &detail,
                );
            }
        }
        let ns = if start.is_some() {
            t0_ns
        } else {
            nanos(start_instant.elapsed())
        };
        self.stats.cycle_ns.record(ns);
        if ns > self.period_ns {
            self.stats.overruns = self.stats.overruns.saturating_add(1);
            self.shared
                .overruns
                .store(self.stats.overruns, Ordering::Release);
        }
        self.cycle = cycle.wrapping_add(1);
        self.stats.cycles = self.cycle;
        self.publish_executive();
        self.shared.cycle.store(self.cycle, Ordering::Release);
        if let Some(signal) = &self.signal {
            signal.raise();
        }
    }

    /// This executive's name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// The heartbeat period.
    pub fn period(&self) -> Duration {
        self.period
    }
    /// Cycles run so far.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }
    /// Cycles that overran the period.
    pub fn overruns(&self) -> u64 {
        self.stats.overruns
    }
    /// Executive-wide statistics.
    pub fn stats(&self) -> &ExecutiveStats {
        &self.stats
    }
}

mod driven;
mod lookup;
mod monitor;
pub use monitor::{ControllerFigures, ControllerMonitor, ExecutiveMonitor};

#[cfg(test)]
mod tests;
