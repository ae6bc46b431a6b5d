//! Whether Graphviz's `dot` is installed, for the end-to-end tests that
//! render with it (DOT syntax of every generated graph, `rcsc graph
//! --format svg`, the README's state graph).

use std::process::{Command, Stdio};

/// Whether `dot -V` runs. Without it the caller skips `what` with a note,
/// except on CI (`CI` set), where a missing `dot` fails the test: `.ci/run`
/// installs Graphviz, so skipping there would hide a broken install.
pub fn dot_available(what: &str) -> bool {
    let found = Command::new("dot")
        .arg("-V")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !found {
        assert!(
            std::env::var_os("CI").is_none(),
            "Graphviz `dot` is not installed, so {what} cannot be checked (CI is set: install graphviz)"
        );
        eprintln!("note: Graphviz `dot` is not installed; {what} not checked");
    }
    found
}
