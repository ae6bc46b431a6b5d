//! The README's "Using the generated code", followed as a newcomer would:
//! its `file=…` blocks make a crate in a folder of its own outside any
//! workspace (`/path/to/rcsc` becomes the rcsc checkout given, and
//! `plans/submarine` is copied in as its first step says), `cargo run`
//! builds and runs it offline against that checkout's lock file, and its
//! output must start each line of the ```text output block.
//!
//! Then four mistakes a newcomer makes, on the same crate: naming a plan set
//! the build script did not compile (`include_plans!` must say which ones
//! it did), a plan with an error (the build fails with the diagnostic,
//! and the summary is not repeated over and over), a plan-set path that
//! does not exist (`cargo::error=` lines with the path and a hint) and an
//! empty plan-set folder (`no_plans`).

use crate::markdown::blocks;
use std::path::Path;
use std::process::{Command, Output};

/// Run the walk-through of `readme` against the rcsc checkout at `rcsc`,
/// building under `target`.
pub fn run(readme: &str, rcsc: &Path, target: &Path) {
    let doc = readme
        .split("\n## ")
        .find(|s| s.starts_with("Using the generated code\n"))
        .expect("README.md has a `## Using the generated code` section");
    let blocks = blocks(doc);
    let mut files: Vec<(String, String)> = Vec::new();
    for b in &blocks {
        let Some(file) = b.attrs.iter().find_map(|a| a.strip_prefix("file=")) else {
            continue;
        };
        let text = b.text.replace("/path/to/rcsc", &rcsc.display().to_string());
        match files.iter_mut().find(|(f, _)| f == file) {
            Some((_, all)) => all.push_str(&text),
            None => files.push((file.to_string(), text)),
        }
    }
    let names: Vec<&str> = files.iter().map(|(f, _)| f.as_str()).collect();
    assert_eq!(names, ["Cargo.toml", "build.rs", "src/main.rs"]);
    let expected: Vec<&str> = blocks
        .iter()
        .find(|b| b.lang == "text" && b.attrs.iter().any(|a| a == "output"))
        .expect("a ```text output block")
        .text
        .lines()
        .collect();

    // Outside the workspace (cargo would take it for a member), one folder
    // per checkout and target; the build is cached in `target`.
    let tag: String = format!("{}{}", rcsc.display(), target.display())
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    let dir = std::env::temp_dir().join(format!("rcsc-walkthrough{tag}"));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(dir.join("src")).unwrap();
    copy_tree(&rcsc.join("plans/submarine"), &dir.join("plans/submarine"));
    for (file, text) in &files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    std::fs::copy(rcsc.join("Cargo.lock"), dir.join("Cargo.lock")).unwrap();
    let cargo = |args: &[&str]| -> Output {
        Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
            .args(args)
            .arg("--offline")
            .current_dir(&dir)
            .env("CARGO_TARGET_DIR", target)
            .env_remove("RUSTFLAGS")
            .output()
            .expect("cargo runs")
    };
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();

    let out = cargo(&["run", "--quiet"]);
    let stdout = text(&out.stdout);
    assert!(
        out.status.success(),
        "the walk-through's crate failed:\n{stdout}\n{}",
        text(&out.stderr)
    );
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), expected.len(), "output:\n{stdout}");
    for (got, want) in lines.iter().zip(&expected) {
        assert!(got.starts_with(want), "`{got}` should start with `{want}`");
    }

    // A plan set the build script did not compile: a compile error that
    // says which ones it did.
    let main = dir.join("src/main.rs");
    let source = std::fs::read_to_string(&main).unwrap();
    let wrong = source.replace(
        "include_plans!(\"submarine\")",
        "include_plans!(\"submarin\")",
    );
    assert_ne!(wrong, source, "the walk-through includes `submarine`");
    std::fs::write(&main, wrong).unwrap();
    let out = cargo(&["build", "--quiet"]);
    let stderr = text(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("no plan set named `submarin`: this crate's build.rs compiled `submarine`"),
        "{stderr}"
    );
    std::fs::write(&main, &source).unwrap();

    // A plan with an error: the build fails with the diagnostic; the
    // summary stands in cargo's error line and its echo of the build
    // script's output, not more.
    let plan = dir.join("plans/submarine/propulsion.rcs");
    let good = std::fs::read_to_string(&plan).unwrap();
    std::fs::write(&plan, good.replacen("TB.done", "TB.dnoe", 1)).unwrap();
    let out = cargo(&["build", "--quiet"]);
    let stderr = text(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("error[unknown_name]: subordinate `TB` has no property `dnoe`"),
        "{stderr}"
    );
    let summary = "could not compile the plans in `plans/submarine` due to 1 error";
    assert_eq!(stderr.matches(summary).count(), 2, "{stderr}");
    assert!(
        stderr.contains("the plans have 1 error, shown above"),
        "{stderr}"
    );
    std::fs::write(&plan, good).unwrap();

    // The plan-set folder is not where build.rs says: cargo's own error
    // lines (`cargo::error=`) name the path and say what to do, and the
    // build script's `main` does not add a Debug-formatted `Error:`.
    let plans = dir.join("plans/submarine");
    let away = dir.join("plans-away");
    std::fs::rename(&plans, &away).unwrap();
    let out = cargo(&["build", "--quiet"]);
    let stderr = text(&out.stderr);
    assert!(!out.status.success());
    let errors: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("error: ") && l.contains("plans/submarine"))
        .collect();
    assert!(
        errors.iter().any(|l| l.contains("hint: `Config::compile` takes the plan-set folder relative to the crate's `Cargo.toml`")),
        "no cargo::error hint naming the path:\n{stderr}"
    );
    assert!(
        !stderr.contains("NotFound {"),
        "a Debug-formatted error:\n{stderr}"
    );

    // An empty plan-set folder is an error (`no_plans`), not an empty system.
    std::fs::create_dir_all(&plans).unwrap();
    let out = cargo(&["build", "--quiet"]);
    let stderr = text(&out.stderr);
    assert!(!out.status.success(), "an empty plan set built:\n{stderr}");
    assert!(stderr.contains("error[no_plans]"), "{stderr}");
    std::fs::remove_dir_all(&plans).unwrap();
    std::fs::rename(&away, &plans).unwrap();
    std::fs::remove_dir_all(dir).ok();
}

/// `cp -r from to`.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let dest = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_tree(&path, &dest);
        } else {
            std::fs::copy(&path, dest).unwrap();
        }
    }
}
