//! What an executive publishes for a console while it runs on its own
//! thread: per controller its verb, state, status, error, the row fired last,
//! each row's hit count and its timing; per executive its cycle time and
//! heartbeat lateness.
//!
//! The executive owns its controllers and their statistics on its thread;
//! a console on another thread must not take a lock the executive takes
//! (issue 31). So the executive, once a monitor is attached
//! ([`Executive::attach_monitor`], before it is spawned), stores those
//! figures in atomics at the end of each controller's turn: relaxed stores
//! into memory allocated at attach time — no lock, no allocation on the
//! cycle path. A reader sees each figure whole; figures of one controller
//! may come from two neighbouring cycles, which a display tolerates.
//!
//! Without a monitor the cycle path pays one `Option` test per controller.

use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use super::{Executive, Slot};
use crate::handshake::{ErrorCode, RowId, StateId, Status, VerbId};

/// "No row": the packed (verb, row) of a controller that fired none yet.
const NO_ROW: u32 = u32::MAX;

/// One controller's published figures. See the module docs.
#[derive(Debug)]
pub struct ControllerMonitor {
    name: String,
    has_plans: bool,
    verb: AtomicU32,
    state: AtomicU32,
    status: AtomicU32,
    error: AtomicU32,
    /// `verb << 16 | row` of the last row fired (sticky), or [`NO_ROW`].
    last_fired: AtomicU32,
    /// The executive's cycle in which `last_fired` fired.
    last_fired_cycle: AtomicU64,
    exec_last_ns: AtomicU64,
    exec_max_ns: AtomicU64,
    overruns: AtomicU64,
    panics: AtomicU64,
    /// Rows per verb the hit counters have room for.
    rows_per_verb: usize,
    /// Hit counts, `verb * rows_per_verb + row`.
    hits: Box<[AtomicU64]>,
    /// Rows fired beyond `rows_per_verb` or the verb count (not counted).
    hits_dropped: AtomicU64,
}

/// A plain copy of a [`ControllerMonitor`]'s figures at one moment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ControllerFigures {
    /// Whether the controller has plan bookkeeping (verb, state… mean
    /// something).
    pub has_plans: bool,
    /// The verb of the command it works on.
    pub verb: VerbId,
    /// The current state of that verb's plan.
    pub state: StateId,
    /// Its status.
    pub status: Status,
    /// Its error code.
    pub error: ErrorCode,
    /// `(verb, row)` of the row it fired last, and the executive's cycle then.
    pub last_fired: Option<(VerbId, RowId, u64)>,
    /// Its execution time in the last cycle, ns.
    pub exec_last_ns: u64,
    /// Its longest execution time, ns.
    pub exec_max_ns: u64,
    /// Cycles in which it alone took longer than the period.
    pub overruns: u64,
    /// Panics caught in its cycle.
    pub panics: u64,
}

impl ControllerMonitor {
    fn new(slot: &Slot, rows_per_verb: usize) -> Self {
        let bk = slot.ctrl.bookkeeping();
        let verbs = bk.map_or(0, |b| b.verb_stats().len());
        let hits = (0..verbs.saturating_mul(rows_per_verb))
            .map(|_| AtomicU64::new(0))
            .collect();
        Self {
            name: slot.name.clone(),
            has_plans: bk.is_some(),
            verb: AtomicU32::new(0),
            state: AtomicU32::new(0),
            status: AtomicU32::new(0),
            error: AtomicU32::new(0),
            last_fired: AtomicU32::new(NO_ROW),
            last_fired_cycle: AtomicU64::new(0),
            exec_last_ns: AtomicU64::new(0),
            exec_max_ns: AtomicU64::new(0),
            overruns: AtomicU64::new(0),
            panics: AtomicU64::new(0),
            rows_per_verb,
            hits,
            hits_dropped: AtomicU64::new(0),
        }
    }

    /// Store `slot`'s figures after its turn in `cycle` (cycle path: atomic
    /// stores only).
    #[inline]
    pub(super) fn publish(&self, slot: &Slot, cycle: u64) {
        let r = Ordering::Relaxed;
        if let Some(bk) = slot.ctrl.bookkeeping() {
            let verb = bk.verb();
            self.verb.store(u32::from(verb), r);
            self.state.store(u32::from(bk.state()), r);
            self.status.store(u32::from(bk.status().0), r);
            self.error.store(u32::from(bk.error().0), r);
            if let Some(row) = bk.fired() {
                self.last_fired
                    .store(u32::from(verb) << 16 | u32::from(row), r);
                self.last_fired_cycle.store(cycle, r);
                let index = usize::from(verb)
                    .checked_mul(self.rows_per_verb)
                    .and_then(|i| i.checked_add(usize::from(row)));
                match index.filter(|_| usize::from(row) < self.rows_per_verb) {
                    Some(i) if i < self.hits.len() => {
                        self.hits[i].fetch_add(1, r);
                    }
                    _ => {
                        self.hits_dropped.fetch_add(1, r);
                    }
                }
            }
        }
        let s = &slot.stats;
        self.exec_last_ns.store(s.exec_ns.last, r);
        self.exec_max_ns.store(s.exec_ns.max, r);
        self.overruns.store(s.overruns, r);
        self.panics.store(s.panics, r);
    }

    /// The controller's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its figures now.
    pub fn figures(&self) -> ControllerFigures {
        let r = Ordering::Relaxed;
        let last = self.last_fired.load(r);
        let narrow = |v: u32| u16::try_from(v).unwrap_or(u16::MAX);
        ControllerFigures {
            has_plans: self.has_plans,
            verb: narrow(self.verb.load(r)),
            state: narrow(self.state.load(r)),
            status: Status(narrow(self.status.load(r))),
            error: ErrorCode(narrow(self.error.load(r))),
            last_fired: (last != NO_ROW).then(|| {
                (
                    narrow(last >> 16),
                    narrow(last & 0xffff),
                    self.last_fired_cycle.load(r),
                )
            }),
            exec_last_ns: self.exec_last_ns.load(r),
            exec_max_ns: self.exec_max_ns.load(r),
            overruns: self.overruns.load(r),
            panics: self.panics.load(r),
        }
    }

    /// How often row `row` of verb `verb`'s plan fired since the monitor was
    /// attached (`None`: beyond the counters' room).
    pub fn hits(&self, verb: VerbId, row: RowId) -> Option<u64> {
        if usize::from(row) >= self.rows_per_verb {
            return None;
        }
        let i = usize::from(verb) * self.rows_per_verb + usize::from(row);
        self.hits.get(i).map(|h| h.load(Ordering::Relaxed))
    }

    /// The verbs its hit counters cover (ids `0..verbs()`).
    pub fn verbs(&self) -> usize {
        self.hits.len().checked_div(self.rows_per_verb).unwrap_or(0)
    }

    /// The rows per verb its hit counters cover.
    pub fn rows_per_verb(&self) -> usize {
        self.rows_per_verb
    }

    /// Rows fired that had no counter (a plan longer than the room given
    /// to [`Executive::attach_monitor`]).
    pub fn hits_dropped(&self) -> u64 {
        self.hits_dropped.load(Ordering::Relaxed)
    }
}

/// An executive's published figures: see the module docs.
#[derive(Debug)]
pub struct ExecutiveMonitor {
    name: String,
    period: Duration,
    controllers: Box<[ControllerMonitor]>,
    cycle_last_ns: AtomicU64,
    cycle_max_ns: AtomicU64,
    lateness_last_ns: AtomicU64,
    lateness_max_ns: AtomicU64,
}

impl ExecutiveMonitor {
    /// The executive's name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Its heartbeat period.
    pub fn period(&self) -> Duration {
        self.period
    }
    /// Its controllers in execution order.
    pub fn controllers(&self) -> &[ControllerMonitor] {
        &self.controllers
    }
    /// Duration of the last whole cycle, ns.
    pub fn cycle_last_ns(&self) -> u64 {
        self.cycle_last_ns.load(Ordering::Relaxed)
    }
    /// Longest whole cycle, ns.
    pub fn cycle_max_ns(&self) -> u64 {
        self.cycle_max_ns.load(Ordering::Relaxed)
    }
    /// How late the last heartbeat woke, ns (0 until the executive runs on
    /// its heartbeat).
    pub fn lateness_last_ns(&self) -> u64 {
        self.lateness_last_ns.load(Ordering::Relaxed)
    }
    /// The latest any heartbeat woke, ns.
    pub fn lateness_max_ns(&self) -> u64 {
        self.lateness_max_ns.load(Ordering::Relaxed)
    }
}

impl Executive {
    /// Publish this executive's figures for a console from now on, with hit
    /// counters for `rows_per_verb` rows of each verb's plan (the longest
    /// plan of the plan set; rows beyond are counted in
    /// [`ControllerMonitor::hits_dropped`]). Call after the controllers are
    /// added: it sizes its storage for them here, so that the cycle path
    /// never allocates. Attaching again starts the counts afresh.
    pub fn attach_monitor(&mut self, rows_per_verb: usize) -> Arc<ExecutiveMonitor> {
        let monitor = Arc::new(ExecutiveMonitor {
            name: self.name.clone(),
            period: self.period,
            controllers: self
                .slots
                .iter()
                .map(|s| ControllerMonitor::new(s, rows_per_verb))
                .collect(),
            cycle_last_ns: AtomicU64::new(0),
            cycle_max_ns: AtomicU64::new(0),
            lateness_last_ns: AtomicU64::new(0),
            lateness_max_ns: AtomicU64::new(0),
        });
        self.monitor = Some(Arc::clone(&monitor));
        monitor
    }

    /// Publish the whole cycle's and the heartbeat's figures (cycle path).
    #[inline]
    pub(super) fn publish_executive(&self) {
        if let Some(m) = &self.monitor {
            let r = Ordering::Relaxed;
            m.cycle_last_ns.store(self.stats.cycle_ns.last, r);
            m.cycle_max_ns.store(self.stats.cycle_ns.max, r);
            m.lateness_last_ns.store(self.stats.lateness_ns.last, r);
            m.lateness_max_ns.store(self.stats.lateness_ns.max, r);
        }
    }
}
