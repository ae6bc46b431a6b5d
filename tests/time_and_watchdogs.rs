//! Time in seconds and watchdogs on buffers (LANGUAGE.md §8), end to end
//! through `rcsc test`: the property below, the ok cases' scenarios on both
//! backends, and the scenario key `silent:` refused where it is wrong.
//!
//! The property: for random CPU
//! periods and durations, a row `S1 when state_time > D` fires on exactly
//! the first cycle at which the time in S1 (cycles × period) exceeds D —
//! never a cycle early, never a cycle late — on the interpreter and on the
//! generated code. (`>=` rows too: the first cycle at which it reaches D.)
//!
//! A seeded loop draws the cases (the same every run): each is a controller
//! on a CPU of its own with the drawn period, its duration written in a
//! drawn unit (`ns`, `us`, `ms`, `s`, with decimals where they are exact).
//! The expected cycle is computed here with plain 128-bit arithmetic,
//! independently of rcsc's lowering, and written into a scenario per
//! controller: no row before that cycle, the timeout row on it. `rcsc test`
//! runs the scenarios on both backends; every one must pass.

mod common;

use common::{rcsc, scratch, text};
use std::fmt::Write as _;
use std::path::Path;

/// A small deterministic generator (xorshift64*): no dependency, the same
/// cases on every run and every machine.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// `ns` written in a unit that states it exactly, drawn at random: a whole
/// number of the unit, or a decimal one when the fraction is exact.
fn written(ns: u64, rng: &mut Rng) -> String {
    let units = [
        ("ns", 1u64),
        ("us", 1_000),
        ("ms", 1_000_000),
        ("s", 1_000_000_000),
    ];
    let (unit, scale) = units[rng.below(4) as usize];
    if ns.is_multiple_of(scale) {
        return format!("{}{unit}", ns / scale);
    }
    let digits = scale.ilog10() as usize;
    if digits == 0 {
        return format!("{ns}ns");
    }
    format!("{}.{:0digits$}{unit}", ns / scale, ns % scale)
}

struct Case {
    period_ns: u64,
    duration_ns: u64,
    at_least: bool,
}

impl Case {
    /// The cycle count in S1 at which the row first holds: the least
    /// `c >= 1` with `c × period > D` (or `>= D`).
    fn fires_at(&self) -> u64 {
        let (p, d) = (u128::from(self.period_ns), u128::from(self.duration_ns));
        let c = if self.at_least {
            d.div_ceil(p)
        } else {
            d / p + 1
        };
        c.max(1) as u64
    }
}

fn cases() -> Vec<Case> {
    let mut rng = Rng(0x5eed_7113_0000_0001);
    let mut out = Vec::new();
    for k in 0..40 {
        // Periods from 1 us to 100 ms, often not round; a few round ones.
        let period_ns = match k % 4 {
            0 => [1_000_000, 10_000_000, 4_000_000, 250_000][rng.below(4) as usize],
            _ => 1_000 + rng.below(100_000_000),
        };
        // Durations up to ~3,000 periods (a scenario step runs that fast),
        // sometimes an exact multiple, sometimes one nanosecond off one.
        let cycles = rng.below(3_000);
        let duration_ns = match rng.below(4) {
            0 => cycles * period_ns,
            1 => (cycles * period_ns).saturating_sub(1),
            2 => cycles * period_ns + 1,
            _ => cycles * period_ns + rng.below(period_ns),
        };
        out.push(Case {
            period_ns,
            duration_ns,
            at_least: k % 3 == 2,
        });
    }
    out
}

/// The plan set: controller `Tk` on CPU `cpuk`, and its scenario.
fn plan_set(cases: &[Case]) -> Vec<(String, String)> {
    let mut rng = Rng(0xd0_0d1e);
    let mut rcs = String::new();
    let mut yaml = String::from("lints: { timer_resolution: allow }\nschedule:\n");
    let mut files = Vec::new();
    for (k, c) in cases.iter().enumerate() {
        let op = if c.at_least { ">=" } else { ">" };
        let d = written(c.duration_ns, &mut rng);
        writeln!(
            rcs,
            "controller T{k} {{\n    command GO\n    plan GO {{\n        \
             E0: *0 when new_command -> S1\n        \
             E1: S1 when state_time {op} {d} -> Done\n    }}\n}}"
        )
        .unwrap();
        writeln!(
            yaml,
            "  - cpu: cpu{k}\n    period: {}ns\n    order: [T{k}]",
            c.period_ns
        )
        .unwrap();
        let n = c.fires_at();
        let mut s = format!(
            "name: T{k} `state_time {op} {d}` on a {} ns period fires at cycle {n}\n\
             controller: T{k}\nsteps:\n  - command: GO\n    expect: {{ fired: E0, state: S1 }}\n",
            c.period_ns
        );
        if n > 1 {
            writeln!(
                s,
                "  - cycles: {}\n    expect: {{ fired: none, state: S1 }}",
                n - 1
            )
            .unwrap();
        }
        s.push_str("  - expect: { fired: E1, status: DONE }\n");
        files.push((format!("set/scenarios/t{k}.scenario.yaml"), s));
    }
    files.push(("set/timers.rcs".to_string(), rcs));
    files.push(("set/rcs.yaml".to_string(), yaml));
    files
}

#[test]
fn a_timeout_fires_on_the_first_cycle_past_its_duration_on_both_backends() {
    let cases = cases();
    let files = plan_set(&cases);
    let refs: Vec<(&str, &str)> = files
        .iter()
        .map(|(p, b)| (p.as_str(), b.as_str()))
        .collect();
    let dir = scratch("timers", &refs);
    let set = dir.join("set");
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join("rcsc-test-driver-time");
    let run = |backend: &str| {
        let out = rcsc(&[
            "test",
            set.to_str().unwrap(),
            "--backend",
            backend,
            "--target-dir",
            target.to_str().unwrap(),
        ]);
        let stdout = text(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{backend}:\n{stdout}{}",
            text(&out.stderr)
        );
        assert_eq!(
            stdout.lines().last(),
            Some(&*format!("{} passed, 0 failed", cases.len())),
            "{stdout}"
        );
        stdout
    };
    let interp = run("interp");
    assert_eq!(
        run("compiled"),
        interp,
        "identical reports on both backends"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// The property can fail: a scenario that expects the row one cycle early
/// (the rounding a careless lowering would do) fails on the interpreter.
#[test]
fn a_timeout_expected_one_cycle_early_fails() {
    let case = Case {
        period_ns: 3_000_000,
        duration_ns: 10_000_000,
        at_least: false,
    };
    assert_eq!(
        case.fires_at(),
        4,
        "3 ms × 4 = 12 ms is the first past 10 ms"
    );
    let scenario = "controller: T\nsteps:\n  - command: GO\n  - cycles: 2\n    expect: { fired: none }\n  - expect: { fired: E1 }\n";
    let dir = scratch(
        "early",
        &[
            (
                "set/t.rcs",
                "controller T {\n    command GO\n    plan GO {\n        E0: *0 when new_command -> S1\n        E1: S1 when state_time > 10ms -> Done\n    }\n}\n",
            ),
            ("set/rcs.yaml", "lints: { timer_resolution: allow }\nschedule:\n  - cpu: main\n    period: 3ms\n    order: [T]\n"),
            ("set/scenarios/early.scenario.yaml", scenario),
        ],
    );
    let out = rcsc(&["test", dir.join("set").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stdout));
    assert!(
        text(&out.stdout).contains("0 passed, 1 failed"),
        "{}",
        text(&out.stdout)
    );
    std::fs::remove_dir_all(dir).ok();
}

/// The ok cases of durations (0620) and buffer watchdogs (0630): their
/// scenarios — timeouts that fire neither early nor late, a subordinate and
/// buffers held `silent:`, a buffer written again — pass on both backends
/// with every row covered, and both print the same report.
#[test]
fn durations_and_watchdogs_pass_their_scenarios_on_both_backends() {
    let sets = [
        "tests/data/ok/0620_durations",
        "tests/data/ok/0630_buffer_watchdog",
    ];
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join("rcsc-test-driver-time-ok");
    let run = |backend: &str| {
        let mut args = vec!["test", "--coverage", "--backend", backend, "--target-dir"];
        args.push(target.to_str().unwrap());
        args.extend(sets);
        let out = rcsc(&args);
        let stdout = text(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{stdout}{}", text(&out.stderr));
        assert!(stdout.contains("rows fired: 14/14"), "{stdout}");
        assert_eq!(
            stdout.lines().last(),
            Some("8 passed, 0 failed"),
            "{stdout}"
        );
        stdout
    };
    let interp = run("interp");
    assert_eq!(
        run("compiled"),
        interp,
        "identical reports on both backends"
    );
}

/// `silent:` names `reads` buffers; a subordinate, an unknown name, or a
/// buffer both written and held in one step is refused with its line.
#[test]
fn silent_is_refused_where_it_names_no_reads_buffer() {
    let set = "tests/data/ok/0630_buffer_watchdog";
    let cases = [
        (
            "controller: AXIS\nsteps:\n  - command: MOVE\n  - silent: [DRIVE]\n",
            "4: error: `AXIS` reads no buffer `DRIVE`; a subordinate is held with `subordinates: { DRIVE: { silent: true } }`",
        ),
        (
            "controller: DRIVE\nsteps:\n  - command: ENABLE\n  - silent: [framez]\n",
            "4: error: `DRIVE` reads no buffer `framez`",
        ),
        (
            "controller: DRIVE\nsteps:\n  - command: ENABLE\n  - silent: [frame]\n    reads: { frame: { position: 1 } }\n",
            "4: error: `frame` is both written (`reads:`) and `silent:` in one step",
        ),
        (
            "controller: DRIVE\nsteps:\n  - command: ENABLE\n  - silent: 3\n",
            "4: error: `silent` is a list of `reads` buffers held unwritten",
        ),
    ];
    for (k, (scenario, want)) in cases.iter().enumerate() {
        let dir = scratch(&format!("silent{k}"), &[("s.scenario.yaml", scenario)]);
        let file = dir.join("s.scenario.yaml");
        let out = rcsc(&["test", set, file.to_str().unwrap()]);
        let stdout = text(&out.stdout);
        assert_ne!(out.status.code(), Some(0), "{stdout}");
        assert!(
            stdout.contains(want),
            "want `{want}` in:\n{stdout}{}",
            text(&out.stderr)
        );
        std::fs::remove_dir_all(dir).ok();
    }
}
