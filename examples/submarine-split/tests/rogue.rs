//! A rogue process against the split submarine. The helm and the engine run
//! as a user runs them; once the ship holds its ordered 15 kn, a rogue on
//! the same machine tries what an outsider on the plant network would:
//! forge a sensor buffer, command a controller it does not supervise,
//! subscribe to everything, flood a key, and take over a dead peer's port.
//!
//! With the generated policy and mutual TLS (`--certs`) every attempt is
//! refused — by the TLS handshake (no certificate), by the access-control
//! policy (a valid certificate of another identity), or by the bridge's own
//! checks (a second instance of a real identity) — and the ship keeps its
//! speed. With `--insecure` the same attacks work, which is what makes the
//! first test able to fail.
//!
//! Nothing asserts on timing: waits have generous deadlines, and what is
//! compared is what the processes report (speed, drive set-point, refusal
//! counts), not when.

#![cfg(feature = "zenoh")]

use std::net::TcpListener;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use rcs_runtime::bridge::zenoh::{self, Wait};
use rcs_runtime::{Bridge, BridgeConfig, CommandBuffer, GlobalMemory};

/// The generated plan set: the rogue uses its types, as a real attacker
/// with the plan set's source would.
#[allow(dead_code)]
mod plans {
    rcs_runtime::include_plans!("submarine_split");
}
use plans::submarine_split::{tb, types::Ship};

mod common;
use common::Proc;

const SYSTEM: &str = "submarine_split";

fn free_port() -> u16 {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    l.local_addr().expect("address").port()
}

fn certs(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rcs-rogue-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    rcs_runtime::acl::certs::make_dev_certs(&dir, &["helm", "engine", "operator"], &[])
        .expect("make development certificates");
    dir
}

/// How the rogue is dressed: which name it claims, and what it presents.
#[derive(Clone)]
enum Disguise {
    /// Plain TCP, no certificate.
    Naked,
    /// A valid certificate of identity `cert` (signed by the real CA).
    Cert { dir: PathBuf, cert: &'static str },
}

/// A rogue bridge claiming to be process `claims`, exporting a forged
/// `ship` (speed 500 kn) and a forged `TB.command` (AHEAD at 5,000 RPM),
/// rewritten every 10 ms for `secs` seconds once it has a peer (waiting up
/// to a minute for one when `need_peer`). Returns whether it had a peer.
fn forge(
    disguise: &Disguise,
    claims: &str,
    endpoint: (&str, &str),
    secs: u64,
    need_peer: bool,
) -> bool {
    let gm = GlobalMemory::new();
    gm.declare::<Ship>("ship").unwrap();
    gm.declare_controller::<tb::Command>(tb::NAME).unwrap();
    let mut ship = gm.writer::<Ship>("ship").unwrap();
    let mut tb_cmd = gm.command_writer::<tb::Command>(tb::NAME).unwrap();
    let mut config = BridgeConfig::new(SYSTEM, claims);
    config.resend_period = Duration::from_millis(20);
    config = dress(config, disguise);
    config = match endpoint {
        ("listen", e) => config.listen(e),
        (_, e) => config.connect(e),
    };
    let mut b = Bridge::builder(config, &gm);
    b.export::<Ship>("ship").unwrap();
    b.export::<CommandBuffer<tb::Command>>(&rcs_runtime::command_buffer_name(tb::NAME))
        .unwrap();
    let bridge = b.start().expect("the rogue's bridge starts");
    let deadline = Instant::now() + Duration::from_secs(if need_peer { 60 } else { 1 });
    while bridge.peers() == 0 && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
    let had_peer = bridge.peers() > 0;
    let start = Instant::now();
    let mut i = 0u32;
    while start.elapsed() < Duration::from_secs(secs) {
        i += 1;
        ship.write(
            Ship {
                speed: 500.0,
                ..Ship::default()
            },
            u64::from(i),
        );
        tb_cmd.write(
            CommandBuffer {
                serial: 1_000_000 + i,
                command: tb::Command::Ahead { rpm: 5000.0 },
                ..CommandBuffer::default()
            },
            u64::from(i),
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    drop(bridge);
    had_peer
}

/// `config` with the rogue's disguise on.
fn dress(config: BridgeConfig, disguise: &Disguise) -> BridgeConfig {
    match disguise {
        Disguise::Naked => config.insecure(),
        Disguise::Cert { dir, cert } => {
            let mut config = config.tls(rcs_runtime::TlsFiles::in_dir(dir, cert));
            // The rogue grants itself everything; what the victims allow
            // is theirs to decide.
            config.policy = Some(
                r#"{"access_control": {"enabled": false, "default_permission": "allow"}}"#.into(),
            );
            config
        }
    }
}

/// Two raw Zenoh sessions of the rogue's: one subscribes to `rcs/**`, the
/// other floods `TB.status` with junk for about a second. Returns how many
/// samples the subscription received (none of them its own: two sessions).
fn snoop_and_flood(disguise: &Disguise, endpoint: &str) -> u64 {
    let open = || {
        let config = dress(
            BridgeConfig::new(SYSTEM, "rogue").connect(endpoint),
            disguise,
        );
        zenoh::open(config.zenoh_config().expect("rogue config"))
            .wait()
            .expect("the rogue's session opens")
    };
    let (snoop, flood) = (open(), open());
    let received = Arc::new(AtomicU64::new(0));
    let count = Arc::clone(&received);
    let sub = snoop
        .declare_subscriber(format!("rcs/{SYSTEM}/**"))
        .callback(move |_| {
            count.fetch_add(1, Ordering::Relaxed);
        })
        .wait()
        .expect("declare the subscriber");
    let key = format!("rcs/{SYSTEM}/TB.status");
    let junk = vec![0xA5u8; 4096];
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(1) {
        let _ = flood.put(&key, junk.clone()).wait();
    }
    let _ = flood.close().wait();
    // Two seconds of the hierarchy's traffic for the subscription to see.
    std::thread::sleep(Duration::from_secs(2));
    drop(sub);
    let n = received.load(Ordering::Relaxed);
    let _ = snoop.close().wait();
    n
}

/// Start helm and engine with `security` (`--certs DIR` or `--insecure`)
/// and wait until the ship holds its speed.
fn hierarchy(security: &[&str], scheme: &str) -> (Proc, Proc, String) {
    let ep = format!("{scheme}/127.0.0.1:{}", free_port());
    let mut helm_args = vec!["helm", "--listen", &ep, "--report-every", "10"];
    helm_args.extend_from_slice(security);
    let mut engine_args = vec!["engine", "--connect", &ep, "--report-every", "10"];
    engine_args.extend_from_slice(security);
    let mut helm = Proc::spawn("helm", common::BIN, &helm_args);
    let engine = Proc::spawn("engine", common::BIN, &engine_args);
    helm.wait_for("the goal", |l| l.starts_with("goal "));
    (helm, engine, ep)
}

fn max(v: &[u64]) -> u64 {
    v.iter().copied().max().unwrap_or(0)
}

#[test]
fn rogue_attacks_are_refused_with_the_generated_policy() {
    let dir = certs("refused");
    let dir_s = dir.display().to_string();
    let (mut helm, mut engine, ep) = hierarchy(&["--certs", &dir_s], "tls");
    let plain = ep.replacen("tls/", "tcp/", 1);
    let operator = Disguise::Cert {
        dir: dir.clone(),
        cert: "operator",
    };

    // 1. No certificate: the TLS listener does not even open a session.
    assert!(!forge(
        &Disguise::Naked,
        "engine",
        ("connect", &plain),
        1,
        false
    ));
    assert_eq!(snoop_and_flood(&Disguise::Naked, &plain), 0);
    // 2. A valid certificate of another identity (the operator's): the
    // session opens, but the policy denies its puts of `ship`, its `rcs/**`
    // subscription and its flood of `TB.status`.
    let refused_before = helm.reports(1, "refused")[0];
    assert!(forge(&operator, "engine", ("connect", &ep), 2, true));
    assert_eq!(snoop_and_flood(&operator, &ep), 0, "rcs/** was served");
    // Dropped by Zenoh's access control, before the bridge decoded any.
    assert_eq!(helm.reports(3, "refused")[2], refused_before);
    // 3. The engine's own certificate in a second process: the policy lets
    // it put `ship`, the bridge refuses a second instance of the writer.
    let engine_cert = Disguise::Cert {
        dir: dir.clone(),
        cert: "engine",
    };
    assert!(forge(&engine_cert, "engine", ("connect", &ep), 2, true));
    // The ship kept its speed throughout, and the refusals were counted.
    let speeds = helm.reports(5, "speed");
    assert!(max(&speeds) < 30, "forged ship speed taken: {speeds:?}");
    assert!(
        helm.printed("ship (second_writer)"),
        "the second engine was not refused"
    );

    // 4. Squatting: the helm dies, the rogue with the operator's
    // certificate listens on its port; the engine reconnects to it (the
    // certificate is valid) and refuses its command to TB.
    drop(helm);
    assert!(
        forge(&operator, "helm", ("listen", &ep), 3, true),
        "the engine never reconnected"
    );
    let rpm = engine.reports(5, "rpm_setpoint");
    assert!(max(&rpm) < 1000, "the squatter commanded TB: {rpm:?}");
    engine.assert_running();
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn rogue_attacks_work_without_access_control() {
    // The same attacks against `--insecure` processes succeed: the test
    // above can fail.
    let (helm, mut engine, ep) = hierarchy(&["--insecure"], "tcp");
    assert!(
        snoop_and_flood(&Disguise::Naked, &ep) > 0,
        "rcs/** not served"
    );
    // Squatting the dead helm's port commands TB.
    drop(helm);
    assert!(forge(&Disguise::Naked, "helm", ("listen", &ep), 3, true));
    let rpm = engine.reports(3, "rpm_setpoint");
    assert!(
        max(&rpm) >= 1000,
        "the squatter's TB command was not obeyed: {rpm:?}"
    );
    engine.assert_running();
}
