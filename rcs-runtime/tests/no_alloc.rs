//! No heap allocation on the cycle path: a counting global allocator around
//! 10,000 cycles of a small hierarchy with commands flowing.
//!
//! Only allocations of the measuring thread, inside its measured region,
//! are counted: the test harness's own threads (and other tests of this
//! binary) allocate whenever they like, so a count of every thread fails at
//! random on a loaded machine.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::{Arc, Barrier};
use std::time::Duration;

use common::{Relay, GO, HOLD};
use rcs_runtime::{Executive, ExecutiveConfig, GlobalMemory, Operator, Status, VerbId};

struct Counting;

thread_local! {
    /// `Some(n)`: this thread is measuring and has allocated `n` times so
    /// far; `None`: not counted. `const`-initialised and without a
    /// destructor, so reading it never allocates (no lazy registration)
    /// and the allocator cannot recurse into itself.
    static MEASURED: Cell<Option<u64>> = const { Cell::new(None) };
}

fn count_one() {
    // `try_with`: during thread teardown the slot may be gone; not counted.
    let _ = MEASURED.try_with(|m| {
        if let Some(n) = m.get() {
            m.set(Some(n + 1));
        }
    });
}

// SAFETY: forwards to the system allocator, only counting calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_one();
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_one();
        // SAFETY: same contract as ours.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Run `f` on this thread and count the heap allocations it makes here.
fn allocations_in<R>(f: impl FnOnce() -> R) -> (u64, R) {
    MEASURED.with(|m| m.set(Some(0)));
    let r = f();
    let n = MEASURED.with(|m| m.replace(None)).unwrap_or(0);
    (n, r)
}

#[test]
fn the_counter_sees_this_threads_allocations_and_only_those() {
    let (n, boxed) = allocations_in(|| std::hint::black_box(Box::new(7u64)));
    assert_eq!(n, 1, "a Box inside the measured region is counted");
    let (n, v) = allocations_in(|| {
        let mut v = Vec::with_capacity(1);
        v.extend([1u8, 2, 3]); // grows: a realloc
        std::hint::black_box(v)
    });
    assert_eq!(n, 2, "an alloc and a realloc");
    // Outside a measured region nothing is counted.
    drop((boxed, v, Box::new(1u8)));

    // Another thread allocating while this one measures is not counted.
    let gate = Arc::new(Barrier::new(2));
    let other = {
        let gate = Arc::clone(&gate);
        std::thread::spawn(move || {
            gate.wait();
            let v: Vec<u64> = std::hint::black_box((0..1000).collect());
            gate.wait();
            v.len()
        })
    };
    let (n, ()) = allocations_in(|| {
        gate.wait(); // the other thread allocates now…
        gate.wait(); // …and is done
    });
    assert_eq!(n, 0, "another thread's allocations are not this thread's");
    assert_eq!(other.join().unwrap(), 1000);
}

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

    let (allocations, done) = allocations_in(|| {
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
        done
    });

    assert_eq!(exec.cycle(), 10 + 10_000);
    assert!(done >= 60, "commands completed: {done}");
    assert_eq!(allocations, 0, "heap allocations on the cycle path");
}
