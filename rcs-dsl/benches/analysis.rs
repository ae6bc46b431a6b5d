//! The analysis of conditions, one plan at a time: every plan of the
//! project's plan sets and of the golden corpus (`plans/`, `tests/data/`),
//! each put through everything the checks can ask of it: each row can
//! match; each row can fire in each state; each row can fire while each
//! other row holds, in each state; and the questions across cycles (hangs,
//! rows bound by the command's values, livelocks, command storms). Prints the slowest plans of ≤ 10 rows
//! (besides `otherwise`), then measures the slowest one with criterion.
//!
//! Run: `cargo bench -p rcs-dsl --bench analysis`

use criterion::{criterion_group, criterion_main, Criterion};
use rcs_dsl::analysis::PlanAnalysis;
use rcs_dsl::ir::{Condition, Ir, StateId};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Every plan set below the repository's `plans/` and `tests/data/`.
fn plan_sets() -> Vec<(String, Ir)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut paths: Vec<PathBuf> = vec![root.join("plans")];
    for kind in ["ok", "err"] {
        let dir = root.join("tests/data").join(kind);
        let mut cases: Vec<PathBuf> = std::fs::read_dir(&dir)
            .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
        cases.retain(|p| p.is_dir() || p.extension().is_some_and(|e| e == "rcs"));
        cases.retain(|p| !p.ends_with("snapshots"));
        cases.sort();
        paths.extend(cases);
    }
    let mut out = Vec::new();
    for path in paths {
        let Ok(sets) = rcs_dsl::load_paths(std::slice::from_ref(&path)) else {
            continue;
        };
        for set in &sets {
            if let Some(ir) = rcs_dsl::lower_unchecked(set) {
                let name = path.strip_prefix(&root).unwrap_or(&path).display();
                out.push((format!("{name} ({})", set.name), ir));
            }
        }
    }
    out
}

/// Every proof the checks can ask of one plan.
fn analyse(ir: &Ir, ci: usize, pi: usize) {
    let c = &ir.controllers[ci];
    let p = &c.plans[pi];
    let a = PlanAnalysis::new(ir, c, p);
    // Across cycles: hangs, rows bound by entry values, loops, storms.
    std::hint::black_box(a.hangs());
    std::hint::black_box(a.entry_bound_rows());
    std::hint::black_box(rcs_dsl::analysis::cycles::livelocks(c, p, &a));
    std::hint::black_box(rcs_dsl::analysis::cycles::command_storms(c, p, &a));
    for r in 0..p.rows.len() {
        std::hint::black_box(a.never_matches(r));
        for s in 0..p.states.len() {
            let s = StateId(s as u32);
            std::hint::black_box(a.never_fires_in(r, s));
            for o in r + 1..p.rows.len() {
                std::hint::black_box(a.never_fires_while(o, r, s));
            }
        }
    }
}

fn slowest(c: &mut Criterion) {
    let sets = plan_sets();
    let mut timed: Vec<(Duration, String, usize, usize, usize)> = Vec::new();
    for (si, (name, ir)) in sets.iter().enumerate() {
        for (ci, ctrl) in ir.controllers.iter().enumerate() {
            for (pi, p) in ctrl.plans.iter().enumerate() {
                let rows = p
                    .rows
                    .iter()
                    .filter(|r| !matches!(r.cond, Condition::Otherwise))
                    .count();
                if rows > 10 {
                    continue;
                }
                // The best of a few runs: the machine may be busy.
                let best = (0..5)
                    .map(|_| {
                        let t = Instant::now();
                        analyse(ir, ci, pi);
                        t.elapsed()
                    })
                    .min()
                    .unwrap_or_default();
                let verb = &ctrl.commands[p.verb.index()].name;
                timed.push((best, format!("{name} {}.{verb}", ctrl.name), si, ci, pi));
            }
        }
    }
    timed.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
    println!("{} plans of ≤ 10 rows; the slowest:", timed.len());
    for (t, name, ..) in timed.iter().take(5) {
        println!("  {:>9.1} µs  {name}", t.as_secs_f64() * 1e6);
    }
    let Some((_, name, si, ci, pi)) = timed.first() else {
        return;
    };
    let ir = &sets[*si].1;
    c.bench_function(&format!("analysis/slowest plan: {name}"), |b| {
        b.iter(|| analyse(ir, *ci, *pi))
    });
}

criterion_group!(benches, slowest);
criterion_main!(benches);
