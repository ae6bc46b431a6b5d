//! The generated files themselves, for every plan set in `plans/` and every
//! ok case in `tests/data/ok/` (picked up by walking the folders: add a case,
//! get its outputs tested):
//!
//! - every generated file is kept as an insta snapshot, named after the
//!   case and the output path (`tests/snapshots/` for `plans/`,
//!   `tests/data/ok/snapshots/` for the ok cases); after a deliberate
//!   change, run `INSTA_UPDATE=always cargo test --test generated` and
//!   review the diff. The Rust is snapshotted as written, after rustfmt;
//!   without rustfmt its snapshots are skipped with a note;
//! - every DOT file parses with Graphviz (`dot -Tsvg`);
//! - every Rust file `rcsc build` writes passes `rustfmt --check`.
//!
//! Without `dot` or `rustfmt` the tests that need them are skipped with a
//! note, unless `CI` is set, where they fail.

use rcs_codegen::OutputFile;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

mod tools;

/// One plan set to generate: where its snapshots go and its name there.
struct Case {
    path: PathBuf,
    name: String,
    snapshots: &'static str,
}

fn entries(dir: &str, keep: impl Fn(&Path) -> bool) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|e| e.expect("readable entry").path())
        .filter(|p| keep(p))
        .collect();
    out.sort();
    out
}

fn cases() -> Vec<Case> {
    let name = |p: &Path| p.file_stem().unwrap().to_string_lossy().into_owned();
    let mut cases: Vec<Case> = entries("plans", |p| p.is_dir())
        .into_iter()
        .map(|p| Case {
            name: name(&p),
            path: p,
            snapshots: "snapshots",
        })
        .collect();
    // The same selection as the golden tests: `NNNN_name.rcs` or a folder.
    let ok = entries("tests/data/ok", |p| {
        p.file_name().unwrap().to_string_lossy().as_bytes()[0].is_ascii_digit()
            && (p.is_dir() || p.extension().is_some_and(|e| e == "rcs"))
    });
    cases.extend(ok.into_iter().map(|p| Case {
        name: name(&p),
        path: p,
        snapshots: "data/ok/snapshots",
    }));
    assert!(cases.len() > 2, "no ok cases found");
    cases
}

fn generate(case: &Case) -> Vec<OutputFile> {
    let sets = rcs_dsl::load_paths(std::slice::from_ref(&case.path))
        .unwrap_or_else(|e| panic!("{}: {e}", case.path.display()));
    assert_eq!(sets.len(), 1, "{}", case.path.display());
    let checked = rcs_dsl::check(&sets[0], &rcs_dsl::Options::default());
    let ir = checked.ir.unwrap_or_else(|| {
        panic!(
            "{}: does not check: {:?}",
            case.path.display(),
            checked.diagnostics
        )
    });
    rcs_codegen::generate(&ir)
}

#[test]
fn generated_files_match_their_snapshots() {
    let formatted = tools::rustfmt_available("the snapshots of the generated Rust");
    for case in cases() {
        let mut files = generate(&case);
        if formatted {
            rcs_codegen::rustfmt::format_files(&mut files);
        }
        let mut paths: Vec<&str> = files.iter().map(|f| f.path.as_str()).collect();
        paths.sort_unstable();
        paths.dedup();
        assert_eq!(
            paths.len(),
            files.len(),
            "{}: duplicate output paths",
            case.name
        );
        insta::with_settings!({
            snapshot_path => case.snapshots,
            prepend_module_to_snapshot => false,
            omit_expression => true,
            description => format!("{}: rcsc build {}", case.name, case.path.display()),
        }, {
            for f in files.iter().filter(|f| formatted || !f.path.ends_with(".rs")) {
                assert!(f.contents.lines().next().unwrap_or("").contains(rcs_codegen::GENERATED));
                let name = format!("{}__{}", case.name, f.path.replace('/', "__"));
                insta::assert_snapshot!(name, f.contents);
            }
        });
    }
}

#[test]
fn every_dot_file_renders_with_graphviz() {
    if !tools::dot_available("the generated DOT files") {
        return;
    }
    let (mut checked, mut failures) = (0, Vec::new());
    for case in cases() {
        for f in generate(&case).iter().filter(|f| f.path.ends_with(".dot")) {
            let mut child = Command::new("dot")
                .arg("-Tsvg")
                .stdin(Stdio::piped())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("dot runs");
            let mut stdin = child.stdin.take().unwrap();
            let contents = f.contents.clone();
            // Write from another thread so a full stdout pipe cannot deadlock.
            let writer = std::thread::spawn(move || stdin.write_all(contents.as_bytes()));
            let out = child.wait_with_output().expect("dot finishes");
            writer.join().unwrap().expect("dot reads its input");
            let stderr = String::from_utf8_lossy(&out.stderr);
            if !out.status.success() || !stderr.trim().is_empty() {
                failures.push(format!(
                    "{} {}: dot -Tsvg: {}\n{}\n--- input ---\n{}",
                    case.name,
                    f.path,
                    out.status,
                    stderr.trim_end(),
                    f.contents
                ));
            } else {
                assert!(String::from_utf8_lossy(&out.stdout).contains("<svg"));
            }
            checked += 1;
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {checked} DOT files do not render:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
    assert!(checked > 10, "only {checked} DOT files");
}

#[test]
fn every_rust_file_rcsc_writes_passes_rustfmt_check() {
    if !tools::rustfmt_available("`rustfmt --check` of the generated Rust") {
        return;
    }
    let out = std::env::temp_dir().join(format!("rcsc-generated-rustfmt-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let mut rust = Vec::new();
    for case in cases() {
        let dir = out.join(&case.name);
        let o = Command::new(env!("CARGO_BIN_EXE_rcsc"))
            .arg("build")
            .arg(&case.path)
            .arg("-o")
            .arg(&dir)
            .arg("-q")
            .output()
            .expect("rcsc runs");
        assert!(o.status.success(), "{}: {o:?}", case.name);
        rust.extend(
            generate(&case)
                .into_iter()
                .filter(|f| f.path.ends_with(".rs"))
                .map(|f| dir.join(f.path)),
        );
    }
    assert!(rust.len() > 10, "only {} Rust files", rust.len());
    let o = Command::new(rcs_codegen::rustfmt::program())
        .args(["--edition", "2021", "--check"])
        .args(&rust)
        .output()
        .expect("rustfmt runs");
    assert!(
        o.status.success(),
        "rustfmt --check finds differences:\n{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let _ = std::fs::remove_dir_all(&out);
}
