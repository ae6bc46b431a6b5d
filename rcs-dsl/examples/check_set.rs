//! One `rcs_dsl::check` of the benchmark's generated plan set, for
//! profilers: `cargo build --release -p rcs-dsl --example check_set`, then
//! `valgrind --tool=callgrind target/release/examples/check_set 100`;
//! `check_set 1000 5` times five checks of the 1,000-controller set, with
//! the CPU time (user and system) and the page faults of each, read from
//! `/proc/self/stat` on Linux: on this workload system time is page faults,
//! so memory shows up in wall time.

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
        let before = Usage::now();
        let start = std::time::Instant::now();
        let checked = check(&set, &Options::default());
        let checked_in = start.elapsed();
        assert!(checked.diagnostics.is_empty());
        // Freeing the result is part of the cost of a `check` (criterion's
        // `check` benchmark times it too).
        drop(checked);
        let took = start.elapsed();
        let used = since(before, Usage::now());
        let dropped_in = took - checked_in;
        if runs > 1 {
            print!(
                "{n} controllers, {bytes} bytes: {:.1} ms ({:.1} ms of it freeing the result), {:.2} MB/s",
                took.as_secs_f64() * 1e3,
                dropped_in.as_secs_f64() * 1e3,
                bytes as f64 / took.as_secs_f64() / 1e6
            );
            match used {
                Some(u) => println!(
                    " (user {} ms, system {} ms, {} page faults)",
                    u.user_ms, u.system_ms, u.faults
                ),
                None => println!(),
            }
        }
    }
}

/// CPU time and minor page faults of this process so far (Linux only).
#[derive(Clone, Copy)]
struct Usage {
    user_ms: u64,
    system_ms: u64,
    faults: u64,
}

impl Usage {
    fn now() -> Option<Usage> {
        let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
        // Fields after the command name, which is in parentheses and may
        // hold spaces: state is field 3, minflt 10, utime 14, stime 15.
        let rest = &stat[stat.rfind(')')? + 2..];
        let fields: Vec<&str> = rest.split(' ').collect();
        let field = |n: usize| fields.get(n - 3)?.parse::<u64>().ok();
        // Clock ticks are 100 per second on every Linux this runs on.
        Some(Usage {
            user_ms: field(14)? * 10,
            system_ms: field(15)? * 10,
            faults: field(10)?,
        })
    }
}

/// What was used between two readings.
fn since(before: Option<Usage>, after: Option<Usage>) -> Option<Usage> {
    let (b, a) = (before?, after?);
    Some(Usage {
        user_ms: a.user_ms.saturating_sub(b.user_ms),
        system_ms: a.system_ms.saturating_sub(b.system_ms),
        faults: a.faults.saturating_sub(b.faults),
    })
}
