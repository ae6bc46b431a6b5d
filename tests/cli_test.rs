//! `rcsc test` end to end: the project's scenarios pass on both backends
//! with every row covered, failures read well and exit 1, scenario files
//! that name things the plans lack are refused with their line, and
//! coverage names the rows no scenario fired.

mod common;

use common::{rcsc, rcsc_in, scratch, text};
use std::path::Path;

fn scenario_count(set: &str) -> usize {
    std::fs::read_dir(Path::new(set).join("scenarios"))
        .expect("scenarios folder")
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .ends_with(".scenario.yaml")
        })
        .count()
}

/// Every `CTRL.VERB  n/m rows` line of a coverage report.
fn coverage_lines(out: &str) -> Vec<(String, usize, usize)> {
    out.lines()
        .filter_map(|l| {
            // A shared plan's name has spaces: `TASK.HOME | UNHOME  3/3 rows`.
            let (head, _) = l.trim().split_once(" rows")?;
            let (name, frac) = head.rsplit_once(' ')?;
            let (a, b) = frac.split_once('/')?;
            Some((name.trim().to_string(), a.parse().ok()?, b.parse().ok()?))
        })
        .collect()
}

/// Every plan set under `plans/`.
const PLAN_SETS: [&str; 6] = [
    "plans/bridgeport_io",
    "plans/fieldbus_drive",
    "plans/figure13",
    "plans/packml",
    "plans/rcs_ex",
    "plans/submarine",
];

/// The plans (coverage lines) of all of them: bridgeport_io 39 (TOOL 17,
/// SPINDLE 9, AUX 6, COOLANT 5, LUBE 2), fieldbus_drive 9 (DRIVE 5, AXIS 4),
/// figure13 1 (GX), packml 27 (UNIT 9,
/// and 6 for each of the Module instances INFEED, FILLER, CAPPER), rcs_ex 9
/// (EMOVE 3, PRIM 2, SERVO 2, TOOL 2), submarine 9 (SM 2, PR 3, TB 4).
const PLANS: usize = 39 + 9 + 1 + 27 + 9 + 9;

fn assert_full_coverage(out: &str, plans: usize) {
    let lines = coverage_lines(out);
    assert_eq!(lines.len(), plans, "one line per plan:\n{out}");
    for (name, fired, rows) in &lines {
        assert_eq!(fired, rows, "{name}: not every row fired:\n{out}");
    }
    assert!(!out.contains("not fired"), "{out}");
}

#[test]
fn the_project_scenarios_pass_on_the_interpreter_with_every_row_covered() {
    let out = rcsc(&["test", "plans/", "--coverage"]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}{}", text(&out.stderr));
    let n = PLAN_SETS
        .iter()
        .map(|set| scenario_count(set))
        .sum::<usize>();
    assert!(n >= 30, "the plans have their scenarios");
    assert_eq!(stdout.lines().filter(|l| l.ends_with("... ok")).count(), n);
    assert_eq!(
        stdout.lines().last(),
        Some(&*format!("{n} passed, 0 failed"))
    );
    assert_full_coverage(&stdout, PLANS);
    assert!(
        text(&out.stderr).contains("Running"),
        "status lines on stderr"
    );
}

#[test]
fn a_wrong_expectation_fails_with_file_line_expected_actual_and_rows_so_far() {
    let out = rcsc(&[
        "test",
        "plans/submarine",
        "tests/data/scenarios/wrong_expectation.scenario.yaml",
    ]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("test tests/data/scenarios/wrong_expectation.scenario.yaml ... FAILED"));
    assert!(
        stdout.contains("tests/data/scenarios/wrong_expectation.scenario.yaml:10: scenario `wrong_expectation` failed here"),
        "{stdout}"
    );
    assert!(
        stdout.contains("    fired: expected E2, got none"),
        "{stdout}"
    );
    assert!(stdout.contains("rows fired so far: E0, -"), "{stdout}");
    assert_eq!(stdout.lines().last(), Some("0 passed, 1 failed"));
}

#[test]
fn a_wrong_system_expectation_names_step_controller_and_key() {
    let out = rcsc(&[
        "test",
        "plans/submarine",
        "tests/data/scenarios/wrong_system_expectation.scenario.yaml",
    ]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("tests/data/scenarios/wrong_system_expectation.scenario.yaml:7: scenario `wrong_system_expectation` failed here\n    step 2, TB: state: expected S1, got S0\n  rows fired so far (2 ticks):\n    SM: E0, -\n    PR: E0, E1\n    TB: E0, -\n"),
        "{stdout}"
    );
    assert_eq!(stdout.lines().last(), Some("0 passed, 1 failed"));
}

/// Coverage counts the rows a system scenario fires in every controller
/// of the run, not only one.
#[test]
fn coverage_counts_the_rows_of_every_controller_of_a_system_scenario() {
    let out = rcsc(&[
        "test",
        "plans/submarine/scenarios/system_init_then_transit.scenario.yaml",
        "--coverage",
    ]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    let lines = coverage_lines(&stdout);
    let fired = |plan: &str| lines.iter().find(|(n, _, _)| n == plan).map(|(_, f, _)| *f);
    // SM, PR and TB each fired rows of their INIT and of the TRANSIT chain.
    assert_eq!(fired("SM.INIT"), Some(2), "{stdout}");
    assert_eq!(fired("SM.TRANSIT"), Some(2), "{stdout}");
    assert_eq!(fired("PR.INIT"), Some(2), "{stdout}");
    assert_eq!(fired("PR.AHEAD"), Some(3), "{stdout}");
    assert_eq!(fired("TB.INIT"), Some(1), "{stdout}");
    assert_eq!(fired("TB.AHEAD"), Some(2), "{stdout}");
    assert_eq!(fired("TB.STOP"), Some(0), "{stdout}");
}

const PLAN: &str = "\
controller A {
    reads tank: Level
    command FILL
    plan FILL {
        E0: *0 when new_command -> S1
        E1: S1 when tank.height > 10 -> Done
        E2: S1 when state_cycles > 5 -> Error(TOO_SLOW)
    }
    error TOO_SLOW
}
buffer Level { height: i32 }
";

#[test]
fn scenario_mistakes_are_refused_with_their_line() {
    let dir = scratch(
        "test-mistakes",
        &[
            ("a.rcs", PLAN),
            (
                "scenarios/bad_controller.scenario.yaml",
                "controller: B\nsteps:\n  - command: FILL\n",
            ),
            (
                "scenarios/bad_field.scenario.yaml",
                "controller: A\nsteps:\n  - command: FILL\n  - reads: { tank: { depth: 3 } }\n",
            ),
            (
                "scenarios/bad_row.scenario.yaml",
                "controller: A\nsteps:\n  - command: FILL\n    expect: { fired: E7 }\n",
            ),
            (
                "scenarios/no_cycles.scenario.yaml",
                "controller: A\nsteps:\n  - command: FILL\n  - cycles: 0\n",
            ),
            (
                "scenarios/too_many_cycles.scenario.yaml",
                "controller: A\nsteps:\n  - command: FILL\n    cycles: 4294967295\n",
            ),
        ],
    );
    // A Latin-1 byte in a comment on line 3.
    std::fs::write(
        dir.join("scenarios/not_utf8.scenario.yaml"),
        b"controller: A\nsteps:\n  - command: FILL # caf\xe9\n",
    )
    .unwrap();
    let out = rcsc_in(&dir, &["test"]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}{}", text(&out.stderr));
    for (file, line, message) in [
        (
            "not_utf8",
            3,
            "not valid UTF-8 (first bad byte at line 3, column 24)",
        ),
        ("bad_controller", 1, "unknown controller `B`"),
        ("bad_field", 4, "has no field `depth`"),
        (
            "bad_row",
            4,
            "no row of `A` is called `E7`: its rows are FILL: E0–E2",
        ),
        (
            "no_cycles",
            4,
            "`cycles` is a whole number from 1 to 10000000, not `0`",
        ),
        ("too_many_cycles", 4, "from 1 to 10000000, not `4294967295`"),
    ] {
        let at = format!("scenarios/{file}.scenario.yaml:{line}: error: ");
        let hit = stdout.lines().find(|l| l.contains(&at));
        assert!(
            hit.is_some_and(|l| l.contains(message)),
            "{file}: {message}\n{stdout}"
        );
    }
    assert_eq!(stdout.lines().last(), Some("0 passed, 6 failed"));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn coverage_names_each_row_no_scenario_fired_with_its_place() {
    let dir = scratch(
        "test-coverage",
        &[
            ("a.rcs", PLAN),
            (
                "scenarios/fill.scenario.yaml",
                "controller: A\nsteps:\n  - command: FILL\n    expect: { fired: E0, state: S1 }\n  - reads: { tank: { height: 11 } }\n    expect: { fired: E1, status: DONE }\n",
            ),
        ],
    );
    let out = rcsc_in(&dir, &["test", "--coverage"]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(stdout.contains("A.FILL"), "{stdout}");
    assert_eq!(coverage_lines(&stdout), [("A.FILL".to_string(), 2, 3)]);
    let missing: Vec<&str> = stdout.lines().filter(|l| l.contains("not fired")).collect();
    assert_eq!(missing.len(), 1, "{stdout}");
    assert!(
        missing[0].contains("E2") && missing[0].contains("a.rcs:7:9"),
        "{stdout}"
    );
    assert!(stdout.contains("rows fired: 2/3"));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn plans_with_errors_run_no_scenario_and_unplaceable_scenarios_are_usage_errors() {
    let dir = scratch(
        "test-errors",
        &[
            ("one/a.rcs", "controller A {\n    command GO\n    plan GO {\n        *0 when nope -> Done\n    }\n}\n"),
            ("one/scenarios/s.scenario.yaml", "controller: A\nsteps:\n  - command: GO\n"),
            ("two/a.rcs", PLAN),
            ("loose.scenario.yaml", "controller: A\nsteps:\n  - command: FILL\n"),
        ],
    );
    let out = rcsc_in(&dir, &["test", "one"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("error["),
        "{}",
        text(&out.stderr)
    );
    assert!(!text(&out.stdout).contains("passed"), "no scenario ran");

    let out = rcsc_in(&dir, &["test", "one", "two", "loose.scenario.yaml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("loose.scenario.yaml is not under any of the plan sets"));

    let out = rcsc_in(&dir, &["test", "two", "missing.scenario.yaml"]);
    assert_eq!(out.status.code(), Some(1), "an unreadable scenario fails");
    assert!(text(&out.stdout).contains("missing.scenario.yaml: error: cannot read"));
    std::fs::remove_dir_all(dir).ok();
}

/// Both backends in one test: the driver crate is built once (into
/// cargo's per-test-suite temporary folder, kept between runs).
#[test]
fn the_compiled_backend_gives_the_same_results_as_the_interpreter() {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join("rcsc-test-driver");
    let target = target.to_str().unwrap();
    let run = |backend: &str, args: &[&str]| {
        let mut all = vec!["test", "--backend", backend, "--target-dir", target];
        all.extend_from_slice(args);
        let out = rcsc(&all);
        (out.status.code(), text(&out.stdout), text(&out.stderr))
    };
    let sets = ["plans/", "--coverage"];
    let (code, compiled, stderr) = run("compiled", &sets);
    assert_eq!(code, Some(0), "{compiled}{stderr}");
    assert_full_coverage(&compiled, PLANS);
    let (_, interp, _) = run("interp", &sets);
    assert_eq!(compiled, interp, "identical reports on both backends");

    let wrong = [
        "plans/submarine",
        "tests/data/scenarios/wrong_expectation.scenario.yaml",
        "tests/data/scenarios/wrong_system_expectation.scenario.yaml",
    ];
    let (code, compiled, _) = run("compiled", &wrong);
    assert_eq!(code, Some(1));
    let (_, interp, _) = run("interp", &wrong);
    assert_eq!(compiled, interp);
    assert!(compiled.contains("fired: expected E2, got none"));
    assert!(compiled.contains("step 2, TB: state: expected S1, got S0"));
}

#[test]
fn a_run_with_no_scenario_is_an_error_and_an_untested_set_a_warning() {
    let go = "controller A {\n    command GO\n    plan GO { *0 when new_command -> Done }\n}\n";
    let dir = scratch("no-scenarios", &[("ws/a/a.rcs", go)]);
    let o = rcsc_in(&dir, &["test", "ws/a"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o.stderr).contains("error: no scenarios to run (looked in ws/a/scenarios/)"),
        "{}",
        text(&o.stderr)
    );
    // Beside a tested set, an untested one is a warning and the run goes on.
    let fig = Path::new("plans/figure13");
    for f in [
        "figure13.rcs",
        "scenarios/gx_principal_sequence.scenario.yaml",
    ] {
        let to = dir.join("ws/figure13").join(f);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(fig.join(f), to).unwrap();
    }
    let o = rcsc_in(&dir, &["test", "ws"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr)
            .contains("warning: plan set `a` has no scenarios (none under ws/a/scenarios/)"),
        "{}",
        text(&o.stderr)
    );
    assert!(text(&o.stdout).ends_with("1 passed, 0 failed\n"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `plan A | B` and `X <- cmd` (tests/data/ok/0300): each verb runs its
/// shared plan, the forwarded command is sent as received, and coverage
/// counts each shared plan once, named by all its verbs.
#[test]
fn shared_plans_and_forwarding_pass_their_scenarios_with_every_row_covered() {
    let set = "tests/data/ok/0300_verbs_pass_through";
    let out = rcsc(&["test", set, "--coverage"]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}{}", text(&out.stderr));
    let n = scenario_count(set);
    assert_eq!(stdout.lines().filter(|l| l.ends_with("... ok")).count(), n);
    // TASK 3 plans, MOT 3: one coverage line per plan, not per verb.
    assert_full_coverage(&stdout, 6);
    assert!(
        stdout.contains("TASK.HOME | UNHOME | JOG_STOP"),
        "a shared plan is named by its verbs:\n{stdout}"
    );
}

/// State sets and `except` (tests/data/ok/0210): the set row fires in both
/// of its states, the `except` row times out of Starting and Execute but
/// never fires in Holding; both backends agree, every row covered.
#[test]
fn state_sets_and_except_pass_their_scenarios_on_both_backends() {
    let set = "tests/data/ok/0210_state_sets";
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join("rcsc-test-driver-sets");
    let run = |backend: &str| {
        let out = rcsc(&[
            "test",
            set,
            "--coverage",
            "--backend",
            backend,
            "--target-dir",
            target.to_str().unwrap(),
        ]);
        let stdout = text(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{stdout}{}", text(&out.stderr));
        stdout
    };
    let interp = run("interp");
    assert_eq!(
        interp.lines().filter(|l| l.ends_with("... ok")).count(),
        scenario_count(set)
    );
    assert_full_coverage(&interp, 1);
    assert_eq!(
        run("compiled"),
        interp,
        "identical reports on both backends"
    );
}
