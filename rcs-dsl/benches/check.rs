//! Throughput of `rcs_dsl::check` (parse + lower + checks) on generated plan
//! sets of 100 and 1,000 controllers × 10 plans, spread over files of ten
//! controllers each, in a tree with five subordinates per supervisor.
//!
//! `check/parse_and_lower/N` times the front end alone on the same sets,
//! so the checks (and the analysis of conditions in them) are the
//! difference.
//!
//! Run: `cargo bench -p rcs-dsl --bench check`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use rcs_dsl::{check, Options, PlanSet};
#[path = "common/plan_set.rs"]
mod plan_set;
use plan_set::plan_set;

fn bench_check(c: &mut Criterion) {
    let mut group = c.benchmark_group("check");
    group.sample_size(10);
    for n in [100, 1000] {
        let files = plan_set(n);
        let bytes: usize = files.iter().map(|(_, t)| t.len()).sum();
        let set = PlanSet::from_texts(
            "bench",
            files.iter().map(|(p, t)| (p.as_str(), t.as_str())),
            None,
        );
        let checked = check(&set, &Options::default());
        assert!(
            checked.diagnostics.is_empty(),
            "generated set must check clean: {:?}",
            checked.diagnostics.first()
        );
        group.throughput(Throughput::Bytes(bytes as u64));
        group.bench_with_input(BenchmarkId::new("controllers", n), &set, |b, set| {
            b.iter(|| check(set, &Options::default()))
        });
        // The front end alone (parsing and lowering, no checks): the rest
        // of `check` is the checks, the analysis of conditions most of it.
        group.bench_with_input(BenchmarkId::new("parse_and_lower", n), &set, |b, set| {
            b.iter(|| rcs_dsl::lower_unchecked(set))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_check);
criterion_main!(benches);
