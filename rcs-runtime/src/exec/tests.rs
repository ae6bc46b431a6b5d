//! Unit tests of [`super`] (exec.rs), kept apart to keep that file short.

use super::*;

/// A supervisor with one subordinate that keeps echoing an old serial.
struct Stuck {
    link: crate::SubordinateLink,
}

impl Controller for Stuck {
    fn name(&self) -> &str {
        "SUP"
    }
    fn cycle(&mut self, ctx: &CycleContext) {
        let read = crate::gm::Stamped {
            value: crate::StatusBuffer::default(),
            generation: ctx.cycle + 1,
            writer_cycle: ctx.cycle,
        };
        self.link.observe(&read);
    }
    fn old_echoes(&self, f: &mut dyn FnMut(&str, u64)) {
        f("SUB", self.link.old_echoes());
    }
}

#[test]
fn the_timing_report_gives_each_subordinates_old_echoes() -> Result<(), Box<dyn std::error::Error>>
{
    let mut link = crate::SubordinateLink::new();
    link.next_command();
    let mut e = Executive::new(ExecutiveConfig::new("cpu", Duration::from_millis(1)))?;
    e.add(Box::new(Stuck { link }))?;
    e.run_cycles(5)?;
    assert_eq!(e.old_echoes("SUP"), vec![("SUB".to_string(), 5)]);
    assert!(e.old_echoes("NOBODY").is_empty());
    Ok(())
}

#[test]
fn a_period_past_the_bound_is_refused_at_construction() {
    let e = Executive::new(ExecutiveConfig::new("cpu", Duration::MAX));
    assert!(matches!(e, Err(SetupError::PeriodTooLong(..))), "{e:?}");
    assert!(Executive::new(ExecutiveConfig::new("cpu", MAX_PERIOD)).is_ok());
    let e = Executive::new(ExecutiveConfig::new("cpu", Duration::ZERO));
    assert!(matches!(e, Err(SetupError::ZeroPeriod(..))), "{e:?}");
}

#[test]
fn cycle_context_tick() {
    let now = Instant::now();
    let ctx = CycleContext {
        cycle: 4,
        now,
        period: Duration::from_millis(1),
    };
    assert_eq!(ctx.tick(), Tick { cycle: 4, now });
}

struct Counter(u64);
impl Controller for Counter {
    fn name(&self) -> &str {
        "count"
    }
    fn cycle(&mut self, _: &CycleContext) {
        self.0 += 1;
    }
}
struct Other;
impl Controller for Other {
    fn name(&self) -> &str {
        "other"
    }
    fn cycle(&mut self, _: &CycleContext) {}
}

#[test]
fn a_controller_comes_back_as_its_own_type() -> Result<(), Box<dyn std::error::Error>> {
    let mut exec = Executive::new(ExecutiveConfig::new("x", Duration::from_millis(1)))?;
    exec.add(Box::new(Counter(0)))?;
    exec.add(Box::new(Other))?;
    exec.run_cycles(3)?;
    assert_eq!(exec.controller_as::<Counter>("count").map(|c| c.0), Some(3));
    assert!(exec.controller_as::<Other>("count").is_none());
    assert!(exec.controller_as::<Counter>("nobody").is_none());
    if let Some(c) = exec.controller_as_mut::<Counter>("count") {
        c.0 = 10;
    }
    exec.step()?;
    assert_eq!(
        exec.controller_as::<Counter>("count").map(|c| c.0),
        Some(11)
    );
    Ok(())
}

/// A controller whose cycle panics while `panic` is set; `fault` records
/// the code it was given.
struct Fragile {
    name: &'static str,
    panic: bool,
    cycles: u64,
    faults: Vec<ErrorCode>,
}

impl Controller for Fragile {
    fn name(&self) -> &str {
        self.name
    }
    fn cycle(&mut self, _: &CycleContext) {
        assert!(!self.panic, "hook {} failed", self.name);
        self.cycles += 1;
    }
    fn fault(&mut self, code: ErrorCode, _: &CycleContext) {
        self.faults.push(code);
    }
}

fn fragile(name: &'static str, panic: bool) -> Box<Fragile> {
    Box::new(Fragile {
        name,
        panic,
        cycles: 0,
        faults: Vec::new(),
    })
}

#[test]
fn a_panicking_controller_is_contained_and_reported() -> Result<(), SetupError> {
    let mut e = Executive::new(ExecutiveConfig::new("cpu", Duration::from_millis(1)))?;
    e.add(fragile("A", false))?;
    e.add(fragile("BAD", true))?;
    e.add(fragile("C", false))?;
    let fault = e.run_cycles(3).expect_err("BAD panics");
    assert_eq!(fault.total, 3);
    assert!(fault.panics.iter().all(|p| p.executive == "cpu"));
    assert_eq!(
        fault
            .panics
            .iter()
            .map(|p| (p.controller.as_str(), p.cycle))
            .collect::<Vec<_>>(),
        vec![("BAD", 0), ("BAD", 1), ("BAD", 2)]
    );
    assert_eq!(fault.panics[0].message, "hook BAD failed");
    assert!(
        fault.to_string().starts_with(
            "controller `BAD` (executive `cpu`) panicked in cycle 0: hook BAD failed;"
        ),
        "{fault}"
    );
    // The others ran every cycle, after the panic too.
    for name in ["A", "C"] {
        assert_eq!(e.controller_as::<Fragile>(name).map(|c| c.cycles), Some(3));
    }
    let bad = e.controller_as::<Fragile>("BAD").map(|c| c.faults.clone());
    assert_eq!(bad, Some(vec![ErrorCode::HOOK_PANIC; 3]));
    assert_eq!(e.controller_stats("BAD").map(|s| s.panics), Some(3));
    assert_eq!(e.controller_stats("A").map(|s| s.panics), Some(0));
    assert_eq!(e.last_panic("BAD"), Some("hook BAD failed"));
    assert_eq!(e.last_panic("A"), None);
    assert_eq!(e.cycle(), 3);
    // Mended, it runs again, and the next call reports nothing old.
    if let Some(c) = e.controller_as_mut::<Fragile>("BAD") {
        c.panic = false;
    }
    assert_eq!(e.step(), Ok(()));
    assert_eq!(e.controller_as::<Fragile>("BAD").map(|c| c.cycles), Some(1));
    Ok(())
}

#[test]
fn a_fault_lists_the_first_panics_and_counts_the_rest() -> Result<(), SetupError> {
    let mut e = Executive::new(ExecutiveConfig::new("cpu", Duration::from_millis(1)))?;
    e.add(fragile("BAD", true))?;
    let fault = e.run_cycles(100).expect_err("BAD panics");
    assert_eq!(fault.total, 100);
    assert_eq!(fault.panics.len(), CycleFault::LISTED);
    assert!(
        fault.to_string().ends_with("(and 84 more panics)"),
        "{fault}"
    );
    // Two executives' faults merge within the bound.
    let mut first = fault.clone();
    first.merge(fault);
    assert_eq!((first.total, first.panics.len()), (200, CycleFault::LISTED));
    Ok(())
}

#[test]
fn on_the_heartbeat_a_panic_lives_on_in_the_statistics() -> Result<(), SetupError> {
    let mut e = Executive::new(ExecutiveConfig::new("cpu", Duration::from_micros(100)))?;
    e.add(fragile("BAD", true))?;
    e.add(fragile("OK", false))?;
    e.run_for(5);
    assert_eq!(e.controller_stats("BAD").map(|s| s.panics), Some(5));
    assert_eq!(e.controller_as::<Fragile>("OK").map(|c| c.cycles), Some(5));
    // Nothing left over for the next step to report.
    if let Some(c) = e.controller_as_mut::<Fragile>("BAD") {
        c.panic = false;
    }
    assert_eq!(e.step(), Ok(()));
    Ok(())
}

#[test]
fn every_cycle_raises_the_attached_signal() -> Result<(), Box<dyn std::error::Error>> {
    let mut exec = Executive::new(ExecutiveConfig::new("x", Duration::from_millis(1)))?;
    exec.add(Box::new(Counter(0)))?;
    let signal = CycleSignal::new();
    exec.step()?;
    assert!(!signal.take(), "not attached yet");
    exec.set_cycle_signal(signal.clone());
    exec.step()?;
    assert!(signal.take());
    assert!(!signal.take());
    exec.run_cycles(3)?;
    assert!(signal.take());
    assert!(exec.take_cycle_signal().is_some());
    exec.step()?;
    assert!(!signal.take(), "detached");
    Ok(())
}

/// Keeps the `now` of each of its cycles, then sleeps `ms`.
struct Sleeper {
    name: &'static str,
    ms: u64,
    seen: Vec<Instant>,
}

impl Controller for Sleeper {
    fn name(&self) -> &str {
        self.name
    }
    fn cycle(&mut self, ctx: &CycleContext) {
        self.seen.push(ctx.now);
        std::thread::sleep(Duration::from_millis(self.ms));
    }
}

/// With measuring on, a controller's `now` is when its own turn began: the
/// cycle's `Instant` plus the TSC time the controllers before it took
/// (here at least A's 5 ms sleep, less 10 % for the calibration), and that
/// time is in A's statistics. With measuring off every controller gets the
/// start of the cycle. Lower bounds only: a loaded machine only lengthens.
#[test]
fn each_controller_sees_when_its_turn_began() -> Result<(), Box<dyn std::error::Error>> {
    for measure in [true, false] {
        let cfg = ExecutiveConfig::new("cpu", Duration::from_secs(10)).with_measure(measure);
        let mut e = Executive::new(cfg)?;
        for (name, ms) in [("A", 5), ("B", 0)] {
            e.add(Box::new(Sleeper {
                name,
                ms,
                seen: Vec::new(),
            }))?;
        }
        let before = Instant::now();
        e.run_cycles(3)?;
        let seen = |name| e.controller_as::<Sleeper>(name).map(|s| s.seen.clone());
        let (a, b) = (seen("A").unwrap(), seen("B").unwrap());
        assert_eq!((a.len(), b.len()), (3, 3));
        for (ta, tb) in a.iter().zip(&b) {
            assert!(*ta >= before);
            let gap = tb.duration_since(*ta);
            if measure {
                assert!(
                    gap >= Duration::from_micros(4500),
                    "B began {gap:?} after A"
                );
            } else {
                assert_eq!(gap, Duration::ZERO);
            }
        }
        let stats = e.controller_stats("A").unwrap().exec_ns;
        if measure {
            assert_eq!(stats.count, 3);
            assert!(stats.min >= 4_500_000, "A took {} ns", stats.min);
            assert!(e.stats().cycle_ns.min >= stats.min);
        } else {
            assert_eq!(stats.count, 0);
        }
    }
    Ok(())
}

/// Fires row 0 into S1 on its first cycle, then row 1 (S1 -> same) on
/// every other.
struct Planner {
    bk: Bookkeeping,
}
impl Controller for Planner {
    fn name(&self) -> &str {
        "P"
    }
    fn cycle(&mut self, ctx: &CycleContext) {
        self.bk.begin_cycle_raw(ctx.tick(), 1, 1, 1, true);
        let row = if self.bk.state() == 0 { 0 } else { 1 };
        let target = if row == 0 {
            crate::Target::State(1)
        } else {
            crate::Target::Same
        };
        self.bk.fire(row, target);
        self.bk.end_cycle();
    }
    fn bookkeeping(&self) -> Option<&Bookkeeping> {
        Some(&self.bk)
    }
}

#[test]
fn a_monitor_publishes_state_rows_fired_and_hit_counts() -> Result<(), SetupError> {
    let mut exec = Executive::new(ExecutiveConfig::new("cpu", Duration::from_millis(10)))?;
    exec.add(Box::new(Planner {
        bk: Bookkeeping::new(2),
    }))?;
    exec.add(Box::new(Counter(0)))?;
    let monitor = exec.attach_monitor(1);
    assert_eq!(monitor.controllers().len(), 2);
    let p = &monitor.controllers()[0];
    assert_eq!(p.figures().last_fired, None);
    exec.run_cycles(5)
        .map_err(|_| SetupError::ZeroPeriod("panic".into()))?;
    let f = p.figures();
    assert!(f.has_plans);
    assert_eq!((f.verb, f.state), (1, 1));
    assert_eq!(f.status, crate::Status::EXECUTING);
    assert_eq!(f.last_fired, Some((1, 1, 4)));
    // Room for one row per verb: row 0 counted, row 1 (4 times) dropped.
    assert_eq!(p.hits(1, 0), Some(1));
    assert_eq!(p.hits(1, 1), None);
    assert_eq!(p.hits_dropped(), 4);
    assert!(!monitor.controllers()[1].figures().has_plans);
    assert_eq!(monitor.name(), "cpu");
    Ok(())
}

#[test]
fn a_main_loop_honours_pause_step_and_go() {
    let mut e = Executive::new(ExecutiveConfig::new("loop", Duration::from_millis(10))).unwrap();
    let h = e.handle();
    assert_eq!(e.step_unless_paused(), Ok(true));
    h.pause();
    assert_eq!(e.step_unless_paused(), Ok(false));
    assert_eq!(e.cycle(), 1);
    h.step_by(2);
    assert_eq!(e.step_unless_paused(), Ok(true));
    assert_eq!(e.step_unless_paused(), Ok(true));
    assert_eq!(e.step_unless_paused(), Ok(false));
    assert_eq!((e.cycle(), h.cycle(), h.pending_steps()), (3, 3, 0));
    h.go();
    assert_eq!(e.step_unless_paused(), Ok(true));
    assert_eq!(e.cycle(), 4);
}

#[test]
fn a_main_loop_notes_its_heartbeats() {
    let mut e = Executive::new(ExecutiveConfig::new("loop", Duration::from_millis(10))).unwrap();
    let m = e.attach_monitor(1);
    let h = e.handle();
    e.note_heartbeat(Duration::from_micros(250), 2);
    e.note_heartbeat(Duration::from_micros(100), 3);
    assert_eq!(
        (m.lateness_last_ns(), m.lateness_max_ns()),
        (100_000, 250_000)
    );
    assert_eq!(h.missed_heartbeats(), 3);
    assert_eq!(e.stats().missed_heartbeats, 3);
}
