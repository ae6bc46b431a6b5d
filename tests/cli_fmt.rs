//! `rcsc fmt` end to end: in-place rewrite of only the files that change,
//! `--check` (exit 1 and a unified diff, nothing written), refusal of a
//! file that does not parse (exit 2, diagnostics, file untouched), the
//! width from `rcsfmt.toml`, and the repository's own plans formatted.

mod common;
use common::{rcsc, rcsc_in, scratch, text};

const MESSY: &str = "controller A {\ncommand GO\n  subordinates B\nplan GO {\nE0: *0 when new_command -> S1 { B <- RUN }\nE1: S1 when B.done -> Done   // finished\n}\n}\n\ncontroller B { command RUN plan RUN { *0 when new_command -> Done } }\n";
const TIDY: &str = "controller A {\n    command GO\n    subordinates B\n    plan GO {\n        E0: *0 when new_command -> S1 { B <- RUN }\n        E1: S1 when B.done      -> Done // finished\n    }\n}\n\ncontroller B {\n    command RUN\n    plan RUN {\n        *0 when new_command -> Done\n    }\n}\n";
const BROKEN: &str =
    "controller A {\n    command GO\n    plan GO {\n        *0 when new_command -> \n    }\n";

#[test]
fn fmt_rewrites_only_the_files_that_change_and_names_them() {
    let dir = scratch(
        "fmt_rewrite",
        &[("set/a.rcs", MESSY), ("set/tidy.rcs", TIDY)],
    );
    let out = rcsc_in(&dir, &["fmt", "set"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    assert!(stderr.contains("Formatted set/a.rcs"), "{stderr}");
    assert!(
        !stderr.contains("tidy.rcs"),
        "an unchanged file is not named: {stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("set/a.rcs")).unwrap(),
        TIDY
    );
    // No temporary is left beside the file.
    let names: Vec<String> = std::fs::read_dir(dir.join("set"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
    // A second run changes nothing.
    let again = rcsc_in(&dir, &["fmt", "--check", "set"]);
    assert_eq!(again.status.code(), Some(0), "{}", text(&again.stdout));
    assert!(again.stdout.is_empty());
}

#[test]
fn fmt_check_prints_a_unified_diff_exits_1_and_writes_nothing() {
    let dir = scratch("fmt_check", &[("a.rcs", MESSY)]);
    let out = rcsc_in(&dir, &["fmt", "--check", "a.rcs"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let diff = text(&out.stdout);
    assert!(
        diff.starts_with("--- a.rcs\n+++ a.rcs (formatted)\n@@ "),
        "{diff}"
    );
    assert!(diff.contains("\n-command GO\n"), "{diff}");
    assert!(diff.contains("\n+    command GO\n"), "{diff}");
    assert!(
        text(&out.stderr).contains("1 file of 1 would be reformatted"),
        "{}",
        text(&out.stderr)
    );
    assert_eq!(std::fs::read_to_string(dir.join("a.rcs")).unwrap(), MESSY);
}

#[test]
fn fmt_refuses_a_file_that_does_not_parse_and_leaves_it_untouched() {
    let dir = scratch("fmt_broken", &[("broken.rcs", BROKEN), ("a.rcs", MESSY)]);
    let out = rcsc_in(&dir, &["fmt", "."]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    assert!(stderr.contains("error[syntax]"), "{stderr}");
    assert!(
        stderr.contains("broken.rcs:5"),
        "the diagnostic points into the file: {stderr}"
    );
    assert!(
        stderr.contains("broken.rcs does not parse; it was not formatted"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("broken.rcs")).unwrap(),
        BROKEN
    );
    // The other file is still formatted.
    assert_eq!(std::fs::read_to_string(dir.join("a.rcs")).unwrap(), TIDY);
    let check = rcsc_in(&dir, &["fmt", "--check", "broken.rcs"]);
    assert_eq!(check.status.code(), Some(2));
}

#[test]
fn the_width_comes_from_the_nearest_rcsfmt_toml() {
    let long = "controller A {\n    command GO\n    var alpha: u8 = 0\n    var beta: u8 = 0\n    plan GO {\n        *0 when new_command && alpha > 1 && beta > 2 -> Done\n    }\n}\n";
    let dir = scratch(
        "fmt_width",
        &[("rcsfmt.toml", "max_width = 40\n"), ("sub/a.rcs", long)],
    );
    let out = rcsc_in(&dir, &["fmt", "sub"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let got = std::fs::read_to_string(dir.join("sub/a.rcs")).unwrap();
    assert!(
        got.contains(
            "        *0 when new_command && alpha > 1\n                && beta > 2 -> Done\n"
        ),
        "{got}"
    );
    std::fs::write(dir.join("rcsfmt.toml"), "max_wdth = 40\n").unwrap();
    let bad = rcsc_in(&dir, &["fmt", "sub"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(
        text(&bad.stderr).contains("unknown setting `max_wdth`"),
        "{}",
        text(&bad.stderr)
    );
}

#[test]
fn the_repository_plans_are_formatted() {
    let out = rcsc(&["fmt", "--check", "plans/", "examples/"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "run `rcsc fmt plans/ examples/`:\n{}",
        text(&out.stdout)
    );
}

#[test]
fn a_missing_path_is_a_usage_error() {
    let out = rcsc(&["fmt", "no/such/folder"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("no/such/folder"),
        "{}",
        text(&out.stderr)
    );
}

/// A plan set whose scenario passes: four rows, labelled.
const STEPS: &str = "buffer Ev {\n    a: bool,\n    b: bool,\n    c: bool,\n}\n\ncontroller P {\n    reads ev: Ev\n    command RUN\n    plan RUN {\n        \
    E0: *0 when new_command -> S1\n        E1: S1 when ev.a        -> S2\n        \
    E2: S2 when ev.b        -> S3\n        E3: S3 when ev.c        -> Done\n    }\n}\n";
const STEPS_SCENARIO: &str =
    "controller: P\nsteps:\n  - command: RUN\n    expect: { fired: E0, state: S1 }\n  \
    - reads: { ev: { a: true } }\n    expect: { fired: E1, state: S2 }   # the first step\n  \
    - reads: { ev: { b: true } }\n    expect: { fired: E2, state: S3 }\n  \
    - reads: { ev: { c: true } }\n    expect:\n      fired: E3\n      status: DONE\n";
/// The line of the first row of P's plan.
const E1_ROW: &str = "        E1: S1 when ev.a        -> S2\n";

#[test]
fn renumber_fixes_a_row_inserted_with_a_copied_label_and_the_scenario_after_it() {
    // A row inserted after E1, its label copied: E2 and E3 move down one.
    let inserted = STEPS.replace(E1_ROW, &format!("{E1_ROW}        E1: S2 when ev.c -> S1\n"));
    assert_ne!(inserted, STEPS);
    let scenario = "p/scenarios/run.scenario.yaml";
    let dir = scratch(
        "fmt_renumber",
        &[("p/p.rcs", &inserted), (scenario, STEPS_SCENARIO)],
    );
    let check = rcsc_in(&dir, &["check", "p"]);
    assert_eq!(check.status.code(), Some(1));
    assert!(
        text(&check.stderr).contains("error[row_number]"),
        "{}",
        text(&check.stderr)
    );
    // `rcsc test` runs plans only the checks reject, but shows why.
    let test = rcsc_in(&dir, &["test", "p"]);
    assert!(
        text(&test.stderr).contains("error[row_number]"),
        "{}",
        text(&test.stderr)
    );
    // Plain `rcsc fmt` lays the rows out and leaves their labels.
    let fmt = rcsc_in(&dir, &["fmt", "p"]);
    assert_eq!(fmt.status.code(), Some(0), "{}", text(&fmt.stderr));
    let formatted = std::fs::read_to_string(dir.join("p/p.rcs")).unwrap();
    assert_eq!(formatted.matches("E1: ").count(), 2, "{formatted}");

    let dry = rcsc_in(&dir, &["fmt", "--renumber", "--check", "p"]);
    assert_eq!(dry.status.code(), Some(1), "{}", text(&dry.stderr));
    let diff = text(&dry.stdout);
    assert!(
        diff.contains("+        E4: S3 when ev.c        -> Done\n"),
        "{diff}"
    );
    assert!(diff.contains("+      fired: E4\n"), "{diff}");
    assert_eq!(
        std::fs::read_to_string(dir.join("p/p.rcs")).unwrap(),
        formatted
    );

    let out = rcsc_in(&dir, &["fmt", "--renumber", "p"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("Renumbered p/p.rcs (E1 → E2, E2 → E3, E3 → E4)"),
        "{stderr}"
    );
    assert!(
        stderr.contains("Updated p/scenarios/run.scenario.yaml (E2 → E3, E3 → E4)"),
        "{stderr}"
    );
    // `E1` is on two rows: the scenario's `fired: E1` is left, and said.
    assert!(
        stderr.contains("warning: p/scenarios/run.scenario.yaml:6: `fired: E1`"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join(scenario)).unwrap(),
        STEPS_SCENARIO
            .replace("fired: E2", "fired: E3")
            .replace("fired: E3\n", "fired: E4\n")
    );
    let check = rcsc_in(&dir, &["check", "p"]);
    assert_eq!(check.status.code(), Some(0), "{}", text(&check.stderr));
    let test = rcsc_in(&dir, &["test", "p"]);
    assert_eq!(test.status.code(), Some(0), "{}", text(&test.stderr));
    assert!(
        text(&test.stdout).contains("1 passed, 0 failed"),
        "{}",
        text(&test.stdout)
    );
    // A second run changes nothing.
    let again = rcsc_in(&dir, &["fmt", "--renumber", "--check", "p"]);
    assert_eq!(again.status.code(), Some(0), "{}", text(&again.stdout));
    assert!(again.stdout.is_empty(), "{}", text(&again.stdout));
}

#[test]
fn renumber_writes_nothing_when_a_file_does_not_parse() {
    let inserted = STEPS.replace(E1_ROW, &format!("{E1_ROW}{E1_ROW}"));
    let dir = scratch(
        "fmt_renumber_broken",
        &[("p/p.rcs", &inserted), ("q/q.rcs", BROKEN)],
    );
    let out = rcsc_in(&dir, &["fmt", "--renumber", "p", "q"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    assert!(stderr.contains("error[syntax]"), "{stderr}");
    assert!(stderr.contains("no file was written"), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(dir.join("p/p.rcs")).unwrap(),
        inserted
    );
    let check = rcsc_in(&dir, &["fmt", "--renumber", "--check", "p", "q"]);
    assert_eq!(check.status.code(), Some(2), "{}", text(&check.stderr));
}
