//! The runtime's two overhead ratios, measured so that a loaded machine
//! cannot skew them: the executive's cost per controller with timing on
//! and off, and a Global Memory write + read against a plain copy of the
//! same size (64 and 512 bytes) — the bodies of `benches/runtime.rs`.
//!
//! Criterion measures one body for seconds, then the next, so a build
//! starting beside it changes one figure and not the other. Here the two
//! bodies of each pair alternate, batch by batch, in one process, and each
//! keeps its fastest batch (other processes only ever add time to a
//! batch). The ratios come from one run.
//!
//! `cargo run --release -p rcs-runtime --example overhead [ROUNDS]`
//! (default 3,000 rounds of one batch each).

use std::hint::black_box;
use std::time::{Duration, Instant};

use rcs_runtime::{Controller, CycleContext, Executive, ExecutiveConfig, GlobalMemory};

struct Noop(&'static str, u64);

impl Controller for Noop {
    fn name(&self) -> &str {
        self.0
    }
    fn cycle(&mut self, ctx: &CycleContext) {
        self.1 = black_box(ctx.cycle);
    }
}

const NAMES: [&str; 10] = ["C0", "C1", "C2", "C3", "C4", "C5", "C6", "C7", "C8", "C9"];

/// Nanoseconds per call of one batch of `per` calls of `f`.
fn batch(f: &mut impl FnMut(), per: u32) -> f64 {
    let t = Instant::now();
    for _ in 0..per {
        f();
    }
    t.elapsed().as_nanos() as f64 / f64::from(per)
}

/// The fastest batch of `a` and of `b`, alternated for `rounds` rounds.
fn alternate(rounds: u32, per: u32, mut a: impl FnMut(), mut b: impl FnMut()) -> (f64, f64) {
    let (mut best_a, mut best_b) = (f64::MAX, f64::MAX);
    for _ in 0..rounds {
        best_a = best_a.min(batch(&mut a, per));
        best_b = best_b.min(batch(&mut b, per));
    }
    (best_a, best_b)
}

/// A buffer of `N` words; only its size matters (so its field is never
/// read).
#[derive(Clone, Copy)]
#[allow(dead_code)]
struct Buf<const N: usize> {
    words: [u64; N],
}

impl<const N: usize> Default for Buf<N> {
    fn default() -> Self {
        Self { words: [0; N] }
    }
}

fn gm<const N: usize>(rounds: u32) {
    let gm = GlobalMemory::new();
    gm.declare::<Buf<N>>("b").expect("a new name");
    let mut w = gm.writer::<Buf<N>>("b").expect("the first writer");
    let r = gm.reader::<Buf<N>>("b").expect("a declared buffer");
    let v = Buf::<N> { words: [7; N] };
    let mut slot = Buf::<N>::default();
    let mut cycle = 0u64;
    let (gm_ns, plain_ns) = alternate(
        rounds,
        200,
        || {
            cycle += 1;
            w.write(black_box(v), cycle);
            black_box(r.read());
        },
        || {
            let dst = black_box(&mut slot);
            *dst = black_box(v);
            black_box(*black_box(&*dst));
        },
    );
    println!(
        "Global Memory {} B: write + read {gm_ns:.2} ns, plain copy {plain_ns:.2} ns, ratio {:.2}",
        N * 8,
        gm_ns / plain_ns
    );
}

fn main() {
    let rounds: u32 = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("ROUNDS is a number"))
        .unwrap_or(3000);
    let executive = |measure: bool| {
        let cfg = ExecutiveConfig::new("bench", Duration::from_millis(1)).with_measure(measure);
        let mut e = Executive::new(cfg).expect("a valid period");
        for n in NAMES {
            e.add(Box::new(Noop(n, 0))).expect("distinct names");
        }
        e
    };
    let (mut on, mut off) = (executive(true), executive(false));
    let (on_ns, off_ns) = alternate(
        rounds,
        100,
        || {
            let _ = black_box(on.step());
        },
        || {
            let _ = black_box(off.step());
        },
    );
    println!(
        "executive, 10 no-op controllers: per controller {:.2} ns timing on, {:.2} ns timing off",
        on_ns / 10.0,
        off_ns / 10.0
    );
    // A console's monitor: the same executive, timing on, publishing its
    // figures in atomics after every controller (issue 31).
    let mut watched = executive(true);
    let _monitor = watched.attach_monitor(16);
    let (watched_ns, on_ns) = alternate(
        rounds,
        100,
        || {
            let _ = black_box(watched.step());
        },
        || {
            let _ = black_box(on.step());
        },
    );
    println!(
        "executive, 10 no-op controllers, timing on: per controller {:.2} ns with a console's monitor attached, {:.2} ns without",
        watched_ns / 10.0,
        on_ns / 10.0
    );
    gm::<8>(rounds);
    gm::<64>(rounds);
}
