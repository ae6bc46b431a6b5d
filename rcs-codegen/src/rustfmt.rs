//! The generated Rust through the `rustfmt` binary, as bindgen does it.
//!
//! It sits between generation and the writer: the back ends stay pure
//! functions of the IR (the Rust one prints with `prettyplease`), and the
//! two places that write outputs — [`crate::Config::compile`] and
//! `rcsc build` (and the driver crate of `rcsc test --backend compiled`) —
//! pass their files through [`format_files`] before [`crate::writer`]
//! writes them. `prettyplease` breaks lines differently from rustfmt; a
//! rustfmt-identical printer is not worth owning, so, like bindgen, rcsc
//! runs the rustfmt that is installed: `$RUSTFMT` if set, else `rustfmt` on
//! `PATH`, with `--edition 2021`, the file on stdin and the result read
//! from stdout. rustfmt finds its configuration as it does for stdin (a
//! `rustfmt.toml` in the current folder or above it).
//!
//! Formatting never fails a build: when rustfmt is missing, fails, or has
//! not finished after [`TIMEOUT`] (it is then killed), the file keeps the
//! `prettyplease` text. The output is deterministic for a given rustfmt:
//! the same toolchain gives the same bytes. Comments (the row comments
//! `// E0: … [file:line]` and the `@generated` first line) are ordinary
//! comments, which rustfmt keeps where they are.

use crate::OutputFile;
use std::ffi::{OsStr, OsString};
use std::io::{Read, Write};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// How long one file may take before rustfmt is killed and the file kept
/// as generated.
pub const TIMEOUT: Duration = Duration::from_secs(60);

/// The rustfmt to run: `$RUSTFMT` if set (and not empty), else `rustfmt`.
pub fn program() -> OsString {
    std::env::var_os("RUSTFMT")
        .filter(|p| !p.is_empty())
        .unwrap_or_else(|| "rustfmt".into())
}

/// Format every `.rs` file of `files` in place with [`program`]; a file
/// rustfmt cannot format keeps its text.
pub fn format_files(files: &mut [OutputFile]) {
    format_files_with(&program(), TIMEOUT, files);
}

/// [`format_files`] with an explicit rustfmt and time limit. After the
/// first file rustfmt could not format, the rest are left as they are (a
/// missing or broken rustfmt is tried once per call, not once per file).
pub fn format_files_with(program: &OsStr, timeout: Duration, files: &mut [OutputFile]) {
    for f in files.iter_mut().filter(|f| f.path.ends_with(".rs")) {
        match format_source(program, timeout, &f.contents) {
            Some(text) => f.contents = text,
            None => return,
        }
    }
}

/// An empty rustfmt configuration (rustfmt's defaults), so that a
/// `rustfmt.toml` near where rcsc happens to run never changes the bytes
/// it writes; `None` if it cannot be written (rustfmt then searches as
/// usual).
fn default_config() -> Option<std::path::PathBuf> {
    let path = std::env::temp_dir().join("rcsc-rustfmt-defaults.toml");
    let text = "# rcsc: rustfmt's default settings, for generated code.\n";
    if std::fs::read_to_string(&path).ok().as_deref() != Some(text) {
        std::fs::write(&path, text).ok()?;
    }
    Some(path)
}

/// `source` formatted by `program` (`--edition 2021`, stdin to stdout), or
/// `None` when it cannot be run, exits unsuccessfully, prints nothing, or
/// takes longer than `timeout`.
pub fn format_source(program: &OsStr, timeout: Duration, source: &str) -> Option<String> {
    let mut command = Command::new(program);
    command.args(["--edition", "2021", "--emit", "stdout", "--quiet"]);
    if let Some(config) = default_config() {
        command.arg("--config-path").arg(config);
    }
    let mut child = command
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    // Feed and read from threads, so neither a full pipe nor a rustfmt that
    // never answers can block this one past the deadline.
    let mut stdin = child.stdin.take()?;
    let input = source.to_string();
    std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let mut stdout = child.stdout.take()?;
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut out = Vec::new();
        let read = stdout.read_to_end(&mut out).map(|_| out);
        let _ = tx.send(read);
    });
    let deadline = Instant::now() + timeout;
    let output = rx.recv_timeout(timeout).ok().and_then(Result::ok);
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break Some(status),
            Ok(None) if output.is_some() && Instant::now() < deadline => {
                std::thread::sleep(Duration::from_millis(2));
            }
            _ => {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
        }
    };
    let text = String::from_utf8(output?).ok()?;
    (status?.success() && !text.trim().is_empty()).then_some(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SOURCE: &str = "// @generated by rcsc from t.rcs. Do not edit.\n\
        pub enum Mode { Transit { speed: f64, heading_in_degrees: f64, depth_in_metres: f64 } }\n";

    fn files() -> Vec<OutputFile> {
        vec![
            OutputFile {
                path: "rust/t.rs".into(),
                contents: SOURCE.into(),
            },
            OutputFile {
                path: "tables/T.md".into(),
                contents: "| a |   b |\n".into(),
            },
        ]
    }

    #[test]
    fn rustfmt_formats_rust_files_only_and_keeps_the_first_line() {
        let mut files = files();
        format_files_with(&program(), TIMEOUT, &mut files);
        if files == self::files() {
            // Skipped without rustfmt, except on CI (which has it).
            assert!(std::env::var_os("CI").is_none(), "rustfmt did not run");
            eprintln!("note: rustfmt is not installed; formatting not checked");
            return;
        }
        let rust = &files[0].contents;
        assert!(
            rust.starts_with("// @generated by rcsc from t.rcs. Do not edit.\n"),
            "{rust}"
        );
        assert!(
            rust.contains("    Transit {\n        speed: f64,\n"),
            "{rust}"
        );
        assert_eq!(files[1], self::files()[1]);
        // Formatting is a fixpoint and deterministic.
        let mut again = files.clone();
        format_files_with(&program(), TIMEOUT, &mut again);
        assert_eq!(again, files);
    }

    #[test]
    fn a_missing_or_failing_rustfmt_leaves_the_text_as_generated() {
        for program in ["false", "/nonexistent/rustfmt", "true"] {
            let mut files = files();
            format_files_with(OsStr::new(program), TIMEOUT, &mut files);
            assert_eq!(files, self::files(), "{program}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_rustfmt_that_hangs_is_killed_after_the_timeout() {
        let dir = std::env::temp_dir().join(format!("rcs-rustfmt-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let hang = dir.join("hang.sh");
        std::fs::write(&hang, "#!/bin/sh\nexec sleep 30\n").unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&hang, std::fs::Permissions::from_mode(0o755)).unwrap();
        let start = Instant::now();
        let mut files = files();
        format_files_with(hang.as_os_str(), Duration::from_millis(300), &mut files);
        assert_eq!(files, self::files());
        let took = start.elapsed();
        assert!(
            took >= Duration::from_millis(300) && took < Duration::from_secs(20),
            "{took:?}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
