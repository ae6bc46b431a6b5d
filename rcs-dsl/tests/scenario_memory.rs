//! A scenario's memory is constant in its number of cycles: ten million
//! cycles of a tiny plan keep a record of two entries, and the most memory
//! live at once while they run is no more than for a thousand cycles. A
//! counting allocator measures it; this file holds one test so that no
//! other test allocates beside it.

use rcs_dsl::scenario;
use rcs_dsl::source::SourceFile;
use rcs_dsl::{check, Options, PlanSet};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, counting bytes live now and the most live since
/// the last reset.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        unsafe { System.dealloc(p, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

const PLANS: &str = "controller A {
    command GO
    var n: i32 = 0
    plan GO {
        *0 when new_command -> S1
        S1 when n > 0 -> Done
    }
}
";

/// The most bytes live above the start while `cycles` cycles run, and the
/// outcome's record.
fn peak_over(cycles: u64) -> (usize, Vec<(String, u64)>) {
    let set = PlanSet::from_texts("t", [("t.rcs", PLANS)], None);
    let ir = check(&set, &Options::default()).ir.expect("clean");
    let text = format!(
        "controller: A\nsteps:\n  - command: GO\n  - cycles: {cycles}\n    expect: {{ fired: none, state: S1 }}\n"
    );
    let s = scenario::parse(&ir, &SourceFile::new("t.scenario.yaml", text), "t").expect("reads");
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let outcome = scenario::run(&ir, &s);
    let peak = PEAK.load(Ordering::Relaxed) - base;
    assert!(outcome.failure.is_none(), "{:?}", outcome.failure);
    assert_eq!(outcome.cycles(), cycles + 1);
    (peak, outcome.fired)
}

#[test]
fn ten_million_cycles_run_in_the_memory_of_a_thousand() {
    let (small, _) = peak_over(1_000);
    let (large, fired) = peak_over(scenario::MAX_CYCLES);
    // Run-length encoded: the command's row, then the wait.
    assert_eq!(
        fired,
        [("E0".to_string(), 1), ("-".to_string(), 10_000_000)]
    );
    assert!(
        large <= small + 4096,
        "{large} bytes live at most over 10,000,000 cycles, {small} over 1,000"
    );
}
