//! Differential test: the reference interpreter (`rcs_dsl::interp::Driven`)
//! and the generated Rust (`rcs_plan_sets::SETS`, compiled by build.rs with
//! the scenario driver) run every plan of every plan set of the repository
//! identically.
//!
//! For every plan set, every controller and every plan, 1,000 random input
//! sequences (proptest; fixed seeds and no failure persistence, so CI plays
//! the same sequences every time) are played against both backends through
//! the one `rcs_runtime::driver::Driven` interface. A sequence sets the
//! world's `reads` buffers, commands the plan's verb, then takes 1–30
//! steps; a step may send a new command (any verb, random typed arguments),
//! make an ill-formed driver call (unknown names, wrong arity, values of the
//! wrong type or out of range), change `reads` buffers (whole, or a few
//! scalars so that conditions met earlier stay met), set hook results and
//! answer for subordinates (DONE, ERROR, EXECUTING or any status of theirs,
//! echoing the serial last sent, an older one or a random one), then runs
//! one cycle — now and then 50–300, so that `state_cycles`, `plan_cycles`
//! and `stale_cycles` timeouts fire. Values follow the IR types: integers
//! favour 0, ±1, the type's bounds and the numeric literals of the
//! controller's own expressions (±1, negated), floats the literals, ±0 and
//! small numbers, so that row conditions come true.
//!
//! Both backends get exactly the same calls. Every call must give the same
//! `Ok`/`Err` on both, and after every cycle the two `Record`s must be the
//! same in full (fired row, state, status, error, verb, sent commands, vars,
//! `writes` buffers; floats compared as `{:?}` prints them, so NaN equals
//! NaN and -0.0 differs from 0.0). A divergence fails with the plan set,
//! controller, plan, step, both records and the calls so far, shrunk by
//! proptest to a small sequence.
//!
//! The test is not vacuous: every row of every plan must fire on both
//! backends in some sequence (a plan whose rows have not all fired after
//! 1,000 sequences gets up to seven more rounds of 1,000, which explore
//! further: one sequence in two starts from random values of the
//! controller's vars and status fields, as a scenario's `initial: vars`
//! may, about one step in three ends with every subordinate answering its
//! latest command DONE, one sequence in two writes its `reads` buffers
//! before every cycle, as a live fieldbus master does, so that a state
//! timeout longer than a frame watchdog can fire, and a subordinate's error
//! code is now and then a built-in one, `INDEX_RANGE` or `HOOK_PANIC`),
//! except the rows listed in [`NEVER_FIRE`], each of
//! which provably cannot fire from the declared initial values (and must
//! indeed never fire from them); and `a_swapped_row_is_caught` shows that a code
//! generator that gets row precedence wrong is caught, as a divergence
//! rather than a crash.
//!
//! `cargo test -p rcs-plan-sets --test differential -- --nocapture` prints
//! a summary: plans, sequences, cycles, driver calls, rows fired, the rows
//! that fired least and the rows that cannot fire.

use proptest::prelude::*;
use proptest::test_runner::TestError;
use rcs_dsl::ir::{Condition, From};
use rcs_plan_sets::SETS;
use std::fmt::Write as _;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Random sequences per plan.
const SEQUENCES: u32 = 1000;
/// Steps per sequence (after the first command).
const MAX_STEPS: usize = 30;

/// Rows that cannot fire whatever the inputs, as `(plan set, controller,
/// verb, row position, why)`: golden test cases written to exercise the
/// checker (shadowed rows, unreachable states, an `otherwise` after an
/// always-true row), not to run. Each must indeed never fire (so the list
/// stays true); every row not listed must fire on both backends.
const NEVER_FIRE: &[(&str, &str, &str, u32, &str)] = &[
    (OK_0009, "A", "ONE", 1, "`S1 when ready`: `ready` starts false and only TWO's `*3 otherwise` sets it, which never fires"),
    (OK_0009, "A", "ONE", 3, "`*3 when plan_cycles > 99`: ONE sits in S1 from its first cycle, so E2 (`state_cycles > 9`, earlier) ends it at plan cycle 10"),
    (OK_0009, "A", "TWO", 1, "`S0_wait when ready`: `ready` is never true (see ONE row 1)"),
    (OK_0009, "A", "TWO", 3, "`*3 otherwise`: TWO leaves S0 on its first cycle (new_command), and in S0_wait `ready` or `!ready` always matches"),
    (OK_0011, "A", "GO", 2, "`S2 when ready`: `ready` starts false and nothing sets it"),
    (OK_0011, "A", "GO", 4, "`otherwise`: `*3 when true` always matches first"),
    (OK_0017, "B", "RUN", 3, "`S2 when true -> Done`: shadowed by `S2 when true -> S1` (`#[allow(shadowed_row)]`)"),
    (OK_0017, "B", "RUN", 4, "`S9 when true`: nothing goes to S9 (`#[allow(unreachable_state)]`)"),
    (OK_0018, "A", "GO", 0, "`new_command && gear == Low`: `gear` starts High and is only ever set to High"),
    (OK_0018, "A", "GO", 2, "S1: reached only through row 0"),
    (OK_0018, "A", "GO", 3, "S2: reached only through row 0"),
    (OK_0018, "A", "GO", 4, "S3: reached only through row 0"),
    (OK_0018, "A", "GO", 5, "S4: reached only through row 0"),
    (OK_0018, "A", "GO", 6, "S5: reached only through row 0"),
    (OK_0018, "A", "GO", 7, "S6: reached only through row 0"),
    (OK_0018, "A", "GO", 8, "S7: reached only through row 0"),
    (OK_0018, "A", "GO", 9, "S8: reached only through row 0"),
    (OK_0018, "A", "GO", 10, "`*10 when state_cycles > 100`: row 1 ends every GO on its first cycle"),
    (OK_0018, "A", "GO", 11, "S1: reached only through row 0"),
    (OK_0107, "H", "ARGS", 2, "`reading(1) == Mid && reading(2) == Low`: the scripted hooks answer one value per hook, whatever the arguments"),
    (OK_0107, "H", "ARGS", 3, "`reading(2) == Low` after `reading(1) == Low`: one scripted value per hook (see row 2)"),
    (OK_0114, "A", "GO", 3, "`state_cycles > 50`: `a * b > 10` or `a * b <= 10` always matches first (the analysis leaves products alone, so it says nothing)"),
    (OK_0115, "A", "GO", 2, "`ok(2)` after `ok(1)`: the scripted hooks answer one value per hook, whatever the arguments"),
    (OK_0121, "A", "GO", 3, "`state_cycles > 4`: `a < b` or `a >= b` always matches first (two inputs compared: left alone by the analysis)"),
    (OK_0126, "A", "GO", 2, "`S2 when state_cycles > 5`: plan_cycles is always above state_cycles, so row 3 (`plan_cycles > 5`) ends S2 first"),
    (OK_0131, "B", "RUN", 1, "`state_cycles > 9`: row 2 (`plan_cycles > 3`) ends RUN first, plan_cycles being at least state_cycles"),
    (OK_0132, "B", "RUN", 1, "`state_cycles > 20`: row 2 (`plan_cycles > 3`) ends RUN first"),
    (OK_0133, "A", "GO", 4, "`otherwise`: `x < 0`, `x > 0` and `x == 0` cover every integer"),
    (OK_0137, "A", "GO", 3, "`plan_cycles > 60`: `reading() > limit` or `reading() <= limit` always matches first"),
    (OK_1209, "Feeder", "FEED", 5, "`S2 when !s.ready -> S1`: the entry sets `armed` and nothing clears it, so row 4 (`S2 when armed`) always fires first — the trap the case is about"),
];
const OK_1209: &str = "tests/data/ok/1209_livelock_var_row_leaves_ring.rcs";
const OK_0114: &str = "tests/data/ok/0114_analysis_opaque_products.rcs";
const OK_0115: &str = "tests/data/ok/0115_analysis_hooks_with_different_arguments.rcs";
const OK_0121: &str = "tests/data/ok/0121_analysis_two_inputs_compared.rcs";
const OK_0126: &str = "tests/data/ok/0126_analysis_state_then_plan_cycles.rcs";
const OK_0131: &str = "tests/data/ok/0131_analysis_stale_watchdog_handles_error.rcs";
const OK_0132: &str = "tests/data/ok/0132_analysis_error_handled_by_timeout.rcs";
const OK_0133: &str = "tests/data/ok/0133_analysis_three_way_split_then_otherwise.rcs";
const OK_0137: &str = "tests/data/ok/0137_analysis_hook_compared_with_var.rcs";
const OK_0009: &str = "tests/data/ok/0009_targets_and_otherwise.rcs";
const OK_0011: &str = "tests/data/ok/0011_otherwise_never_shadowed.rcs";
const OK_0017: &str = "tests/data/ok/0017_lint_levels";
const OK_0018: &str = "tests/data/ok/0018_allowed_lints_and_bare_initialisers.rcs";
const OK_0107: &str = "tests/data/ok/0107_analysis_hooks_and_arguments.rcs";

mod hierarchies;
mod inputs;
mod running;
mod systems;

use running::*;

#[test]
fn every_plan_runs_the_same_on_interpreter_and_generated_code() {
    let start = Instant::now();
    // The plan sets are independent: spread them over the cores.
    let next = AtomicUsize::new(0);
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get().min(4));
    let mut reports: Vec<(usize, Report)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(set) = SETS.get(i) else { break done };
                        done.push((i, check_set(set)));
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("a worker panicked"))
            .collect()
    });
    reports.sort_by_key(|(i, _)| *i);
    let mut all = Report::default();
    for (_, r) in reports {
        all.controllers += r.controllers;
        all.plans += r.plans;
        all.rows += r.rows;
        all.sequences += r.sequences;
        all.cycles += r.cycles;
        all.calls += r.calls;
        all.extra_rounds.extend(r.extra_rounds);
        all.divergences.extend(r.divergences);
        all.never.extend(r.never);
        all.unexpected.extend(r.unexpected);
        all.listed_but_fired.extend(r.listed_but_fired);
        all.fired.extend(r.fired);
    }
    println!(
        "differential: {} plan sets, {} controllers, {} plans, {} sequences, {} cycles, \
         {} driver calls; {}/{} rows fired on both backends; {} divergences; {:.1} s",
        SETS.len(),
        all.controllers,
        all.plans,
        all.sequences,
        all.cycles,
        all.calls,
        all.fired.len(),
        all.rows,
        all.divergences.len(),
        start.elapsed().as_secs_f64()
    );
    for r in &all.extra_rounds {
        println!("differential: more sequences: {r}");
    }
    all.fired.sort();
    for (t, name) in all.fired.iter().take(5) {
        println!("differential: rarely fired: {name}, {t} times");
    }
    for n in &all.never {
        println!("differential: never fired (cannot fire, see NEVER_FIRE): {n}");
    }
    assert!(
        all.divergences.is_empty(),
        "the interpreter and the generated code diverge:\n{}",
        all.divergences.join("\n\n")
    );
    assert!(
        all.unexpected.is_empty(),
        "rows that never fired on both backends (add inputs that reach them, \
         or list them in NEVER_FIRE with the reason):\n{}",
        all.unexpected.join("\n")
    );
    assert!(
        all.listed_but_fired.is_empty(),
        "rows listed in NEVER_FIRE that fired:\n{}",
        all.listed_but_fired.join("\n")
    );
    assert!(
        all.plans >= SETS.len() as u64 && all.sequences >= all.plans * u64::from(SEQUENCES),
        "every plan got its sequences"
    );
}

/// A broken code generator is caught: the interpreter runs figure13's RUN
/// plan with rows E2 (`S1 when ev.e2 -> S1`) and E3 (`S1 when ev.e3 -> S2`)
/// swapped — both can be true in S1, so precedence decides — against the
/// generated code of the plan as written. The rows keep their `position`,
/// so a fired id still names the row as written: only precedence differs.
#[test]
fn a_swapped_row_is_caught() {
    let set = SETS
        .iter()
        .find(|s| s.path == "plans/figure13")
        .expect("plans/figure13 is compiled");
    let ir = load(set.path);
    let ctrl = ir.controller_by_name("GX").expect("GX");
    let mut mutant = ir.clone();
    let c = &mut mutant.controllers[ctrl.index()];
    let verb = c
        .commands
        .iter()
        .position(|k| k.name == "RUN")
        .expect("RUN");
    let plan = &mut c.plans[c.commands[verb].plan.expect("a plan").index()];
    let e2 = plan
        .rows
        .iter()
        .position(|r| r.label == Some(2))
        .expect("E2");
    let e3 = plan
        .rows
        .iter()
        .position(|r| r.label == Some(3))
        .expect("E3");
    assert_eq!(e3, e2 + 1, "E2 and E3 are adjacent");
    assert_eq!(
        plan.rows[e2].from, plan.rows[e3].from,
        "E2 and E3 leave one state"
    );
    for r in [e2, e3] {
        assert!(
            matches!(plan.rows[r].cond, Condition::When(_)) && !plan.rows[r].is_dont_care(),
            "E2 and E3 are plain rows"
        );
        assert!(matches!(plan.rows[r].from, From::State(_)));
    }
    plan.rows.swap(e2, e3);

    let subject = Subject::new(set, &ir, &mutant, ctrl);
    let stats = Stats::default();
    match run_plan(&subject, verb, 0, &stats).map_err(|e| *e) {
        Ok(()) => panic!(
            "{} sequences of {} cycles missed the swapped rows",
            stats.sequences.get(),
            stats.cycles.get()
        ),
        Err(TestError::Fail(reason, minimal)) => {
            let reason = reason.message();
            println!("mutant caught; minimal sequence {minimal:?}\n{reason}");
            assert!(
                reason.starts_with("divergence between interpreter and generated code"),
                "caught as a divergence, not a crash: {reason}"
            );
            // Shrunk to the essentials: RUN, then at most a few steps.
            assert!(minimal.steps.len() <= 3, "shrunk: {minimal:?}");
        }
        Err(e) => panic!("not a divergence: {e}"),
    }
}
