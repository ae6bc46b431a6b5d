//! `rcsc completions SHELL` and `rcsc man` end to end (issue 28, item 3):
//! the completion scripts parse in their shells (bash always; zsh and fish
//! when installed) and the man pages render with `man -l` and `groff`
//! without warnings. `man` and `groff` are required, not optional: `.ci/run`
//! installs them, and a missing one fails with the package to install.

use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};

mod common;
use common::{rcsc, scratch, text};

/// Every subcommand the pages and the scripts must know.
const SUBCOMMANDS: [&str; 14] = [
    "check",
    "build",
    "graph",
    "ir",
    "test",
    "diff",
    "fmt",
    "doc",
    "trace",
    "certs",
    "console",
    "lsp",
    "completions",
    "man",
];

/// Run `program args…` with `input` on stdin.
fn run_with_stdin(program: &str, args: &[&str], input: &[u8]) -> std::io::Result<Output> {
    let mut child = Command::new(program)
        .args(args)
        .env("MANWIDTH", "80")
        .env("MANPAGER", "cat")
        .env("PAGER", "cat")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    let mut stdin = child.stdin.take().expect("piped stdin");
    let input = input.to_vec();
    // Write from another thread so a full stdout pipe cannot deadlock.
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let out = child.wait_with_output()?;
    // A program may stop reading early and still succeed; its status says.
    let _ = writer.join();
    Ok(out)
}

/// Whether `program` runs at all (`--version` answers).
fn installed(program: &str) -> bool {
    Command::new(program)
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Panics with what to install when a required tool is missing.
fn require(program: &str, package: &str) {
    assert!(
        installed(program),
        "`{program}` is not installed, so the man page cannot be checked; install {package} \
         (.ci/run does: apt-get install man-db groff-base)"
    );
}

fn completion_script(shell: &str) -> Vec<u8> {
    let out = rcsc(&["completions", shell]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(out.stderr.is_empty(), "{}", text(&out.stderr));
    let script = text(&out.stdout);
    for sub in SUBCOMMANDS {
        assert!(
            script.contains(sub),
            "{shell} script lacks `{sub}`:\n{script}"
        );
    }
    out.stdout
}

/// `shell CHECK_FLAG FILE` exits 0 with nothing on stderr.
fn assert_parses(shell: &str, check_flag: &str, script: &[u8], dir: &Path) {
    let file = dir.join(format!("rcsc.{shell}"));
    std::fs::write(&file, script).unwrap();
    let out = Command::new(shell)
        .arg(check_flag)
        .arg(&file)
        .output()
        .unwrap_or_else(|e| panic!("{shell} runs: {e}"));
    assert!(
        out.status.success() && out.stderr.is_empty(),
        "{shell} {check_flag} {}: {}\n{}",
        file.display(),
        out.status,
        text(&out.stderr)
    );
}

#[test]
fn the_bash_script_parses() {
    let dir = scratch("bash", &[]);
    let script = completion_script("bash");
    assert_parses("bash", "-n", &script, &dir);
    // The check can fail: a script cut in half does not parse.
    let half = &script[..script.len() / 2];
    let file = dir.join("half.bash");
    std::fs::write(&file, half).unwrap();
    let out = Command::new("bash").arg("-n").arg(&file).output().unwrap();
    assert!(!out.status.success(), "bash -n accepted half a script");
}

#[test]
fn the_zsh_and_fish_scripts_parse_where_installed() {
    let dir = scratch("zsh-fish", &[]);
    for (shell, flag) in [("zsh", "-n"), ("fish", "--no-execute")] {
        let script = completion_script(shell);
        if installed(shell) {
            assert_parses(shell, flag, &script, &dir);
        } else {
            eprintln!("note: {shell} is not installed; its completion script was not parsed");
        }
    }
}

#[test]
fn every_shell_gets_a_script_and_an_unknown_one_is_refused() {
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        assert!(!completion_script(shell).is_empty());
    }
    let out = rcsc(&["completions", "tcsh"]);
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(err.contains("invalid value 'tcsh'"), "{err}");
    assert!(err.contains("bash"), "{err}");
}

/// The page rendered by `man -l -`, overstrikes removed; asserts it has
/// the NAME and SYNOPSIS sections and the manual's name in its header.
fn assert_renders(page: &[u8], name: &str) {
    require("man", "man-db");
    require("groff", "groff-base");
    let out = run_with_stdin("man", &["-l", "-"], page).expect("man runs");
    assert_eq!(out.status.code(), Some(0), "man -l: {}", text(&out.stderr));
    let mut shown = String::new();
    for c in text(&out.stdout).chars() {
        if c == '\u{8}' {
            shown.pop(); // `X\bX` is bold, `_\bX` underlined: keep the last.
        } else {
            shown.push(c);
        }
    }
    for section in ["NAME", "SYNOPSIS", "DESCRIPTION"] {
        assert!(
            shown.lines().any(|l| l.trim_end() == section),
            "{name}: no {section} section in:\n{shown}"
        );
    }
    let header = shown.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    assert!(header.contains("rcsc manual"), "{name}: header `{header}`");
    assert!(
        header.starts_with(&format!("{name}(1)")),
        "{name}: header `{header}`"
    );
    // groff with every warning on: a malformed page warns even where man
    // would still show something.
    let out = run_with_stdin("groff", &["-man", "-Tutf8", "-ww", "-z"], page).expect("groff runs");
    assert!(
        out.status.success() && out.stderr.is_empty(),
        "{name}: groff -man -ww: {}\n{}",
        out.status,
        text(&out.stderr)
    );
}

#[test]
fn the_man_page_renders() {
    let out = rcsc(&["man"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let page = text(&out.stdout);
    assert!(page.starts_with(".\\\" @generated by rcsc"), "{page}");
    for sub in SUBCOMMANDS {
        assert!(
            page.contains(&format!("rcsc\\-{sub}(1)")),
            "no rcsc-{sub}:\n{page}"
        );
    }
    assert_renders(&out.stdout, "rcsc");
    // Deterministic: no date, nothing from the machine.
    assert_eq!(rcsc(&["man"]).stdout, out.stdout);
}

#[test]
fn man_out_writes_one_page_per_subcommand_and_keeps_hand_written_files() {
    let dir = scratch("man-out", &[]);
    let out_dir = dir.join("man");
    let out_arg = out_dir.to_str().unwrap();
    let out = rcsc(&["man", "--out", out_arg]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let mut names: Vec<String> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut expected: Vec<String> = SUBCOMMANDS.iter().map(|s| format!("rcsc-{s}.1")).collect();
    expected.push("rcsc.1".into());
    expected.sort();
    assert_eq!(names, expected);
    assert_eq!(
        std::fs::read(out_dir.join("rcsc.1")).unwrap(),
        rcsc(&["man"]).stdout,
        "rcsc.1 is what `rcsc man` prints"
    );
    for name in &names {
        let page = std::fs::read(out_dir.join(name)).unwrap();
        assert_renders(&page, name.trim_end_matches(".1"));
    }
    let check = text(&std::fs::read(out_dir.join("rcsc-check.1")).unwrap());
    assert!(check.contains("\\-\\-message\\-format"), "{check}");

    // Its own pages are replaced; a hand-written one is not, and then
    // nothing is written.
    let again = rcsc(&["man", "--out", out_arg]);
    assert_eq!(again.status.code(), Some(0), "{}", text(&again.stderr));
    std::fs::write(out_dir.join("rcsc-ir.1"), "my own notes\n").unwrap();
    std::fs::remove_file(out_dir.join("rcsc.1")).unwrap();
    let refused = rcsc(&["man", "--out", out_arg]);
    assert_eq!(refused.status.code(), Some(2));
    let err = text(&refused.stderr);
    assert!(
        err.contains("rcsc-ir.1 exists and was not written by rcsc"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(out_dir.join("rcsc-ir.1")).unwrap(),
        "my own notes\n"
    );
    assert!(!out_dir.join("rcsc.1").exists(), "wrote before refusing");
}

/// A reader that stops early (`rcsc test plans/ | head -1`) closes the
/// pipe under a report still being written: the command ends without a
/// panic (status 101 and a `panicked` line are what `print!` makes of it).
#[test]
fn a_closed_stdout_ends_a_report_without_a_panic() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    // 200 unformatted files: their diffs are more than a pipe holds.
    let files: Vec<(String, String)> = (0..200)
        .map(|i| {
            let body = format!(
                "controller C{i} {{\n  command   GO\n  plan GO {{ *0 when new_command -> Done }}\n}}\n"
            );
            (format!("c{i}.rcs"), body)
        })
        .collect();
    let files: Vec<(&str, &str)> = files
        .iter()
        .map(|(p, b)| (p.as_str(), b.as_str()))
        .collect();
    let unformatted = scratch("closed_stdout", &files);
    let plans = repo.join("plans");
    let set = plans.join("bridgeport_io");
    let cases: [(&str, Vec<&std::ffi::OsStr>); 3] = [
        ("test", vec!["test".as_ref(), plans.as_os_str()]),
        (
            "fmt --check",
            vec!["fmt".as_ref(), "--check".as_ref(), unformatted.as_os_str()],
        ),
        ("ir", vec!["ir".as_ref(), set.as_os_str()]),
    ];
    for (name, args) in cases {
        let mut child = Command::new(env!("CARGO_BIN_EXE_rcsc"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("rcsc runs");
        // Read a byte, then close the pipe.
        let mut out = child.stdout.take().expect("stdout");
        let _ = std::io::Read::read(&mut out, &mut [0u8; 1]);
        drop(out);
        let output = child.wait_with_output().expect("rcsc ends");
        let stderr = text(&output.stderr);
        assert!(!stderr.contains("panicked"), "rcsc {name}: {stderr}");
        assert_ne!(output.status.code(), Some(101), "rcsc {name}: {stderr}");
    }
}
