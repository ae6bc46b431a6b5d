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
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Barrier};
use std::time::Duration;

use common::{Relay, GO, HOLD};
use rcs_runtime::{
    CycleSignal, Executive, ExecutiveConfig, GlobalMemory, Operator, Status, VerbId,
};

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
    // A cycle signal with a thread waiting on it, as the bridge's export
    // thread does: every cycle raises it, and wakes the waiter whenever it
    // has taken the last raise.
    let signal = CycleSignal::new();
    exec.set_cycle_signal(signal.clone());
    let stop = Arc::new(AtomicBool::new(false));
    let waiter = {
        let (signal, stop) = (signal.clone(), Arc::clone(&stop));
        std::thread::spawn(move || {
            let mut woken = 0u64;
            while !stop.load(Ordering::Acquire) {
                woken += u64::from(signal.wait(Duration::from_millis(100)));
            }
            woken
        })
    };
    // Warm up once (first-touch effects, lazily initialised statics).
    op.command(GO);
    exec.run_cycles(10).unwrap();

    let (allocations, done) = allocations_in(|| {
        let mut done = 0;
        for round in 0..100u32 {
            // Alternate a completing command and a superseding one.
            op.command(if round % 3 == 2 { HOLD } else { GO });
            exec.run_cycles(50).unwrap();
            if op.outcome() == Some((Status::DONE, Default::default())) {
                done += 1;
            }
            op.command(GO);
            exec.run_cycles(50).unwrap();
            let _ = handle.cycle();
        }
        done
    });

    stop.store(true, Ordering::Release);
    signal.raise();
    let woken = waiter.join().expect("the waiting thread");
    assert!(woken >= 1, "the signal never woke its waiter");
    assert_eq!(exec.cycle(), 10 + 10_000);
    assert!(done >= 60, "commands completed: {done}");
    assert_eq!(allocations, 0, "heap allocations on the cycle path");
}

/// The same hierarchy split over two Global Memories joined by Zenoh
/// bridges (TB in "process" B, on a thread of its own): the cycles of SM
/// and PR, which raise their bridge's cycle signal, still allocate nothing
/// while the bridges carry TB's command and status back and forth.
#[cfg(feature = "zenoh")]
#[test]
fn cycles_allocate_nothing_with_the_bridge_running() {
    use rcs_runtime::{Bridge, BridgeConfig, CommandBuffer, StatusBuffer};
    use std::time::Instant;

    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free port")
        .port();
    let ep = format!("tcp/127.0.0.1:{port}");
    let (gm_a, gm_b) = (GlobalMemory::new(), GlobalMemory::new());
    gm_a.declare_controller::<VerbId>("TB").unwrap();
    let mut exec = Executive::new(ExecutiveConfig::new("helm", Duration::from_millis(1))).unwrap();
    exec.add(Box::new(Relay::new(&gm_a, "SM", Some("PR"), 0).unwrap()))
        .unwrap();
    exec.add(Box::new(Relay::new(&gm_a, "PR", Some("TB"), 0).unwrap()))
        .unwrap();
    let mut engine =
        Executive::new(ExecutiveConfig::new("engine", Duration::from_millis(1))).unwrap();
    engine
        .add(Box::new(Relay::new(&gm_b, "TB", None, 3).unwrap()))
        .unwrap();
    let mut a = Bridge::builder(
        BridgeConfig::new("noalloc", "helm").listen(&ep).insecure(),
        &gm_a,
    );
    a.export::<CommandBuffer<VerbId>>("TB.command").unwrap();
    a.import::<StatusBuffer>("TB.status", "engine").unwrap();
    let a = a.start().unwrap();
    let mut b = Bridge::builder(
        BridgeConfig::new("noalloc", "engine")
            .connect(&ep)
            .insecure(),
        &gm_b,
    );
    b.import::<CommandBuffer<VerbId>>("TB.command", "helm")
        .unwrap();
    b.export::<StatusBuffer>("TB.status").unwrap();
    let b = b.start().unwrap();
    // Each executive raises its bridge's signal after every cycle, as the
    // generated `System::process` sets them up: the measured cycles below
    // include the raise.
    exec.set_cycle_signal(a.signal());
    engine.set_cycle_signal(b.signal());
    let stop = Arc::new(AtomicBool::new(false));
    let engine_thread = {
        let stop = Arc::clone(&stop);
        std::thread::spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                engine.step().unwrap();
                std::thread::sleep(Duration::from_millis(1));
            }
        })
    };
    let mut op = Operator::<VerbId>::connect(&gm_a, "SM").unwrap();
    let tb_status = gm_a.reader::<StatusBuffer>("TB.status").unwrap();
    // Warm up until the link carries TB's status (bounded).
    op.command(GO);
    let deadline = Instant::now() + Duration::from_secs(60);
    while tb_status.generation() == 0 && Instant::now() < deadline {
        exec.run_cycles(1).unwrap();
        std::thread::sleep(Duration::from_millis(1));
    }
    assert!(
        tb_status.generation() > 0,
        "the bridge never carried TB's status"
    );

    // Measure SM's and PR's cycles until the bridge has delivered 50 more of
    // TB's statuses into this Global Memory (bounded by a deadline).
    let start_gen = tb_status.generation();
    let imported_before = a.stats().imported;
    let (allocations, cycles) = allocations_in(|| {
        let mut cycles = 0u64;
        while tb_status.generation() < start_gen + 50 && Instant::now() < deadline {
            if cycles.is_multiple_of(40) {
                op.command(if cycles.is_multiple_of(120) { HOLD } else { GO });
            }
            exec.run_cycles(1).unwrap();
            cycles += 1;
            std::thread::sleep(Duration::from_micros(500));
        }
        cycles
    });
    stop.store(true, Ordering::Relaxed);
    engine_thread.join().unwrap();
    assert!(
        tb_status.generation() >= start_gen + 50,
        "the bridge stalled"
    );
    assert!(a.stats().imported > imported_before);
    assert!(cycles > 0);
    assert_eq!(
        allocations, 0,
        "heap allocations on the cycle path with the bridge running"
    );
}
