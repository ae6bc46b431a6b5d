//! Issue 31's acceptance test, as a person would do it: the two-process
//! submarine (helm and engine, mutual TLS on loopback, the helm ordering
//! nothing itself: `--no-order`) and `rcsc console PLANS --connect HELM
//! --connect ENGINE --certs DIR` in a detached tmux session, keys typed
//! with `send-keys`, the screen read with `capture-pane`.
//!
//! The tree shows SM, PR and TB from both processes; `s` advances the
//! paused helm's cycle count by exactly one; a command typed through `c`
//! reaches SM (the helm says so) and PR reaches AT_GOAL; killing the
//! engine shows its CPU silent, TB stale and PR's watchdog error
//! (TURBINE_SILENT); `q` restores the terminal with exit status 0, and the
//! session's recording (`--trace FILE.mcap`) holds the three controllers
//! and SM's TRANSIT.
//!
//! rcsc is built here with the feature `remote-console` (cargo's lock
//! makes that wait for other builds; `RCSC_BIN` names a ready binary
//! instead). Every wait is bounded by a generous deadline; nothing asserts
//! on time. Without tmux the test skips with a reason, except under
//! `CI=true`, where it fails.

#![cfg(feature = "zenoh")]

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::thread::sleep;
use std::time::Duration;

mod common;
use common::{security_args, Proc};

const DEADLINE: Duration = Duration::from_secs(180);

#[path = "../../submarine/tests/tmux/mod.rs"]
mod tmux;
use tmux::{cycle, stale, tmux, tmux_available, tree_row, Session};

/// rcsc with the remote console: `RCSC_BIN`, or built here.
fn rcsc() -> PathBuf {
    if let Some(bin) = std::env::var_os("RCSC_BIN") {
        return PathBuf::from(bin);
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let target = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .expect("the target folder")
        .to_path_buf();
    let built = Command::new(env!("CARGO"))
        .current_dir(&root)
        .args(["build", "--bin", "rcsc", "--features", "remote-console"])
        .arg("--target-dir")
        .arg(&target)
        .status()
        .expect("run cargo");
    assert!(built.success(), "cargo build --bin rcsc failed");
    target.join("debug").join("rcsc")
}

fn free_endpoint() -> String {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    format!("tls/127.0.0.1:{}", l.local_addr().expect("address").port())
}

#[test]
fn remote_console_in_tmux_watches_steps_commands_and_sees_a_dead_engine() {
    if !tmux_available() {
        if std::env::var("CI").is_ok_and(|v| v == "true") {
            panic!("tmux is missing under CI=true (.ci/run installs it)");
        }
        println!("skipped: tmux is not installed (apt-get install tmux)");
        return;
    }
    let rcsc = rcsc();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let security = security_args(dir);
    let certs = security[1].clone();
    let (helm_ep, engine_ep) = (free_endpoint(), free_endpoint());
    let mut helm = Proc::submarine(
        "helm",
        &["--listen", &helm_ep, "--no-order", "--report-every", "10"],
        dir,
    );
    let engine = Proc::submarine(
        "engine",
        &["--connect", &helm_ep, "--listen", &engine_ep],
        dir,
    );
    helm.wait_for("the engine", |l| l == "helm: engine answered");

    let session = Session {
        name: format!("rcs-remote-console-test-{}", std::process::id()),
        deadline: DEADLINE,
    };
    let started = tmux(&[
        "new-session",
        "-d",
        "-s",
        &session.name,
        "-x",
        "170",
        "-y",
        "48",
        "bash --norc --noprofile",
    ]);
    assert!(started.status.success(), "tmux new-session: {started:?}");
    let plans = Path::new(env!("CARGO_MANIFEST_DIR")).join("plans");
    let trace = dir.join(format!("console-{}.mcap", std::process::id()));
    session.type_text(&format!(
        "PS1='shell$ '; {} console {} --connect {helm_ep} --connect {engine_ep} --certs {certs} --trace {}; echo \"console exit status: $?\"",
        rcsc.display(),
        plans.display(),
        trace.display(),
    ));
    session.keys(&["Enter"]);

    // 1. The tree: SM and PR from the helm, TB from the engine.
    let screen = session.wait_for("the tree with SM, PR and TB from both processes", |s| {
        cycle(s, "helm").is_some_and(|c| c > 0)
            && cycle(s, "engine").is_some_and(|c| c > 0)
            && tree_row(s, 0, "SM").is_some()
            && tree_row(s, 2, "PR").is_some()
            && tree_row(s, 4, "TB").and_then(stale).is_some()
    });
    println!("after start:\n{screen}");

    // 2. Pause the helm (SM is selected), let the count settle,
    // single-step: exactly one more cycle.
    session.keys(&["p"]);
    session.wait_for("the helm PAUSED", |s| s.contains("CPU helm | PAUSED |"));
    let mut paused_at = None;
    session.wait_for("a settled cycle count", |s| {
        let now = cycle(s, "helm");
        let settled = now.is_some() && now == paused_at;
        paused_at = now;
        sleep(Duration::from_millis(500));
        settled
    });
    let before = paused_at.expect("a cycle count");
    session.keys(&["s"]);
    let screen = session.wait_for("the single step", |s| cycle(s, "helm") != Some(before));
    assert_eq!(
        cycle(&screen, "helm"),
        Some(before + 1),
        "one step, one cycle:\n{screen}"
    );
    sleep(Duration::from_secs(1));
    let screen = session.screen();
    assert_eq!(
        cycle(&screen, "helm"),
        Some(before + 1),
        "still paused after the step:\n{screen}"
    );
    assert!(screen.contains("CPU helm | PAUSED |"), "{screen}");
    assert!(screen.contains("CPU engine | RUN |"), "{screen}");
    println!("after the single step:\n{screen}");
    session.keys(&["p"]);
    session.wait_for("the helm running", |s| s.contains("CPU helm | RUN |"));

    // 3. Command SM through `c`: TRANSIT(8). SM takes it (the helm prints
    // SM's new verb) and PR reaches AT_GOAL.
    session.keys(&["c"]);
    session.wait_for("the verb picker", |s| s.contains("command SM: pick a verb"));
    session.keys(&["Down", "Enter"]);
    session.wait_for("the speed prompt", |s| {
        s.contains("SM <- TRANSIT: speed (f64) = ")
    });
    session.type_text("8");
    session.keys(&["Enter"]);
    session.wait_for("the command sent", |s| {
        s.contains("sent SM <- TRANSIT(8) serial 1")
    });
    helm.wait_for("SM on TRANSIT in the helm", |l| l.contains("SM=TRANSIT/"));
    let goal = helm.wait_for("the goal in the helm", |l| l.starts_with("goal "));
    assert!(goal.contains("PR=AHEAD/"), "{goal}");
    let screen = session.wait_for("PR at AT_GOAL on the console", |s| {
        tree_row(s, 0, "SM").is_some_and(|l| l.contains("TRANSIT"))
            && tree_row(s, 2, "PR").is_some_and(|l| l.contains("AT_GOAL"))
    });
    println!("after SM <- TRANSIT(8):\n{screen}");

    // 4. The engine dies: its CPU falls silent, TB goes stale, and PR's
    // watchdog row fires (TURBINE_SILENT), as the helm reports too.
    drop(engine);
    let screen = session.wait_for("the engine silent, TB stale, PR in error", |s| {
        s.contains("CPU engine | SILENT")
            && tree_row(s, 4, "TB").and_then(stale).is_some_and(|n| n > 30)
            && tree_row(s, 2, "PR")
                .is_some_and(|l| l.contains("ERROR") && l.contains("TURBINE_SILENT"))
    });
    println!("after the engine died:\n{screen}");
    common::watchdog_fired(&mut helm);

    // 5. Quit: the shell is back, off the alternate screen, exit status 0.
    let quit = session.quit();
    assert_eq!(
        quit.exit_line.as_deref(),
        Some("console exit status: 0"),
        "{}",
        quit.screen
    );
    assert_eq!(quit.alternate_on, "0");
    helm.assert_running();

    // 6. The recording: every controller, SM on TRANSIT (verb 1).
    let bytes = std::fs::read(&trace).expect("the recording");
    let records = rcs_runtime::read_trace_bytes(&bytes).expect("an MCAP recording");
    let mut names: Vec<&str> = records.iter().map(|r| r.controller.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names, ["PR", "SM", "TB"]);
    assert!(records
        .iter()
        .any(|r| r.controller == "SM" && r.verb == Some(1)));
    let _ = std::fs::remove_file(&trace);
}
