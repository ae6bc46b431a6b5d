//! Whether the external tools some end-to-end tests run are installed:
//! Graphviz's `dot` (DOT syntax of every generated graph, `rcsc graph
//! --format svg`, the README's state graph) and `rustfmt` (the generated
//! Rust is formatted with it).

use std::process::{Command, Stdio};

/// Whether `dot -V` runs. Without it the caller skips `what` with a note,
/// except on CI (`CI` set), where a missing `dot` fails the test: `.ci/run`
/// installs Graphviz, so skipping there would hide a broken install.
#[allow(dead_code)] // each test binary compiles this module; not all use it
pub fn dot_available(what: &str) -> bool {
    available("dot", "-V", "Graphviz `dot`", "install graphviz", what)
}

/// Whether the rustfmt rcsc runs (`$RUSTFMT`, else `rustfmt`) answers
/// `--version`; like [`dot_available`], a missing one fails on CI, which
/// has rustfmt since it runs `cargo fmt --check`.
#[allow(dead_code)]
pub fn rustfmt_available(what: &str) -> bool {
    available(
        &rcs_codegen::rustfmt::program().to_string_lossy(),
        "--version",
        "rustfmt",
        "rustup component add rustfmt",
        what,
    )
}

fn available(program: &str, arg: &str, name: &str, install: &str, what: &str) -> bool {
    let found = Command::new(program)
        .arg(arg)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !found {
        assert!(
            std::env::var_os("CI").is_none(),
            "{name} is not installed, so {what} cannot be checked (CI is set: {install})"
        );
        eprintln!("note: {name} is not installed; {what} not checked");
    }
    found
}
