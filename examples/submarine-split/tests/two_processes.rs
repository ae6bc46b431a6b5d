//! The split submarine as a user runs it: two processes on loopback. The
//! helm reaches AT_GOAL with the same statuses as the one-process run;
//! killing the engine makes PR's watchdog row fire (E2, after 31 silent
//! cycles) and SM fail with it; a new engine and a new order recover.
//! Every wait has a deadline; nothing asserts on timing.

#![cfg(feature = "zenoh")]

mod common;

use std::net::TcpListener;
use std::path::Path;

use common::{endpoint, one_process_goal, Proc};

fn free_endpoint() -> String {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    endpoint("127.0.0.1", l.local_addr().expect("address").port())
}

#[test]
fn split_reaches_the_goal_fails_on_a_dead_engine_and_recovers() {
    let ep = free_endpoint();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let mut helm = Proc::submarine("helm", &["--listen", &ep], dir);
    let engine = Proc::submarine("engine", &["--connect", &ep], dir);

    // 1. AT_GOAL across two processes, with the statuses of one process.
    let goal = helm.wait_for("goal line", |l| l.starts_with("goal "));
    assert_eq!(goal, one_process_goal());

    // 2. The engine dies: PR's watchdog row fires once TB's status has
    // been silent for more than 30 of PR's cycles, and SM fails with it.
    drop(engine);
    let stale = common::watchdog_fired(&mut helm);
    assert_eq!(
        stale,
        common::E2_FIRES_AT,
        "E2 fires on the first cycle with stale_cycles > 30"
    );
    helm.wait_for("SM in ERROR", |l| {
        l.contains("SM=TRANSIT/") && l.contains("/ERROR PR=")
    });

    // 3. A new engine and a new order: the hierarchy reaches the goal again.
    let _engine = Proc::submarine("engine", &["--connect", &ep], dir);
    // Order once the new engine is heard: an order while TB is still
    // silent fails at once on E2, as it should.
    helm.wait_for("the new engine", |l| {
        l.starts_with("helm: engine answered again")
    });
    helm.say("transit 15");
    helm.wait_for("the order", |l| l.starts_with("order "));
    let again = helm.wait_for("goal line after the restart", |l| l.starts_with("goal "));
    assert_eq!(again, goal);
}
