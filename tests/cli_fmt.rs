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
