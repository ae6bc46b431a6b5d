//! One control cycle of propulsion (PR) in Appendix C's S1 servo loop, side
//! by side: the controller rcsc generates from `plans/submarine`, the same
//! plan hand-written in idiomatic Rust over the same runtime and buffers,
//! and the methodology's C template compiled with `-O2`. Each iteration
//! includes the harness playing the turbine and the ship.
//!
//! Two groups: `pr_servo_cycle` calls each Rust controller's `cycle` through
//! `&mut dyn Controller`, as the runtime's `Executive` does (the figure the
//! ratio target is about); `pr_servo_cycle_inlined` lets the compiler inline
//! `cycle` into criterion's loop, where code layout of the whole loop decides
//! as much as the controller does.
//!
//! Run: `cargo bench -p rcs-plan-sets --bench pr_cycle`

use criterion::{criterion_group, criterion_main, Criterion};
use rcs_plan_sets::servo;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("pr_servo_cycle");
    let mut generated = servo::generated().expect("setup");
    group.bench_function("generated", |b| b.iter(|| generated.step()));
    let mut hand = servo::hand_written().expect("setup");
    group.bench_function("hand_written", |b| b.iter(|| hand.step()));
    let mut c_loop = servo::CLoop::new().expect("the C port is free");
    group.bench_function("c_template_O2", |b| b.iter(|| c_loop.step()));
    group.finish();

    let mut group = c.benchmark_group("pr_servo_cycle_inlined");
    let mut generated = servo::generated().expect("setup");
    group.bench_function("generated", |b| b.iter(|| generated.step_inlined()));
    let mut hand = servo::hand_written().expect("setup");
    group.bench_function("hand_written", |b| b.iter(|| hand.step_inlined()));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
