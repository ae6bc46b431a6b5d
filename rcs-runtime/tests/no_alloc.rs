//! No heap allocation on the cycle path: a counting global allocator around
//! 10,000 cycles of a small hierarchy with commands flowing.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use common::{Relay, GO, HOLD};
use rcs_runtime::{Executive, ExecutiveConfig, GlobalMemory, Operator, Status, VerbId};

struct Counting;

static ALLOCS: AtomicU64 = AtomicU64::new(0);

// SAFETY: forwards to the system allocator, only counting calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as ours.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

// The only test in this binary, so no other test thread allocates meanwhile.
#[test]
fn ten_thousand_cycles_allocate_nothing() {
    let gm = GlobalMemory::new();
    let mut exec = Executive::new(ExecutiveConfig::new("main", Duration::from_millis(10))).unwrap();
    exec.add(Box::new(Relay::new(&gm, "SM", Some("PR"), 0).unwrap()))
        .unwrap();
    exec.add(Box::new(Relay::new(&gm, "PR", Some("TB"), 0).unwrap()))
        .unwrap();
    exec.add(Box::new(Relay::new(&gm, "TB", None, 3).unwrap()))
        .unwrap();
    let mut op = Operator::<VerbId>::connect(&gm, "SM").unwrap();
    let handle = exec.handle();
    // Warm up once (first-touch effects, lazily initialised statics).
    op.command(GO);
    exec.run_cycles(10);

    let before = ALLOCS.load(Ordering::SeqCst);
    assert!(
        before > 0,
        "the counting allocator counts (setup allocated)"
    );
    let mut done = 0;
    for round in 0..100u32 {
        // Alternate a completing command and a superseding one.
        op.command(if round % 3 == 2 { HOLD } else { GO });
        exec.run_cycles(50);
        if op.outcome() == Some((Status::DONE, Default::default())) {
            done += 1;
        }
        op.command(GO);
        exec.run_cycles(50);
        let _ = handle.cycle();
    }
    let after = ALLOCS.load(Ordering::SeqCst);

    assert_eq!(exec.cycle(), 10 + 10_000);
    assert!(done >= 60, "commands completed: {done}");
    assert_eq!(after - before, 0, "heap allocations on the cycle path");
}
