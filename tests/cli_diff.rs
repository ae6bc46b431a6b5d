//! `rcsc diff` end to end: golden cases under `tests/data/diff/<case>/`
//! (`old/` and `new/` plan sets), each kept as an insta snapshot of the
//! exit status, the text and the markdown; the diff graph of a reordered
//! plan; the JSON shape; and revisions of a scratch git repository.

use std::path::Path;
use std::process::Command;

mod common;
use common::{rcsc_in, scratch, text};

fn cases() -> Vec<String> {
    let mut out: Vec<String> = std::fs::read_dir("tests/data/diff")
        .expect("tests/data/diff")
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    out.sort();
    out
}

#[test]
fn golden_cases() {
    let cases = cases();
    assert!(cases.len() >= 8, "{cases:?}");
    for case in cases {
        let dir = Path::new("tests/data/diff").join(&case);
        let out = rcsc_in(&dir, &["diff", "old", "new"]);
        assert!(out.stderr.is_empty(), "{case}: {}", text(&out.stderr));
        let md = rcsc_in(&dir, &["diff", "old", "new", "--format", "markdown"]);
        assert_eq!(md.status.code(), out.status.code(), "{case}");
        let shown = format!(
            "exit status: {:?}\n--- text\n{}--- markdown\n{}",
            out.status.code(),
            text(&out.stdout),
            text(&md.stdout)
        );
        insta::assert_snapshot!(format!("diff_{case}"), shown);
    }
}

#[test]
fn whitespace_only_is_no_change() {
    let out = rcsc_in(
        Path::new("tests/data/diff/whitespace_only"),
        &["diff", "old", "new"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(out.stdout.is_empty(), "{}", text(&out.stdout));
}

#[test]
fn a_reordered_plan_draws_its_move() {
    let dir = scratch("diff-graphs", &[]);
    let graphs = dir.join("g");
    let out = rcsc_in(
        Path::new("tests/data/diff/reordered"),
        &["diff", "old", "new", "--graphs", graphs.to_str().unwrap()],
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let dot = std::fs::read_to_string(graphs.join("TANK.FILL.dot")).unwrap();
    insta::assert_snapshot!("diff_reordered_graph", dot);
    // An otherwise row is a note, coloured as its row.
    let out = rcsc_in(
        Path::new("tests/data/diff/otherwise_added"),
        &["diff", "old", "new", "--graphs", graphs.to_str().unwrap()],
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let dot = std::fs::read_to_string(graphs.join("TANK.FILL.dot")).unwrap();
    assert!(
        dot.contains("\"E5 otherwise\" [label=\"+E5 otherwise\""),
        "{dot}"
    );
    assert!(
        dot.contains("shape=note, style=dashed, fontsize=11, color=darkgreen"),
        "{dot}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn json_names_the_move_and_its_witness() {
    let out = rcsc_in(
        Path::new("tests/data/diff/reordered"),
        &["diff", "old", "new", "--format", "json"],
    );
    assert_eq!(out.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let plan = &v["systems"][0]["controllers"][0]["plans"][0];
    assert_eq!(plan["verb"], "FILL");
    let m = &plan["moves"][0];
    assert_eq!(m["now_first"], "E1");
    assert_eq!(m["was"], "E2");
    let effect = &m["effect"]["changes_firing"];
    assert_eq!(effect["state"], "S1");
    assert!(
        effect["input"].as_str().unwrap().contains("s.depth = "),
        "{effect}"
    );
    assert_eq!(
        v["systems"][0]["findings_introduced"][0]["code"],
        "shadowed_row"
    );
}

/// `rcsc diff ARGS` in `dir` exits 2 saying each of `says` on stderr.
fn fails_saying(dir: &Path, args: &[&str], says: &[&str]) {
    let out = rcsc_in(dir, args);
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    for s in says {
        assert!(
            text(&out.stderr).contains(s),
            "{args:?}: {}",
            text(&out.stderr)
        );
    }
}

#[test]
fn bad_sides_are_errors() {
    fails_saying(
        Path::new("."),
        &["diff", "no-such-revision-or-path"],
        &["neither a file or folder nor a git revision"],
    );
    fails_saying(
        Path::new("tests/data/diff/reordered"),
        &["diff", "old"],
        &["name NEW too"],
    );
    // A side that does not parse: its diagnostics, then exit status 2.
    let dir = scratch(
        "diff-broken",
        &[("a/x.rcs", "controller {"), ("b/x.rcs", "controller {")],
    );
    fails_saying(
        &dir,
        &["diff", "a", "b"],
        &["error[syntax]", "does not parse"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn git(dir: &Path, args: &[&str]) {
    let out = Command::new("git")
        .args(["-c", "user.name=t", "-c", "user.email=t@example.com"])
        .args(args)
        .current_dir(dir)
        .output()
        .expect("git runs");
    assert!(out.status.success(), "git {args:?}: {}", text(&out.stderr));
}

#[test]
fn revisions_of_a_git_repository() {
    let case = Path::new("tests/data/diff/reordered");
    let old = std::fs::read_to_string(case.join("old/tank.rcs")).unwrap();
    let new = std::fs::read_to_string(case.join("new/tank.rcs")).unwrap();
    let repo = scratch(
        "diff-git",
        &[
            ("plans/tank.rcs", &old),
            ("plans/rcs.yaml", "system: tank\n"),
        ],
    );
    git(&repo, &["init", "-q"]);
    git(&repo, &["add", "."]);
    git(&repo, &["commit", "-q", "-m", "one"]);
    std::fs::write(repo.join("plans/tank.rcs"), &new).unwrap();
    git(&repo, &["commit", "-q", "-am", "two"]);

    // The working tree is the second commit: HEAD~1 against it, and the
    // two commits named as a range, give the same diff as the folders.
    let folders = rcsc_in(case, &["diff", "old", "new"]);
    let against_tree = rcsc_in(&repo, &["diff", "HEAD~1", "--path", "plans"]);
    assert_eq!(
        against_tree.status.code(),
        Some(1),
        "{}",
        text(&against_tree.stderr)
    );
    assert_eq!(text(&against_tree.stdout), text(&folders.stdout));
    let range = rcsc_in(&repo.join("plans"), &["diff", "HEAD~1..HEAD"]);
    assert_eq!(range.status.code(), Some(1), "{}", text(&range.stderr));
    assert_eq!(text(&range.stdout), text(&folders.stdout));
    // A revision against itself: no change.
    let same = rcsc_in(&repo, &["diff", "HEAD", "--path", "plans"]);
    assert_eq!(same.status.code(), Some(0), "{}", text(&same.stderr));
    assert!(same.stdout.is_empty());
    let _ = std::fs::remove_dir_all(&repo);
}

#[test]
fn the_readme_example_is_what_rcsc_diff_prints() {
    let readme = std::fs::read_to_string("README.md").unwrap();
    let at = readme
        .find("(`tests/data/diff/reordered`)")
        .expect("README.md shows the markdown of the reordered case");
    let block = readme[at..]
        .split_once("```markdown\n")
        .and_then(|(_, rest)| rest.split_once("\n```"))
        .map(|(block, _)| block)
        .expect("a ```markdown block");
    let out = rcsc_in(
        Path::new("tests/data/diff/reordered"),
        &["diff", "old", "new", "--format", "markdown"],
    );
    assert_eq!(text(&out.stdout).trim_end(), block);
}

/// A row that becomes a state set, and a `*` row that becomes `except`:
/// the diff shows each pattern as written, and its graph draws the set row
/// from each of its states.
#[test]
fn state_sets_are_shown_as_written_and_drawn_per_state() {
    let dir = scratch("diff-state-sets", &[]);
    let graphs = dir.join("g");
    let case = Path::new("tests/data/diff/state_sets");
    let out = rcsc_in(
        case,
        &["diff", "old", "new", "--graphs", graphs.to_str().unwrap()],
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    let shown = text(&out.stdout);
    assert!(
        shown.contains("from: Starting → Starting | Execute"),
        "{shown}"
    );
    assert!(shown.contains("from: * → * except Holding"), "{shown}");
    let dot = std::fs::read_to_string(graphs.join("CELL.RUN.dot")).unwrap();
    for from in ["Starting", "Execute"] {
        let edge = format!("\"{from}\" -> \"Holding\" [label=<<TABLE BORDER=\"0\" CELLBORDER=\"0\" CELLSPACING=\"0\" CELLPADDING=\"3\"><TR><TD><FONT COLOR=\"darkorange\">~E2</FONT>");
        assert!(dot.contains(&edge), "{edge}\n{dot}");
    }
    assert!(dot.contains("\"*5\" -> \"Error\""), "{dot}");
    // The states of a set in another order mean the same: no change.
    let old = std::fs::read_to_string(case.join("new/cell.rcs")).unwrap();
    let new = old.replace("Starting | Execute", "Execute | Starting");
    assert_ne!(old, new);
    let dir = scratch(
        "diff-state-sets",
        &[("old/c.rcs", &old), ("new/c.rcs", &new)],
    );
    let out = rcsc_in(&dir, &["diff", "old", "new"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
    assert!(out.stdout.is_empty(), "{}", text(&out.stdout));
    let _ = std::fs::remove_dir_all(&dir);
}
