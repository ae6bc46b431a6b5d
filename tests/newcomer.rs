//! A newcomer's first commands: a fresh clone of this repository (its
//! HEAD, as CI and a newcomer get it: uncommitted changes are not in it),
//! then the commands of README.md's `## Quick start` `sh` block, read from
//! the README at test time and run as written in one shell, then the files
//! the Quick start promises; then the README's "Using the generated code"
//! against the clone (see `walkthrough`).
//!
//! Lines not run: the `git clone …` line (the test made the clone),
//! comment-only lines, and `cargo test …` — the test suite is what runs
//! this test, so running it again from here would recurse.
//!
//! Needs `git` and `sh`. The commands build in release mode, as the Quick
//! start says; `CARGO_TARGET_DIR` points them at `newcomer-target` under
//! cargo's target folder, kept between runs, so dependencies are built once
//! per machine; the clone is made at one kept path with its files dated to
//! the commit, so a second run of the same commit rebuilds nothing. `cargo install` goes into a temporary root whose
//! `bin` is first on `PATH`, never into `~/.cargo/bin`.

#[allow(dead_code)] // not every helper is used here
mod common;
mod markdown;
mod walkthrough;

use common::{scratch, text};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// What the Quick start promises, keyed by the command that makes it: the
/// first key found among the block's commands gives the paths (relative to
/// the clone) that must exist afterwards. When the Quick start changes,
/// change this list.
const PROMISES: &[(&str, &[&str])] = &[
    (
        "build plans/submarine",
        &[
            "target/rcs/rust/submarine.rs",
            "target/rcs/graphs/hierarchy.dot",
            "target/rcs/graphs/PR/AHEAD.dot",
            "target/rcs/tables/PR.md",
        ],
    ),
    (
        "build plans/",
        &[
            "target/rcs/submarine/rust/submarine.rs",
            "target/rcs/submarine/graphs/PR/AHEAD.dot",
            "target/rcs/submarine/tables/PR.md",
            "target/rcs/figure13/rust/figure13.rs",
            "target/rcs/figure13/graphs/hierarchy.dot",
        ],
    ),
];

/// The commands of the first `sh` block under `## Quick start`, with the
/// lines left out (and why).
fn quick_start(readme: &str) -> (Vec<String>, Vec<(String, &'static str)>) {
    let section = readme
        .split("\n## ")
        .find(|s| s.starts_with("Quick start\n"))
        .expect("README.md has a `## Quick start` section");
    let block = section
        .split("```sh\n")
        .nth(1)
        .and_then(|b| b.split("\n```").next())
        .expect("the Quick start has a ```sh block");
    let mut run = Vec::new();
    let mut skipped = Vec::new();
    for line in block.lines().map(str::trim).filter(|l| !l.is_empty()) {
        let command = line.split(" #").next().unwrap_or(line).trim();
        if line.starts_with('#') {
            continue;
        } else if command.starts_with("git clone") {
            skipped.push((line.to_string(), "the test made the clone"));
        } else if command.starts_with("cargo test") {
            skipped.push((
                line.to_string(),
                "the test suite runs this test: it would recurse",
            ));
        } else {
            run.push(line.to_string());
        }
    }
    (run, skipped)
}

#[test]
fn the_readme_quick_start_works_on_a_fresh_clone() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = scratch("newcomer", &[]);
    // A fresh clone every run, at one path kept between runs, its files
    // dated to the commit: cargo keys its builds of path packages on their
    // path and file times, so a second run of the same commit reuses the
    // first's release build instead of spending minutes on it again.
    let clone = Path::new(env!("CARGO_TARGET_TMPDIR")).join("newcomer-clone");
    let _ = std::fs::remove_dir_all(&clone);
    let cloned = Command::new("git")
        .args(["clone", "--quiet"])
        .arg(repo)
        .arg(&clone)
        .output()
        .expect("git runs (this test needs git on PATH)");
    assert!(cloned.status.success(), "{}", text(&cloned.stderr));
    date_to_commit(&clone);

    // The README of the clone: what a newcomer reads.
    let readme = std::fs::read_to_string(clone.join("README.md")).unwrap();
    let (commands, skipped) = quick_start(&readme);
    for (line, why) in &skipped {
        eprintln!("not run: `{line}` ({why})");
    }
    assert!(!commands.is_empty(), "the Quick start runs no command");
    let promised = PROMISES
        .iter()
        .find(|(key, _)| commands.iter().any(|c| c.contains(key)))
        .map(|(_, paths)| *paths)
        .unwrap_or_else(|| {
            panic!("no entry of PROMISES matches the Quick start's commands {commands:?}: add what they promise")
        });

    let root = tmp.join("install-root");
    let path = std::env::join_paths(std::iter::once(root.join("bin")).chain(
        std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()),
    ))
    .unwrap();
    let script = format!("set -ex\n{}\n", commands.join("\n"));
    let started = Instant::now();
    let out = Command::new("sh")
        .arg("-c")
        .arg(&script)
        .current_dir(&clone)
        .env(
            "CARGO_TARGET_DIR",
            Path::new(env!("CARGO_TARGET_TMPDIR")).join("newcomer-target"),
        )
        .env("CARGO_INSTALL_ROOT", &root)
        .env("PATH", path)
        .env("NO_COLOR", "1")
        .env_remove("RCSC_RUNTIME_PATH")
        .output()
        .expect("sh runs");
    eprintln!("the Quick start's commands: {:.1?}", started.elapsed());
    assert!(
        out.status.success(),
        "the Quick start failed:\n{script}\nstdout:\n{}\nstderr:\n{}",
        text(&out.stdout),
        text(&out.stderr)
    );
    let missing: Vec<&&str> = promised
        .iter()
        .filter(|p| !clone.join(p).is_file())
        .collect();
    assert!(
        missing.is_empty(),
        "the Quick start promises {missing:?}; stderr:\n{}",
        text(&out.stderr)
    );

    // Then "Using the generated code", as written, against the clone.
    let started = Instant::now();
    walkthrough::run(
        &readme,
        &clone,
        &Path::new(env!("CARGO_TARGET_TMPDIR")).join("newcomer-walkthrough"),
    );
    eprintln!("Using the generated code: {:.1?}", started.elapsed());
    let _ = std::fs::remove_dir_all(&tmp);
    let _ = std::fs::remove_dir_all(&clone);
}

/// Set every file of a clone to its commit's time (`.git` aside).
fn date_to_commit(clone: &Path) {
    let out = Command::new("git")
        .args(["log", "-1", "--format=%ct"])
        .current_dir(clone)
        .output()
        .expect("git runs");
    let seconds: u64 = text(&out.stdout).trim().parse().expect("a commit time");
    let time = std::time::UNIX_EPOCH + std::time::Duration::from_secs(seconds);
    let mut stack = vec![clone.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.file_name().is_some_and(|n| n == ".git") {
                continue;
            }
            if path.is_dir() {
                stack.push(path);
            } else {
                std::fs::File::options()
                    .write(true)
                    .open(&path)
                    .and_then(|f| f.set_modified(time))
                    .unwrap();
            }
        }
    }
}

#[test]
fn the_quick_start_reader_runs_commands_and_skips_what_it_must() {
    let readme = "# x\n\n## Quick start\n\nText.\n\n```sh\n\
                  git clone <this repository> rcsc && cd rcsc\n\
                  # a comment\n\
                  cargo run --release -- build plans/   # build\n\
                  cargo test --workspace                 # test\n\
                  ```\n\n## Next\n\n```sh\nnot this\n```\n";
    let (run, skipped) = quick_start(readme);
    assert_eq!(run, ["cargo run --release -- build plans/   # build"]);
    let skipped: Vec<&str> = skipped.iter().map(|s| s.0.as_str()).collect();
    assert_eq!(
        skipped,
        [
            "git clone <this repository> rcsc && cd rcsc",
            "cargo test --workspace                 # test"
        ]
    );
}
