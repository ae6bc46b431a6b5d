//! Criterion benchmarks of rcs-runtime: Global Memory write+read against a
//! plain copy, and executive overhead per controller per cycle.
//!
//! `cargo bench -p rcs-runtime --bench runtime -- --warm-up-time 1 --measurement-time 3`
//!
//! On a loaded machine, `examples/overhead.rs` gives the same ratios with
//! the two bodies of each pair alternated in one process.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rcs_runtime::{
    Controller, CycleContext, Executive, ExecutiveConfig, GlobalMemory, Operator, VerbId,
};

#[path = "../tests/common/mod.rs"]
mod common;

/// A buffer of `N` words; its contents only matter for their size.
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

impl<const N: usize> Buf<N> {
    fn new() -> Self {
        Self { words: [7; N] }
    }
}

fn gm_bench<const N: usize>(c: &mut Criterion) {
    let bytes = N * 8;
    let mut g = c.benchmark_group(format!("gm_{bytes}B"));
    let gm = GlobalMemory::new();
    gm.declare::<Buf<N>>("b").unwrap();
    let mut w = gm.writer::<Buf<N>>("b").unwrap();
    let r = gm.reader::<Buf<N>>("b").unwrap();
    let v = Buf::<N>::new();
    let mut cycle = 0u64;
    g.bench_function("write+read", |b| {
        b.iter(|| {
            cycle += 1;
            w.write(black_box(v), cycle);
            black_box(r.read())
        })
    });
    let mut slot = Buf::<N>::default();
    g.bench_function("plain copy in+out", |b| {
        b.iter(|| {
            let dst = black_box(&mut slot);
            *dst = black_box(v);
            black_box(*black_box(&*dst))
        })
    });
    g.finish();
}

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

fn exec_bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("executive_10_noop_controllers");
    g.throughput(Throughput::Elements(NAMES.len() as u64));
    for measure in [true, false] {
        let cfg = ExecutiveConfig::new("bench", Duration::from_millis(1)).with_measure(measure);
        let mut e = Executive::new(cfg).unwrap();
        for n in NAMES {
            e.add(Box::new(Noop(n, 0))).unwrap();
        }
        let label = if measure {
            "cycle (timing on)"
        } else {
            "cycle (timing off)"
        };
        g.bench_function(label, |b| b.iter(|| e.step()));
    }
    // Baseline: the same ten dynamic calls without the executive.
    let mut ctrls: Vec<Box<dyn Controller>> =
        NAMES.iter().map(|n| Box::new(Noop(n, 0)) as _).collect();
    let ctx = CycleContext {
        cycle: 0,
        now: std::time::Instant::now(),
        period: Duration::from_millis(1),
    };
    g.bench_function("bare dyn calls", |b| {
        b.iter(|| {
            for c in ctrls.iter_mut() {
                c.cycle(black_box(&ctx));
            }
        })
    });
    g.finish();
}

/// A realistic cycle: three hand-written controllers (SM -> PR -> TB) with
/// Global Memory reads and writes, handshake and plan bookkeeping, a new
/// command every 20 cycles.
fn hierarchy_bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("hierarchy_3_controllers");
    g.throughput(Throughput::Elements(3));
    for measure in [true, false] {
        let gm = GlobalMemory::new();
        let cfg = ExecutiveConfig::new("bench", Duration::from_millis(1)).with_measure(measure);
        let mut e = Executive::new(cfg).unwrap();
        e.add(Box::new(
            common::Relay::new(&gm, "SM", Some("PR"), 0).unwrap(),
        ))
        .unwrap();
        e.add(Box::new(
            common::Relay::new(&gm, "PR", Some("TB"), 0).unwrap(),
        ))
        .unwrap();
        e.add(Box::new(common::Relay::new(&gm, "TB", None, 5).unwrap()))
            .unwrap();
        let mut op = Operator::<VerbId>::connect(&gm, "SM").unwrap();
        let label = if measure {
            "cycle (timing on)"
        } else {
            "cycle (timing off)"
        };
        let mut n = 0u32;
        g.bench_function(label, |b| {
            b.iter(|| {
                if n.is_multiple_of(20) {
                    op.command(common::GO);
                }
                n = n.wrapping_add(1);
                e.step()
            })
        });
    }
    g.finish();
}

fn benches(c: &mut Criterion) {
    gm_bench::<8>(c); // 64 bytes
    gm_bench::<64>(c); // 512 bytes
    exec_bench(c);
    hierarchy_bench(c);
}

criterion_group!(group, benches);
criterion_main!(group);
