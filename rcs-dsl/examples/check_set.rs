//! One `rcs_dsl::check` of the benchmark's generated plan set, for
//! profilers: `cargo build --release -p rcs-dsl --example check_set`, then
//! `valgrind --tool=callgrind target/release/examples/check_set 100`;
//! `check_set 1000 5` times five checks of the 1,000-controller set.

#[path = "../benches/common/plan_set.rs"]
mod plan_set;

use rcs_dsl::{check, Options, PlanSet};

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(100);
    let runs: usize = std::env::args()
        .nth(2)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1);
    let files = plan_set::plan_set(n);
    let bytes: usize = files.iter().map(|(_, t)| t.len()).sum();
    let set = PlanSet::from_texts(
        "bench",
        files.iter().map(|(p, t)| (p.as_str(), t.as_str())),
        None,
    );
    for _ in 0..runs {
        let start = std::time::Instant::now();
        let checked = check(&set, &Options::default());
        let took = start.elapsed();
        assert!(checked.diagnostics.is_empty());
        if runs > 1 {
            println!(
                "{n} controllers, {bytes} bytes: {:.1} ms, {:.2} MB/s",
                took.as_secs_f64() * 1e3,
                bytes as f64 / took.as_secs_f64() / 1e6
            );
        }
    }
}
