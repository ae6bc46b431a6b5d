//! `rcsc check` end to end: the binary, its exit statuses (0 / 1 / 2), its
//! output formats and its lint flags, as a user meets them.

use std::path::Path;
use std::process::Command;

mod common;
use common::{rcsc, scratch, text};

const UNUSED_VAR: &str = "controller A {\n    command GO\n    var spare: u8 = 0\n    plan GO {\n        *0 when new_command -> Done\n    }\n}\n";

#[test]
fn reference_plan_sets_check_silently() {
    for set in ["plans/submarine", "plans/figure13"] {
        for format in ["json", "human", "short"] {
            let out = rcsc(&["check", set, "--message-format", format]);
            assert_eq!(
                out.status.code(),
                Some(0),
                "{set} {format}: {}",
                text(&out.stderr)
            );
            assert!(
                out.stdout.is_empty(),
                "{set} {format}: {}",
                text(&out.stdout)
            );
            assert!(
                out.stderr.is_empty(),
                "{set} {format}: {}",
                text(&out.stderr)
            );
        }
    }
}

#[test]
fn several_plan_sets_and_single_files_in_one_call() {
    let out = rcsc(&["check", "plans/submarine", "plans/figure13/figure13.rcs"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
}

#[test]
fn errors_exit_1_with_json_lines_on_stdout() {
    let dir = scratch("json", &[("a.rcs", "controller A {\n    command GO\n    plan GO {\n        *0 when new_command && nope -> Done\n    }\n}\n")]);
    let out = rcsc(&["check", dir.to_str().unwrap(), "--message-format", "json"]);
    assert_eq!(out.status.code(), Some(1));
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 1, "{stdout}");
    let v: serde_json::Value = serde_json::from_str(lines[0]).expect("one JSON object per line");
    assert_eq!(v["code"], "unknown_name");
    assert_eq!(v["severity"], "error");
    assert_eq!(v["line"], 4);
    assert_eq!(v["column"], 32);
    assert_eq!(v["end_column"], 36);
    assert!(v["file"].as_str().unwrap().ends_with("a.rcs"));
    assert_eq!(v["labels"][0]["primary"], true);
    assert!(v["notes"].is_array());
}

#[test]
fn human_output_has_a_snippet_and_a_summary_on_stderr() {
    let dir = scratch("human", &[("a.rcs", UNUSED_VAR)]);
    let out = rcsc(&["check", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "a warning is not a failure");
    let err = text(&out.stderr);
    assert!(
        err.contains("warning[unused]: var `spare` of `A` is never used"),
        "{err}"
    );
    assert!(err.contains("a.rcs:3:9"), "{err}");
    assert!(err.contains("3 |     var spare: u8 = 0"), "{err}");
    assert!(err.contains("warning: 1 warning emitted"), "{err}");
    assert!(
        !err.contains('\u{1b}'),
        "no colour when NO_COLOR is set: {err:?}"
    );
    assert!(out.stdout.is_empty());
}

#[test]
fn color_always_colours_human_output() {
    let dir = scratch("color", &[("a.rcs", UNUSED_VAR)]);
    let out = rcsc(&["check", dir.to_str().unwrap(), "--color", "always"]);
    assert!(
        text(&out.stderr).contains('\u{1b}'),
        "ANSI escapes expected"
    );
}

#[test]
fn short_format_is_one_line_per_diagnostic() {
    let dir = scratch("short", &[("a.rcs", UNUSED_VAR)]);
    let out = rcsc(&["check", dir.to_str().unwrap(), "--message-format", "short"]);
    let err = text(&out.stderr);
    let first = err.lines().next().unwrap();
    assert!(
        first.ends_with("a.rcs:3:9: warning[unused]: var `spare` of `A` is never used"),
        "{err}"
    );
}

#[test]
fn lint_flags_change_levels() {
    let dir = scratch("flags", &[("a.rcs", UNUSED_VAR)]);
    let d = dir.to_str().unwrap();
    let denied = rcsc(&["check", d, "-D", "unused", "--message-format", "short"]);
    assert_eq!(denied.status.code(), Some(1));
    assert!(text(&denied.stderr).contains("error[unused]"));
    let allowed = rcsc(&["check", d, "-A", "unused"]);
    assert_eq!(allowed.status.code(), Some(0));
    assert!(allowed.stderr.is_empty(), "{}", text(&allowed.stderr));
    let quiet = rcsc(&["check", d, "-q"]);
    assert_eq!(quiet.status.code(), Some(0));
    assert!(
        quiet.stderr.is_empty(),
        "--quiet hides warnings: {}",
        text(&quiet.stderr)
    );
}

#[test]
fn attributes_override_command_line_levels() {
    let dir = scratch(
        "attr",
        &[("a.rcs", &format!("#[allow(unused)]\n{UNUSED_VAR}"))],
    );
    let out = rcsc(&["check", dir.to_str().unwrap(), "-D", "unused"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
}

#[test]
fn manifest_lints_apply_and_flags_override_them() {
    let dir = scratch(
        "manifest",
        &[
            ("a.rcs", UNUSED_VAR),
            ("rcs.yaml", "lints: { unused: deny }\n"),
        ],
    );
    let d = dir.to_str().unwrap();
    assert_eq!(rcsc(&["check", d]).status.code(), Some(1));
    assert_eq!(rcsc(&["check", d, "-W", "unused"]).status.code(), Some(0));
}

#[test]
fn missing_paths_exit_2_naming_the_path() {
    let out = rcsc(&["check", "no/such/plans"]);
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("no/such/plans"), "{err}");
}

#[test]
fn non_plan_files_exit_2() {
    let out = rcsc(&["check", "Cargo.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("Cargo.toml"));
}

#[test]
fn unknown_lints_on_the_command_line_are_usage_errors() {
    let out = rcsc(&["check", "plans/figure13", "-D", "no_such_lint"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("no_such_lint"));
}

#[test]
fn non_utf8_files_are_a_diagnostic_naming_the_byte() {
    let dir = scratch("utf8", &[]);
    std::fs::write(dir.join("bad.rcs"), b"controller A { command GO \xff\xfe }").unwrap();
    let out = rcsc(&["check", dir.to_str().unwrap(), "--message-format", "json"]);
    assert_eq!(out.status.code(), Some(1));
    let v: serde_json::Value =
        serde_json::from_str(text(&out.stdout).lines().next().unwrap()).unwrap();
    assert_eq!(v["code"], "syntax");
    assert!(v["message"].as_str().unwrap().contains("offset 26"), "{v}");
}

#[test]
fn default_path_is_the_current_folder() {
    let out = Command::new(env!("CARGO_BIN_EXE_rcsc"))
        .arg("check")
        .current_dir(Path::new("plans/figure13"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
}

#[test]
fn help_lists_examples() {
    let out = rcsc(&["check", "--help"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(text(&out.stdout).contains("rcsc check plans/submarine"));
}

/// The golden cases whose findings carry runs: paths through several
/// states, a wait for `state_cycles`, a command parameter and a var.
const WITH_RUNS: [&str; 5] = [
    "tests/data/err/2911_unhandled_error_reference_submarine",
    "tests/data/err/2912_unhandled_error_status_test.rcs",
    "tests/data/err/2913_unhandled_error_one_of_two_subordinates.rcs",
    "tests/data/err/2914_unhandled_error_after_a_wait.rcs",
    "tests/data/err/2915_unhandled_error_with_parameter_and_var.rcs",
];

#[test]
fn witnesses_are_scenarios_that_rcsc_test_passes() {
    let mut written = 0;
    for (i, case) in WITH_RUNS.iter().enumerate() {
        let dir = scratch(&format!("witnesses{i}"), &[]);
        let out = rcsc(&["check", case, "--witnesses", dir.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(0), "{case}: {}", text(&out.stderr));
        assert!(text(&out.stderr).contains("witness scenario"), "{case}");
        let mut files: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path().to_string_lossy().into_owned())
            .collect();
        files.sort();
        assert!(!files.is_empty(), "{case}: no witness written");
        for f in &files {
            let name = Path::new(f).file_name().unwrap().to_string_lossy();
            assert!(
                name.starts_with("unhandled_error_") && name.ends_with(".scenario.yaml"),
                "{name}"
            );
        }
        // The same check writes the same files.
        let again = scratch(&format!("witnesses{i}again"), &[]);
        rcsc(&["check", case, "--witnesses", again.to_str().unwrap()]);
        assert_eq!(common::tree(&dir), common::tree(&again), "{case}");
        assert_replays(case, &files, &[]);
        written += files.len();
    }
    assert!(written >= 6, "only {written} witnesses");
}

#[test]
fn json_findings_carry_their_run() {
    let out = rcsc(&["check", WITH_RUNS[2], "--message-format", "json"]);
    let stdout = text(&out.stdout);
    let v: serde_json::Value = serde_json::from_str(stdout.lines().next().unwrap()).unwrap();
    assert_eq!(v["code"], "unhandled_error");
    let run = &v["witness"]["run"];
    assert_eq!(run["controller"], "C");
    assert_eq!(run["command"], "GO");
    let steps = run["steps"].as_array().unwrap();
    let last = steps.last().unwrap();
    assert_eq!(last["cycles"], 30);
    assert_eq!(last["expect"]["kind"], "stays");
    assert_eq!(last["subordinates"]["D"], "ERROR");
}

#[test]
fn an_unwritable_witnesses_folder_exits_2() {
    let dir = scratch("witnesses-file", &[("taken", "not a folder\n")]);
    let target = dir.join("taken");
    let out = rcsc(&[
        "check",
        WITH_RUNS[1],
        "--witnesses",
        target.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = text(&out.stderr);
    assert!(stderr.contains("error: cannot write"), "{stderr}");
    assert!(stderr.contains("taken"), "{stderr}");
}

/// The value lints' golden cases (`err/50NN_*`): each finding's run is
/// written by `--witnesses` under the lint's name and `rcsc test` passes
/// it — the wrapped or zero-divided value expected where the scenario can
/// write it, the NaN latch as cycles with no row firing, the stale read
/// as two commands.
#[test]
fn value_lint_witnesses_replay_in_rcsc_test() {
    let mut cases: Vec<String> = std::fs::read_dir("tests/data/err")
        .unwrap()
        .map(|e| e.unwrap().path().to_string_lossy().into_owned())
        .filter(|p| p.contains("/50") && p.ends_with(".rcs"))
        .collect();
    cases.sort();
    assert!(cases.len() >= 16, "only {} value-lint cases", cases.len());
    let mut with_vars = 0;
    for (i, case) in cases.iter().enumerate() {
        let lint = ["int_wrap", "div_by_zero", "nan_path", "read_before_assign"]
            .into_iter()
            .find(|l| case.contains(l))
            .unwrap_or_else(|| panic!("{case}: names no value lint"));
        let dir = scratch(&format!("value-witnesses{i}"), &[]);
        let out = rcsc(&["check", case, "--witnesses", dir.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(0), "{case}: {}", text(&out.stderr));
        let files: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path().to_string_lossy().into_owned())
            .collect();
        assert_eq!(files.len(), 1, "{case}: {files:?}");
        let name = Path::new(&files[0]).file_name().unwrap().to_string_lossy();
        assert!(name.starts_with(&format!("{lint}_")), "{case}: {name}");
        let body = std::fs::read_to_string(&files[0]).unwrap();
        with_vars += usize::from(body.contains("    vars:"));
        assert_replays(case, &files, &[]);
    }
    assert!(with_vars >= 5, "only {with_vars} runs expect the value");
}

/// The runs of the cross-controller findings (err 5101–5160), written by
/// `--witnesses`, pass `rcsc test` — 5160's too, although its set has an
/// `unreachable_row` error: `rcsc test` runs a set the checks reject.
#[test]
fn cross_controller_witnesses_replay_in_rcsc_test() {
    let mut cases: Vec<String> = std::fs::read_dir("tests/data/err")
        .unwrap()
        .map(|e| e.unwrap().path().to_string_lossy().into_owned())
        .filter(|p| p.contains("/51"))
        .collect();
    cases.sort();
    assert!(
        cases.len() >= 20,
        "only {} cross-controller cases",
        cases.len()
    );
    let mut replayed = 0;
    let mut with_error = 0;
    for (i, case) in cases.iter().enumerate() {
        let dir = scratch(&format!("cross-witnesses{i}"), &[]);
        let out = rcsc(&["check", case, "--witnesses", dir.to_str().unwrap()]);
        let files: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path().to_string_lossy().into_owned())
            .collect();
        if files.is_empty() {
            continue;
        }
        with_error += usize::from(out.status.code() != Some(0));
        assert_replays(case, &files, &[]);
        replayed += files.len();
    }
    assert!(replayed >= 12, "only {replayed} runs replayed");
    assert!(with_error >= 1, "no case with an error of the checks");
}

/// A cross-controller finding's system run, as `--witnesses` writes it,
/// passes on the generated code too: one case per lint that has one.
#[test]
fn cross_controller_system_runs_pass_on_the_compiled_backend() {
    let target = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("rcsc-witness-driver");
    for (i, case) in [
        "tests/data/err/5101_unhandled_error_watchdog_on_live_subordinate.rcs",
        "tests/data/err/5106_unhandled_error_timer_gated_on_another_subordinate.rcs",
        "tests/data/err/5121_stale_subordinate_status_state_row_before_command.rcs",
        "tests/data/err/5130_command_overwritten_no_wait.rcs",
        "tests/data/err/5140_always_rejected_refused_by_limit.rcs",
    ]
    .into_iter()
    .enumerate()
    {
        let dir = scratch(&format!("system-witnesses{i}"), &[]);
        rcsc(&["check", case, "--witnesses", dir.to_str().unwrap()]);
        let files: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path().to_string_lossy().into_owned())
            .filter(|p| p.ends_with("_system.scenario.yaml"))
            .collect();
        assert_eq!(files.len(), 1, "{case}: one system run written");
        let backend = [
            "--backend",
            "compiled",
            "--target-dir",
            target.to_str().unwrap(),
        ];
        assert_replays(case, &files, &backend);
    }
}

/// `rcsc test [OPTIONS] CASE FILES…` passes: the witness scenarios written
/// for a case replay on its plans.
fn assert_replays(case: &str, files: &[String], options: &[&str]) {
    let mut args = vec!["test"];
    args.extend_from_slice(options);
    args.push(case);
    args.extend(files.iter().map(String::as_str));
    let out = rcsc(&args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{case}: {}{}",
        text(&out.stdout),
        text(&out.stderr)
    );
}

#[test]
fn a_folder_without_plans_is_a_no_plans_error() {
    let dir = scratch("no_plans", &[]);
    let out = rcsc(&["check", dir.to_str().unwrap(), "--message-format", "json"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let v: serde_json::Value =
        serde_json::from_str(text(&out.stdout).lines().next().unwrap()).unwrap();
    assert_eq!(v["code"], "no_plans", "{v}");
    assert!(v["help"].as_str().unwrap().contains(".rcs"), "{v}");
    // A manifest alone is no plans either.
    std::fs::write(dir.join("rcs.yaml"), "system: empty\n").unwrap();
    let out = rcsc(&["check", dir.to_str().unwrap(), "--message-format", "short"]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(err.contains("rcs.yaml:1:1: error[no_plans]"), "{err}");
}
