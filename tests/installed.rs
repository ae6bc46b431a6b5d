//! An installed `rcsc` needs no checkout: `cargo install` from a copy of
//! this repository into a temporary root, delete the copy, then run the
//! compiled backend on a plan set in another folder, offline.
//!
//! Needs `git` (to list the repository's files) and cargo with rcsc's
//! dependencies in its registry cache (true once rcsc has been built, which
//! running this test implies). The copy is made at one path under cargo's
//! target folder, with the files' times kept, and the install builds into a
//! folder there kept between runs (`installed-build`), so a second run
//! rebuilds only what changed; the driver builds into `installed-drivers`,
//! also kept.

#[allow(dead_code)] // not every helper is used here
mod common;

use common::{scratch, text};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A folder under cargo's target folder, kept between test runs.
fn kept(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(name)
}

fn cargo() -> Command {
    Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
}

/// The repository as a person's checkout holds it: the files git tracks and
/// the new ones it does not ignore, as they are in the working tree.
fn copy_checkout(to: &Path) {
    let listed = Command::new("git")
        .args([
            "ls-files",
            "-z",
            "--cached",
            "--others",
            "--exclude-standard",
        ])
        .current_dir(repo())
        .output()
        .expect("git runs (this test needs git on PATH)");
    assert!(listed.status.success(), "{}", text(&listed.stderr));
    for path in listed.stdout.split(|&b| b == 0).filter(|p| !p.is_empty()) {
        let path = std::str::from_utf8(path).expect("a UTF-8 path");
        let from = repo().join(path);
        if !from.is_file() {
            continue; // deleted in the working tree
        }
        let into = to.join(path);
        std::fs::create_dir_all(into.parent().unwrap()).unwrap();
        std::fs::copy(&from, &into).unwrap();
        // Keep the file's time, as `cp -p` does: at the same kept path, cargo
        // then rebuilds only what changed since the last run.
        let modified = std::fs::metadata(&from).unwrap().modified().unwrap();
        std::fs::File::options()
            .write(true)
            .open(&into)
            .and_then(|f| f.set_modified(modified))
            .unwrap();
    }
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let path = entry.path();
        if path.is_dir() {
            copy_dir(&path, &to.join(entry.file_name()));
        } else {
            std::fs::copy(&path, to.join(entry.file_name())).unwrap();
        }
    }
}

/// `rcsc test` as a user runs it: in `cwd`, offline, without what cargo
/// sets for this test process.
fn rcsc_test(rcsc: &Path, cwd: &Path, args: &[&str]) -> Output {
    Command::new(rcsc)
        .arg("test")
        .args(args)
        .current_dir(cwd)
        .env("NO_COLOR", "1")
        .env("CARGO_NET_OFFLINE", "true")
        .env_remove("CARGO")
        .env_remove("CARGO_TARGET_DIR")
        .env_remove("RCSC_RUNTIME_PATH")
        .output()
        .expect("rcsc runs")
}

#[test]
fn an_installed_rcsc_runs_the_compiled_backend_without_its_checkout() {
    let tmp = scratch("installed", &[]);
    // The copy lives at one path kept between runs (and is deleted after
    // the install, as the test requires): cargo keys its build of a path
    // package on that path, so a second run reuses the first's.
    let source = kept("installed-checkout");
    let _ = std::fs::remove_dir_all(&source);
    let root = tmp.join("root");
    copy_checkout(&source);

    let started = Instant::now();
    let install = cargo()
        .args(["install", "--locked", "--offline", "--debug", "--quiet"])
        .arg("--path")
        .arg(&source)
        .arg("--root")
        .arg(&root)
        .arg("--target-dir")
        .arg(kept("installed-build"))
        .env_remove("CARGO_TARGET_DIR")
        .env_remove("CARGO_INSTALL_ROOT")
        .output()
        .expect("cargo runs");
    assert!(
        install.status.success(),
        "cargo install failed:\n{}",
        text(&install.stderr)
    );
    eprintln!("cargo install: {:.1?}", started.elapsed());
    std::fs::remove_dir_all(&source).unwrap();
    assert!(!source.exists());

    // A plan set with its scenarios, alone in another folder.
    let work = tmp.join("work");
    copy_dir(&repo().join("plans/submarine"), &work);
    let scenarios = std::fs::read_dir(work.join("scenarios")).unwrap().count();
    let rcsc = root
        .join("bin")
        .join(format!("rcsc{}", std::env::consts::EXE_SUFFIX));
    let drivers = kept("installed-drivers");
    let drivers = drivers.to_str().unwrap();

    let started = Instant::now();
    let compiled = rcsc_test(
        &rcsc,
        &work,
        &[".", "--backend", "compiled", "--target-dir", drivers],
    );
    eprintln!("rcsc test --backend compiled: {:.1?}", started.elapsed());
    let report = text(&compiled.stdout);
    assert_eq!(
        compiled.status.code(),
        Some(0),
        "{report}{}",
        text(&compiled.stderr)
    );
    assert!(
        report.ends_with(&format!("\n{scenarios} passed, 0 failed\n")),
        "{report}"
    );
    let interp = rcsc_test(&rcsc, &work, &["."]);
    assert_eq!(interp.status.code(), Some(0));
    assert_eq!(
        report,
        text(&interp.stdout),
        "the same report on both backends"
    );

    // The driver builds against the runtime rcsc carries, not a checkout.
    let manifest = std::fs::read_to_string(Path::new(drivers).join("rcsc/driver/Cargo.toml"))
        .expect("the driver crate");
    assert!(
        manifest.contains("rcs-runtime = { path = \"../rcs-runtime\" }"),
        "{manifest}"
    );
    let lib = std::fs::read_to_string(Path::new(drivers).join("rcsc/rcs-runtime/src/lib.rs"))
        .expect("the shipped runtime");
    assert!(lib.lines().next().unwrap().contains("@generated by rcsc"));
    let _ = std::fs::remove_dir_all(&tmp);
}

/// When the runtime cannot be built (here: cargo offline with an empty
/// registry cache), `rcsc test` says why and exits 2.
#[test]
fn a_runtime_that_cannot_be_built_is_a_clear_error() {
    let tmp = scratch("no-registry", &[]);
    let empty_home = tmp.join("cargo-home");
    std::fs::create_dir_all(&empty_home).unwrap();
    let target = tmp.join("target");
    // The compiled backend on figure13, with `env` (name, value or unset).
    let compiled = |env: &[(&str, Option<&Path>)]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_rcsc"));
        cmd.args(["test", "plans/figure13", "--backend", "compiled"])
            .arg("--target-dir")
            .arg(&target)
            .env("NO_COLOR", "1");
        for (name, value) in env {
            match value {
                Some(v) => cmd.env(name, v),
                None => cmd.env_remove(name),
            };
        }
        let out = cmd.output().expect("rcsc runs");
        assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
        (text(&out.stdout), text(&out.stderr))
    };

    let (stdout, stderr) = compiled(&[
        ("CARGO_HOME", Some(&empty_home)),
        ("CARGO_NET_OFFLINE", Some(Path::new("true"))),
        ("RCSC_RUNTIME_PATH", None),
    ]);
    assert!(
        stderr.contains("building the scenario driver (")
            && stderr.contains(") failed; cargo said:"),
        "{stderr}"
    );
    assert!(
        stderr.contains("help: the driver needs rcs-runtime's dependencies"),
        "{stderr}"
    );
    assert!(stdout.is_empty(), "no scenario ran:\n{stdout}");

    // A runtime folder that is not a crate is refused before cargo runs.
    let (_, stderr) = compiled(&[("RCSC_RUNTIME_PATH", Some(&empty_home))]);
    assert!(
        stderr.contains("is not a crate folder (no Cargo.toml)"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&tmp);
}
