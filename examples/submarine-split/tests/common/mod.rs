//! What the split submarine's tests share: a child process read line by
//! line ([`Proc`]), the one place that builds endpoints ([`endpoint`]) and
//! the security arguments of every helm and engine spawn
//! ([`security_args`]), and the parsing of the helm's lines.
//!
//! `two_processes.rs` runs helm and engine on loopback; `netns_faults.rs`
//! runs them in network namespaces of their own (`netns.rs` here) with
//! faults between them. Every wait has a generous deadline; nothing asserts
//! on timing.

#![allow(dead_code)] // each test binary uses part of it

pub mod netns;

use std::ffi::OsStr;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The split submarine's binary.
pub const BIN: &str = env!("CARGO_BIN_EXE_submarine-split");
/// The fault-injecting relay (`src/bin/fault_relay.rs`).
pub const RELAY: &str = env!("CARGO_BIN_EXE_fault-relay");
/// Generous: the machine may be busy with other builds.
pub const DEADLINE: Duration = Duration::from_secs(180);

/// The extra arguments every helm and engine gets for the bridge's
/// security: `--certs DIR` with a development CA and the certificates of
/// `helm`, `engine` and `operator`, made once per test process in a folder
/// of its own under `dir`. Every link is then mutual TLS under the policy
/// rcsc generated.
pub fn security_args(dir: &Path) -> Vec<String> {
    static CERTS: OnceLock<PathBuf> = OnceLock::new();
    let certs = CERTS.get_or_init(|| {
        let certs = dir.join(format!("certs-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&certs);
        rcs_runtime::acl::certs::make_dev_certs(&certs, &["helm", "engine", "operator"], &[])
            .expect("make development certificates");
        certs
    });
    vec!["--certs".into(), certs.display().to_string()]
}

/// A Zenoh TLS endpoint: `tls/ADDR:PORT`.
pub fn endpoint(addr: &str, port: u16) -> String {
    format!("tls/{addr}:{port}")
}

/// `ROLE ARGS… SECURITY…`: the arguments of a helm or engine run.
pub fn submarine_args(role: &str, args: &[&str], security_dir: &Path) -> Vec<String> {
    std::iter::once(role.to_owned())
        .chain(args.iter().map(|a| (*a).to_owned()))
        .chain(security_args(security_dir))
        .collect()
}

/// A process whose standard output lines arrive on a channel and are kept
/// (`history`); killed when dropped.
pub struct Proc {
    pub name: String,
    child: Child,
    lines: Receiver<String>,
    stdin: Option<ChildStdin>,
    /// Every line read so far, in order.
    pub history: Vec<String>,
}

impl Proc {
    /// Run `program` with `args`, named `name` in messages.
    pub fn spawn<S: AsRef<OsStr>>(name: &str, program: &str, args: &[S]) -> Proc {
        let mut child = Command::new(program)
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap_or_else(|e| panic!("spawn {name} ({program}): {e}"));
        let out = child.stdout.take().expect("stdout");
        let stdin = child.stdin.take();
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Proc {
            name: name.to_owned(),
            child,
            lines,
            stdin,
            history: Vec::new(),
        }
    }

    /// `submarine-split ROLE ARGS…` with the security arguments.
    pub fn submarine(role: &str, args: &[&str], security_dir: &Path) -> Proc {
        Proc::spawn(role, BIN, &submarine_args(role, args, security_dir))
    }

    /// The first line (from now on) for which `f` holds; panics with the
    /// lines seen if the deadline passes or the process ends.
    pub fn wait_for(&mut self, what: &str, f: impl Fn(&str) -> bool) -> String {
        let deadline = Instant::now() + DEADLINE;
        let from = self.history.len();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) => {
                    self.history.push(line.clone());
                    if f(&line) {
                        return line;
                    }
                }
                Err(e) => {
                    let seen = &self.history[from.max(self.history.len().saturating_sub(30))..];
                    panic!(
                        "{}: no {what} ({e:?}); last lines:\n{}",
                        self.name,
                        seen.join("\n")
                    )
                }
            }
        }
    }

    /// The number after `key=` on each of the next `n` `report` lines
    /// printed from now on (lines already printed are kept, not counted).
    pub fn reports(&mut self, n: usize, key: &str) -> Vec<u64> {
        self.drain();
        (0..n)
            .map(|_| {
                let line = self.wait_for("a report line", |l| l.starts_with("report "));
                field(&line, key).unwrap_or_else(|| panic!("no {key} on `{line}`"))
            })
            .collect()
    }

    /// Whether a line read so far contains `text`.
    pub fn printed(&self, text: &str) -> bool {
        self.history.iter().any(|l| l.contains(text))
    }

    /// Keep the lines that arrived so far without waiting.
    pub fn drain(&mut self) {
        while let Ok(line) = self.lines.try_recv() {
            self.history.push(line);
        }
    }

    /// Write one line to its standard input.
    pub fn say(&mut self, line: &str) {
        let name = self.name.clone();
        let stdin = self.stdin.as_mut().expect("stdin");
        writeln!(stdin, "{line}").unwrap_or_else(|e| panic!("write to {name}: {e}"));
        stdin.flush().expect("flush");
    }

    /// Panics if the process has ended (a crash: none of them ends on its
    /// own while the tests run it).
    pub fn assert_running(&mut self) {
        if let Some(status) = self.child.try_wait().expect("try_wait") {
            self.drain();
            let tail = &self.history[self.history.len().saturating_sub(30)..];
            panic!(
                "{} ended: {status}; last lines:\n{}",
                self.name,
                tail.join("\n")
            );
        }
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The `goal` line of a one-process run of the same plan set.
pub fn one_process_goal() -> String {
    let out = Command::new(BIN)
        .args(["one-process"])
        .output()
        .expect("run one-process");
    assert!(out.status.success(), "one-process run failed");
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .find(|l| l.starts_with("goal "))
        .expect("a goal line")
        .to_string()
}

/// The number after `key=` on `line`.
pub fn field(line: &str, key: &str) -> Option<u64> {
    let at = line.find(&format!("{key}="))? + key.len() + 1;
    line[at..]
        .split(|c: char| !c.is_ascii_digit())
        .next()?
        .parse()
        .ok()
}

/// Whether `line` is the helm's status line of PR failing (its watchdog
/// row E2 or another error).
pub fn is_pr_error(line: &str) -> bool {
    line.contains("PR=AHEAD/") && line.contains("/ERROR tb_stale=")
}

/// Wait for PR's watchdog to fire on the helm and return `tb_stale` on
/// that line: the count of silent cycles at which E2 fired.
pub fn watchdog_fired(helm: &mut Proc) -> u64 {
    let line = helm.wait_for("PR in ERROR (watchdog E2)", is_pr_error);
    field(&line, "tb_stale").expect("tb_stale on the line")
}

/// PR's watchdog row E2 fires on the first cycle with `TB.stale_cycles >
/// 30`: the count on the helm's ERROR line.
pub const E2_FIRES_AT: u64 = 31;
