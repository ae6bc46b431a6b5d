//! The split submarine as a user runs it: two processes on loopback. The
//! helm reaches AT_GOAL with the same statuses as the one-process run;
//! killing the engine makes PR's watchdog row fire (E2, after 31 silent
//! cycles) and SM fail with it; a new engine and a new order recover.
//! Every wait has a deadline; nothing asserts on timing.

#![cfg(feature = "zenoh")]

use std::io::{BufRead, BufReader, Write};
use std::net::TcpListener;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_submarine-split");
/// Generous: the machine may be busy with other builds.
const DEADLINE: Duration = Duration::from_secs(180);

/// A process whose standard output lines arrive on a channel; killed when
/// dropped.
struct Proc {
    child: Child,
    lines: Receiver<String>,
    stdin: Option<ChildStdin>,
}

impl Proc {
    fn spawn(args: &[&str]) -> Proc {
        let mut child = Command::new(BIN)
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("spawn submarine-split");
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
            child,
            lines,
            stdin,
        }
    }

    /// The first line (from now on) for which `f` holds; panics with the
    /// lines seen if the deadline passes or the process ends.
    fn wait_for(&self, what: &str, f: impl Fn(&str) -> bool) -> String {
        let deadline = Instant::now() + DEADLINE;
        let mut seen = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) if f(&line) => return line,
                Ok(line) => seen.push(line),
                Err(e) => panic!(
                    "no {what} ({e:?}); last lines:\n{}",
                    seen[seen.len().saturating_sub(30)..].join("\n")
                ),
            }
        }
    }

    fn say(&mut self, line: &str) {
        let stdin = self.stdin.as_mut().expect("stdin");
        writeln!(stdin, "{line}").expect("write to the helm");
        stdin.flush().expect("flush");
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn free_endpoint() -> String {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    format!("tls/127.0.0.1:{}", l.local_addr().expect("address").port())
}

/// A development CA and the certificates of both processes, in a fresh
/// folder of this test's.
fn certs(test: &str) -> String {
    let dir = std::env::temp_dir().join(format!("rcs-split-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    rcs_runtime::acl::certs::make_dev_certs(&dir, &["helm", "engine", "operator"], &[])
        .expect("make development certificates");
    dir.display().to_string()
}

/// The `goal` line of a one-process run of the same plan set.
fn one_process_goal() -> String {
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

#[test]
fn split_reaches_the_goal_fails_on_a_dead_engine_and_recovers() {
    let ep = free_endpoint();
    let dir = certs("goal");
    let mut helm = Proc::spawn(&["helm", "--certs", &dir, "--listen", &ep]);
    let engine = Proc::spawn(&["engine", "--certs", &dir, "--connect", &ep]);

    // 1. AT_GOAL across two processes, with the statuses of one process.
    let goal = helm.wait_for("goal line", |l| l.starts_with("goal "));
    assert_eq!(goal, one_process_goal());

    // 2. The engine dies: PR's watchdog row fires once TB's status has
    // been silent for more than 30 of PR's cycles, and SM fails with it.
    drop(engine);
    let failed = helm.wait_for("PR in ERROR", |l| {
        l.contains("PR=AHEAD/") && l.contains("/ERROR tb_stale=")
    });
    let stale: u32 = failed
        .rsplit("tb_stale=")
        .next()
        .and_then(|s| s.trim().parse().ok())
        .expect("tb_stale on the line");
    assert_eq!(
        stale, 31,
        "E2 fires on the first cycle with stale_cycles > 30"
    );
    helm.wait_for("SM in ERROR", |l| {
        l.contains("SM=TRANSIT/") && l.contains("/ERROR PR=")
    });

    // 3. A new engine and a new order: the hierarchy reaches the goal again.
    let _engine = Proc::spawn(&["engine", "--certs", &dir, "--connect", &ep]);
    helm.say("transit 15");
    helm.wait_for("the order", |l| l.starts_with("order "));
    let again = helm.wait_for("goal line after the restart", |l| l.starts_with("goal "));
    assert_eq!(again, goal);
}
