//! A `reads` buffer's watchdog across processes (LANGUAGE.md §8): PR, in
//! the helm process, reads `ship`, which the ship simulator writes in the
//! engine process; the bridge carries each write with its generation, so
//! `ship.stale_cycles` (PR's status field `ship_age`, printed as
//! `ship_stale=` on the helm's report lines) is 0 on the cycles whose read
//! sees a new write, and grows once the writer's process is gone. Every
//! wait has a deadline; nothing asserts on timing (both CPUs run at 30 ms,
//! unsynchronised, so a helm cycle may now and then see no new write: the
//! test asks for fresh reads, not for every read to be fresh).

#![cfg(feature = "zenoh")]

mod common;

use std::net::TcpListener;
use std::path::Path;

use common::{endpoint, Proc};

fn free_endpoint() -> String {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    endpoint("127.0.0.1", l.local_addr().expect("address").port())
}

#[test]
fn a_remote_buffer_is_fresh_while_written_and_goes_stale_when_its_writer_stops() {
    let ep = free_endpoint();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let mut helm = Proc::submarine("helm", &["--listen", &ep, "--report-every", "5"], dir);
    let engine = Proc::submarine("engine", &["--connect", &ep], dir);
    helm.wait_for("the engine", |l| l.starts_with("helm: engine answered"));

    // 1. Written every engine cycle: the reads see new generations.
    let written = helm.reports(20, "ship_stale");
    assert!(
        written.iter().filter(|s| **s == 0).count() >= 10,
        "while the engine writes `ship`, most reads are fresh: {written:?}"
    );
    assert!(
        written.iter().all(|s| *s <= 30),
        "no read is older than PR's bound while the engine runs: {written:?}"
    );

    // 2. The writer's process stops: `ship.stale_cycles` grows, cycle by
    // cycle, on the helm (which keeps the last value it imported).
    drop(engine);
    let deadline_reports = 400;
    let mut stale = Vec::new();
    for _ in 0..deadline_reports {
        let s = helm.reports(1, "ship_stale")[0];
        stale.push(s);
        if stale.len() >= 3 && stale.iter().rev().take(3).all(|s| *s > 40) {
            break;
        }
    }
    let last: Vec<u64> = stale.iter().rev().take(3).rev().copied().collect();
    assert!(
        last.len() == 3 && last.iter().all(|s| *s > 40),
        "after the engine stopped, `ship` went stale: {stale:?}"
    );
    assert!(
        last.windows(2).all(|w| w[1] == w[0] + 5),
        "one more per helm cycle (reports every 5 cycles): {last:?}"
    );
}
