//! The operator in a process of its own: `Operators::remote` commands SM,
//! which runs in the helm, through the access control (the `operator`
//! certificate), and sees SM's status come back. A process certificate
//! (the engine's) cannot command the root the same way. SM refuses an order
//! beyond the hull's top speed (`accept when`): across the processes the
//! operator sees ERROR / REFUSED for that order until it sends another,
//! while SM's transit under way goes on and is not taken as the answer.
//!
//! Every wait has a generous deadline; nothing asserts on timing.

#![cfg(feature = "zenoh")]

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use rcs_runtime::{BridgeConfig, ErrorCode, Status, TlsFiles};

mod common;
use common::{endpoint, security_args, Proc};

#[allow(dead_code)]
mod plans {
    rcs_runtime::include_plans!("submarine_split");
}
use plans::submarine_split::{sm, Operators};

fn free_port() -> u16 {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    l.local_addr().expect("address").port()
}

/// Helm and engine over TLS; returns them, the helm's endpoint and the
/// certificates' folder, once the ship holds its first order (15 kn).
fn hierarchy() -> (Proc, Proc, String, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let certs = PathBuf::from(&security_args(dir)[1]);
    let ep = endpoint("127.0.0.1", free_port());
    let mut helm = Proc::submarine("helm", &["--listen", &ep, "--report-every", "10"], dir);
    let engine = Proc::submarine("engine", &["--connect", &ep], dir);
    helm.wait_for("the goal", |l| l.starts_with("goal "));
    (helm, engine, ep, certs)
}

fn until<R>(what: &str, mut f: impl FnMut() -> Option<R>) -> R {
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        if let Some(r) = f() {
            return r;
        }
        assert!(Instant::now() < deadline, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The operator's own process: its bridge, with the `operator`
/// certificate, connected to the helm at `ep` and hearing it.
fn operator(ep: &str, certs: &Path) -> (Operators, rcs_runtime::Bridge) {
    let config = BridgeConfig::new("submarine_split", "operator")
        .certs(certs)
        .connect(ep);
    let (ops, bridge) = Operators::remote(config).expect("the operator's bridge");
    until("the helm as a peer", || (bridge.peers() > 0).then_some(()));
    (ops, bridge)
}

#[test]
fn operator_commands_a_root_in_another_process() {
    let (mut helm, _engine, ep, certs) = hierarchy();
    let (mut ops, bridge) = operator(&ep, &certs);
    let serial = ops.sm.command(sm::Command::Transit { speed: 8.0 });
    // SM takes the command (its status echoes it back to this process)...
    until("SM's echo of the operator's command", || {
        (ops.sm.status().value.echo_serial == serial).then_some(())
    });
    assert!(!ops.sm.view().error(), "{:?}", ops.sm.status());
    // ...and the ship slows from 15 to 8 kn.
    until("the ship at 8 kn", || {
        let speed = helm.reports(1, "speed")[0];
        (speed == 7 || speed == 8).then_some(())
    });
    assert!(bridge.errors().is_empty(), "{:?}", bridge.errors());
}

#[test]
fn a_root_in_another_process_refuses_an_order_and_its_transit_goes_on() {
    let (mut helm, _engine, ep, certs) = hierarchy();
    let (mut ops, bridge) = operator(&ep, &certs);
    let slow = ops.sm.command(sm::Command::Transit { speed: 8.0 });
    until("SM's echo of the 8 kn order", || {
        (ops.sm.status().value.echo_serial == slow).then_some(())
    });
    // 40 kn is beyond MAX_KNOTS: refused in the helm, seen here.
    let fast = ops.sm.command(sm::Command::Transit { speed: 40.0 });
    until("the refusal", || {
        let v = ops.sm.view();
        (v.error == ErrorCode::REFUSED).then_some(())
    });
    let refused = |ops: &mut Operators| {
        let v = ops.sm.view();
        let raw = ops.sm.status().value;
        assert_eq!(
            (v.status, v.error),
            (Status::ERROR, ErrorCode::REFUSED),
            "the refusal shows until the operator sends again: {raw:?}"
        );
        assert_eq!((raw.refused_serial, raw.echo_serial), (fast, slow));
        raw
    };
    // The 8 kn transit goes on: the ship slows to 8 kn and SM's plan for
    // it reaches S2 (PR at its goal), all of it reported for the older
    // order, none of it taken as the answer to the refused one.
    until("the ship at 8 kn under the refusal", || {
        refused(&mut ops);
        let speed = helm.reports(1, "speed")[0];
        (speed == 7 || speed == 8).then_some(())
    });
    until("SM's 8 kn transit at its goal (S2)", || {
        let raw = refused(&mut ops);
        (sm::state_name(raw.verb, raw.state) == Some("S2")).then_some(())
    });
    // Sending again ends the refusal.
    let again = ops.sm.command(sm::Command::Transit { speed: 10.0 });
    until("SM's echo of the 10 kn order", || {
        (ops.sm.status().value.echo_serial == again).then_some(())
    });
    assert_ne!(ops.sm.view().error, ErrorCode::REFUSED);
    assert!(bridge.errors().is_empty(), "{:?}", bridge.errors());
}

#[test]
fn rogue_with_a_process_certificate_cannot_command_a_root() {
    let (mut helm, _engine, ep, certs) = hierarchy();
    // The engine's certificate, dressed as the operator's program.
    let config = BridgeConfig::new("submarine_split", "operator")
        .tls(TlsFiles {
            cert: certs.join("engine.pem"),
            key: certs.join("engine.key"),
            ca: certs.join("ca.pem"),
        })
        .connect(&ep);
    let (mut ops, bridge) = Operators::remote(config).expect("the rogue's bridge");
    until("the helm as a peer", || (bridge.peers() > 0).then_some(()));
    let serial = ops.sm.command(sm::Command::Transit { speed: 8.0 });
    // Thirty reports (300 helm cycles) later, the ship still holds 15 kn
    // and SM never echoed the rogue's command.
    let speeds = helm.reports(30, "speed");
    assert!(speeds.iter().all(|s| (14..=15).contains(s)), "{speeds:?}");
    assert_ne!(ops.sm.status().value.echo_serial, serial);
}
