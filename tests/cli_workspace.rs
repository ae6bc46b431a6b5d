//! Plan-set workspaces end to end: a folder without a manifest whose
//! subfolders hold plans, nested manifests, `workspace:` manifests, loose
//! files, and the repository root itself (`rcs.yaml` with `workspace:`).

use std::collections::BTreeSet;
use std::path::Path;

mod common;
use common::{rcsc, rcsc_in, scratch, text, tree};

const GO: &str = "controller A {\n    command GO\n    plan GO {\n        *0 when new_command -> Done\n    }\n}\n";

/// Every file below `dir`, as `/`-separated relative paths.
fn files(dir: &Path) -> BTreeSet<String> {
    tree(dir).into_keys().collect()
}

/// The generated Rust of `plans/`: one file per set, in path order.
const ALL_RUST: [&str; 6] = [
    "bridgeport_io/rust/bridgeport_io.rs",
    "fieldbus_drive/rust/fieldbus_drive.rs",
    "figure13/rust/figure13.rs",
    "packml/rust/packml.rs",
    "rcs_ex/rust/rcs_ex.rs",
    "submarine/rust/submarine.rs",
];

/// The generated Rust files of a build, i.e. which systems it wrote where.
fn rust_files(dir: &Path) -> Vec<String> {
    files(dir)
        .into_iter()
        .filter(|f| f.ends_with(".rs"))
        .collect()
}

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 temp path")
}

#[test]
fn building_plans_builds_each_set_into_its_own_folder_with_its_own_schedule() {
    let out = scratch("plans", &[]);
    let o = rcsc(&["build", "plans/", "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("    Checking figure13 (1 file)\n"), "{err}");
    assert!(err.contains("    Checking submarine (3 files)\n"), "{err}");
    assert!(err.contains("    Checking rcs_ex (4 files)\n"), "{err}");
    assert!(
        err.contains("    Checking bridgeport_io (5 files)\n"),
        "{err}"
    );
    assert!(err.contains("    Checking packml (2 files)\n"), "{err}");
    assert!(
        err.contains("    Checking fieldbus_drive (2 files)\n"),
        "{err}"
    );
    assert_eq!(rust_files(&out), ALL_RUST);
    // Each set keeps its own manifest: submarine's 30 ms CPU, figure13's default 10 ms.
    let sub = std::fs::read_to_string(out.join("submarine/rust/submarine.rs")).unwrap();
    let fig = std::fs::read_to_string(out.join("figure13/rust/figure13.rs")).unwrap();
    assert!(sub.contains(", 30000000u64);"), "30 ms period");
    assert!(fig.contains(", 10000000u64);"), "10 ms period");
    // The same tree as naming the sets.
    let named = scratch("plans-named", &[]);
    let o = rcsc(&[
        "build",
        "plans/submarine",
        "plans/figure13",
        "plans/rcs_ex",
        "plans/bridgeport_io",
        "plans/packml",
        "plans/fieldbus_drive",
        "-o",
        s(&named),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(files(&out), files(&named));
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&named);
}

#[test]
fn the_repository_root_is_a_workspace_of_plans() {
    // `rcs.yaml` at the root says `workspace: [plans]`, so tests/data (full
    // of broken plans) is not checked.
    let o = rcsc(&["check"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let out = scratch("root", &[]);
    let o = rcsc(&["build", "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(rust_files(&out), ALL_RUST);
    let o = rcsc(&["test"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("scenarios of figure13"), "{err}");
    assert!(err.contains("scenarios of submarine"), "{err}");
    assert!(err.contains("scenarios of rcs_ex"), "{err}");
    assert!(err.contains("scenarios of bridgeport_io"), "{err}");
    assert!(err.contains("scenarios of packml"), "{err}");
    assert!(err.contains("scenarios of fieldbus_drive"), "{err}");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn nested_manifests_are_plan_sets_of_their_own() {
    let dir = scratch(
        "nested",
        &[
            ("top/rcs.yaml", "system: top\n"),
            ("top/a.rcs", GO),
            ("top/parts/b.rcs", &GO.replace("A {", "B {")),
            ("top/inner/rcs.yaml", "system: inner\n"),
            ("top/inner/c.rcs", GO),
        ],
    );
    let o = rcsc_in(&dir, &["build", "top", "-o", "out"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    // `top` owns a.rcs and parts/b.rcs, but not inner/c.rcs.
    assert!(err.contains("Checking top (2 files)"), "{err}");
    assert!(err.contains("Checking inner (1 file)"), "{err}");
    assert_eq!(
        rust_files(&dir.join("out")),
        ["inner/rust/inner.rs", "top/rust/top.rs"]
    );
    let top = std::fs::read_to_string(dir.join("out/top/rust/top.rs")).unwrap();
    assert!(
        top.contains("from rcs.yaml, a.rcs, parts/b.rcs."),
        "{top:.200}"
    );

    // Naming a nested set's folder in `plans:` is a manifest error.
    std::fs::write(dir.join("top/rcs.yaml"), "plans: [a.rcs, inner]\n").unwrap();
    let o = rcsc_in(&dir, &["check", "top", "--message-format", "short"]);
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(
        err.contains("top/rcs.yaml:1:16: error[manifest]: `plans` names `inner`, which has an `rcs.yaml` of its own"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn folders_without_manifests_nest_into_workspaces() {
    let dir = scratch(
        "deep",
        &[
            ("ws/group/x/a.rcs", GO),
            ("ws/group/y/b.rcs", GO),
            ("ws/z/rcs.yaml", ""),
            ("ws/z/c.rcs", GO),
            ("ws/z/more/d.rcs", &GO.replace("A {", "D {")),
            ("ws/.hidden/e.rcs", "not even a plan"),
            ("ws/docs/notes.md", "no plans here"),
        ],
    );
    let o = rcsc_in(&dir, &["build", "ws", "-o", "out"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(
        rust_files(&dir.join("out")),
        ["x/rust/x.rs", "y/rust/y.rs", "z/rust/z.rs"]
    );
    // `z` has a manifest, so its subfolder belongs to it (without one, `z`
    // would be a workspace with `c.rcs` loose in it).
    assert!(text(&o.stderr).contains("Checking z (2 files)"));
    // Naming a member beside its workspace loads it once.
    let o = rcsc_in(&dir, &["check", "ws", "ws/z", "ws/group/x"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let o = rcsc_in(&dir, &["build", "ws", "ws/z", "-o", "again"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(files(&dir.join("out")), files(&dir.join("again")));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_member_named_alone_builds_flat_and_a_one_member_workspace_does_not() {
    let dir = scratch("one-member", &[("ws/x/a.rcs", GO)]);
    let o = rcsc_in(&dir, &["build", "ws", "-o", "ws-out"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(rust_files(&dir.join("ws-out")), ["x/rust/x.rs"]);
    let o = rcsc_in(&dir, &["build", "ws/x", "-o", "x-out"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(rust_files(&dir.join("x-out")), ["rust/x.rs"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn loose_files_beside_plan_sets_are_an_error_and_nothing_is_written() {
    let dir = scratch(
        "loose",
        &[
            ("ws/stray.rcs", GO),
            ("ws/x/rcs.yaml", ""),
            ("ws/x/a.rcs", GO),
        ],
    );
    let o = rcsc_in(
        &dir,
        &["build", "ws", "-o", "out", "--message-format", "short"],
    );
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(
        err.contains("ws/stray.rcs:1:1: error[loose_file]: `stray.rcs` stands loose beside the plan-set folders `x/`"),
        "{err}"
    );
    assert!(!dir.join("out").exists(), "a failed check writes nothing");
    // The help's way out: an rcs.yaml makes the whole folder one set.
    std::fs::write(dir.join("ws/rcs.yaml"), "system: all\n").unwrap();
    std::fs::remove_file(dir.join("ws/x/rcs.yaml")).unwrap();
    std::fs::write(dir.join("ws/x/a.rcs"), GO.replace("A {", "B {")).unwrap();
    let o = rcsc_in(&dir, &["build", "ws", "-o", "out"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("Checking all (2 files)"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_workspace_manifest_lists_its_members() {
    let dir = scratch(
        "members",
        &[
            ("root/rcs.yaml", "workspace: [plans/a]\n"),
            ("root/plans/a/a.rcs", GO),
            ("root/plans/b/b.rcs", "this is not listed, so never read"),
            ("root/tests/broken.rcs", "nor is this"),
        ],
    );
    let o = rcsc_in(&dir.join("root"), &["build", "-o", "out"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(rust_files(&dir.join("root/out")), ["a/rust/a.rs"]);
    // Naming the manifest itself is the same as naming its folder.
    let o = rcsc_in(&dir, &["check", "root/rcs.yaml"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn a_symlinked_folder_loop_is_not_followed() {
    let dir = scratch("loop", &[("ws/x/a.rcs", GO)]);
    std::os::unix::fs::symlink(dir.join("ws"), dir.join("ws/x/back")).unwrap();
    std::os::unix::fs::symlink(dir.join("ws"), dir.join("ws/loop")).unwrap();
    let o = rcsc_in(&dir, &["build", "ws", "-o", "out"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(rust_files(&dir.join("out")), ["x/rust/x.rs"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn graph_ir_and_test_take_a_workspace() {
    let o = rcsc(&["graph", "plans", "--plan", "PR.AHEAD"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(text(&o.stdout).starts_with("// @generated by rcsc"));
    let o = rcsc(&["ir", "plans", "--format", "json"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let ir: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let systems: Vec<&str> = ir
        .as_array()
        .expect("a list for a workspace")
        .iter()
        .map(|i| i["system"].as_str().unwrap())
        .collect();
    assert_eq!(
        systems,
        [
            "bridgeport_io",
            "fieldbus_drive",
            "figure13",
            "packml",
            "rcs_ex",
            "submarine"
        ]
    );
    let o = rcsc(&["test", "plans"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let scenarios = [
        "plans/submarine",
        "plans/figure13",
        "plans/rcs_ex",
        "plans/bridgeport_io",
        "plans/packml",
        "plans/fieldbus_drive",
    ]
    .iter()
    .map(|set| {
        std::fs::read_dir(Path::new(set).join("scenarios"))
            .unwrap()
            .count()
    })
    .sum::<usize>();
    let want = format!("{scenarios} passed, 0 failed\n");
    assert!(text(&o.stdout).ends_with(&want), "{}", text(&o.stdout));
}
