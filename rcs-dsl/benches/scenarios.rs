//! What `rcsc test` costs on the interpreter: every scenario of
//! `plans/submarine` (parsed once) run to the end, and one interpreted
//! cycle of PR in the servo loop, for the per-cycle figure.
//!
//! Run: `cargo bench -p rcs-dsl --bench scenarios`

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rcs_dsl::interp::{Driven, Value};
use rcs_dsl::scenario;
use rcs_dsl::source::SourceFile;
use rcs_runtime::driver::Driven as _;
use rcs_runtime::{Status, StatusBuffer};
use std::path::Path;

fn bench(c: &mut Criterion) {
    let set = rcs_dsl::load_folder(Path::new("../plans/submarine")).expect("plans");
    let ir = rcs_dsl::check(&set, &rcs_dsl::Options::default())
        .ir
        .expect("clean");
    let mut paths: Vec<_> = std::fs::read_dir("../plans/submarine/scenarios")
        .expect("scenarios")
        .map(|e| e.expect("entry").path())
        .collect();
    paths.sort();
    // The one-controller scenarios (system scenarios are not timed here).
    let scenarios: Vec<_> = paths
        .iter()
        .filter_map(|p| {
            let text = std::fs::read_to_string(p).expect("readable");
            match scenario::parse_any(&ir, &SourceFile::new(p.display().to_string(), text), "s")
                .expect("valid")
            {
                scenario::AnyScenario::One(s) => Some(s),
                scenario::AnyScenario::System(_) => None,
            }
        })
        .collect();
    let cycles: usize = scenarios
        .iter()
        .map(|s| scenario::run(&ir, s).fired.len())
        .sum();

    let mut group = c.benchmark_group("scenarios");
    group.throughput(Throughput::Elements(cycles as u64));
    group.bench_function("submarine_all_interp", |b| {
        b.iter(|| {
            for s in &scenarios {
                assert!(scenario::run(&ir, s).failure.is_none());
            }
        })
    });
    group.finish();

    // One PR cycle in S1 with TB answering DONE and the ship at the goal.
    let pr = ir.controller_by_name("PR").expect("PR");
    let mut d = Driven::new(&ir, pr);
    d.command("AHEAD", &[Value::Float(10.0)]).expect("verb");
    d.set_hook("speed_error", &Value::Enum(1)).expect("hook");
    d.cycle();
    c.bench_function("interp_pr_cycle", |b| {
        b.iter(|| {
            let serial = d.last_sent("TB").expect("TB");
            let done = StatusBuffer {
                echo_serial: serial,
                status: Status::DONE,
                ..StatusBuffer::default()
            };
            d.write_sub_status("TB", done).expect("TB");
            d.cycle()
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
