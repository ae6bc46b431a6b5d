//! Two bridges in one test process, joined over loopback TCP. Every wait is
//! bounded by a deadline; nothing asserts on timing.

use std::net::TcpListener;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use super::*;
use crate::schema::{combine, Schema};
use crate::SetupError;
use zenoh::Wait as _;

#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct Ship {
    pub(super) speed: f64,
    pub(super) ahead: bool,
    pub(super) count: u64,
}

impl Schema for Ship {
    const SCHEMA: u64 = combine("Ship{speed:f64,ahead:bool,count:u64}", &[]);
}

/// The same layout as `Ship` under another declaration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
struct Boat {
    speed: f64,
    ahead: bool,
    count: u64,
}

impl Schema for Boat {
    const SCHEMA: u64 = combine("Boat{speed:f64,ahead:bool,count:u64}", &[]);
}

/// A loopback endpoint on a port that was free a moment ago.
pub(crate) fn free_endpoint() -> String {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    let port = l.local_addr().expect("local address").port();
    format!("tcp/127.0.0.1:{port}")
}

/// Configurations of two processes of system `sys`: `a` listens, `b`
/// connects to it. Fast resends so that a test does not wait for a late
/// subscriber.
fn pair(sys: &str) -> (BridgeConfig, BridgeConfig) {
    let ep = free_endpoint();
    let mut a = BridgeConfig::new(sys, "a").listen(&ep).insecure();
    let mut b = BridgeConfig::new(sys, "b").connect(&ep).insecure();
    a.resend_period = Duration::from_millis(20);
    b.resend_period = Duration::from_millis(20);
    (a, b)
}

/// Poll `f` until it returns `Some` or 30 s pass.
fn within<R>(what: &str, mut f: impl FnMut() -> Option<R>) -> R {
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        if let Some(r) = f() {
            return r;
        }
        assert!(Instant::now() < deadline, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(2));
    }
}

#[test]
fn a_value_crosses_with_its_stamps() {
    let (ca, cb) = pair("cross");
    let (gm_a, gm_b) = (GlobalMemory::new(), GlobalMemory::new());
    gm_a.declare::<Ship>("ship").unwrap();
    gm_b.declare::<Ship>("ship").unwrap();
    let mut w = gm_a.writer::<Ship>("ship").unwrap();
    let mut ba = Bridge::builder(ca, &gm_a);
    ba.export::<Ship>("ship").unwrap();
    let _ba = ba.start().unwrap();
    let mut bb = Bridge::builder(cb, &gm_b);
    bb.import::<Ship>("ship", "a").unwrap();
    let bb = bb.start().unwrap();
    // The import holds the local writer: nothing else in B may write it.
    assert!(matches!(
        gm_b.writer::<Ship>("ship"),
        Err(SetupError::WriterTaken(_))
    ));
    let v = Ship {
        speed: 2.5,
        ahead: true,
        count: 3,
    };
    w.write(Ship::default(), 5);
    w.write(Ship::default(), 6);
    w.write(v, 7);
    let r = gm_b.reader::<Ship>("ship").unwrap();
    let s = within("the value in B", || {
        let s = r.read();
        (s.value == v).then_some(s)
    });
    // The local generation counts imports (one to three, as the exporter
    // polled); the writer's cycle stamp crosses as it was.
    assert!((1..=3).contains(&s.generation), "{s:?}");
    assert_eq!(s.writer_cycle, 7);
    assert!(bb.errors().is_empty());
    assert!(bb.stats().imported >= 1);
}

#[test]
fn a_sample_of_another_schema_is_refused() {
    let (ca, cb) = pair("schema");
    let (gm_a, gm_b) = (GlobalMemory::new(), GlobalMemory::new());
    gm_a.declare::<Ship>("ship").unwrap();
    gm_b.declare::<Boat>("ship").unwrap();
    let mut w = gm_a.writer::<Ship>("ship").unwrap();
    let mut ba = Bridge::builder(ca, &gm_a);
    ba.export::<Ship>("ship").unwrap();
    let _ba = ba.start().unwrap();
    let mut bb = Bridge::builder(cb, &gm_b);
    bb.import::<Boat>("ship", "a").unwrap();
    let bb = bb.start().unwrap();
    w.write(
        Ship {
            speed: 1.0,
            ahead: true,
            count: 1,
        },
        1,
    );
    let errors = within("a refusal", || {
        let e = bb.errors();
        (!e.is_empty()).then_some(e)
    });
    assert_eq!(
        errors,
        vec![BridgeError::SchemaMismatch {
            buffer: "ship".into(),
            expected: Boat::SCHEMA,
            got: Ship::SCHEMA,
        }]
    );
    assert!(errors[0].to_string().contains("refused"));
    // Nothing was written.
    let r = gm_b.reader::<Boat>("ship").unwrap();
    assert_eq!(r.read(), crate::Stamped::default());
    assert_eq!(bb.stats().imported, 0);
}

#[test]
fn a_burst_keeps_only_the_newest_in_order() {
    let (ca, cb) = pair("burst");
    let (gm_a, gm_b) = (GlobalMemory::new(), GlobalMemory::new());
    gm_a.declare::<Ship>("ship").unwrap();
    gm_b.declare::<Ship>("ship").unwrap();
    let mut w = gm_a.writer::<Ship>("ship").unwrap();
    let mut ba = Bridge::builder(ca, &gm_a);
    ba.export::<Ship>("ship").unwrap();
    let ba = ba.start().unwrap();
    let mut bb = Bridge::builder(cb, &gm_b);
    bb.import::<Ship>("ship", "a").unwrap();
    let bb = bb.start().unwrap();
    let r = gm_b.reader::<Ship>("ship").unwrap();
    // Wait until the link carries values, then write far faster than the
    // bridge publishes (no signal here: its fallback poll, 10 ms, and a
    // raise every 100 writes) and watch B: counts only grow, and each value
    // arrives with the stamps of the write that made it.
    w.write(Ship::default(), 0);
    within("the link", || (r.generation() > 0).then_some(()));
    const N: u64 = 20_000;
    let watcher = {
        let r = r.clone();
        std::thread::spawn(move || {
            let mut last = 0;
            let mut seen = 0u64;
            let deadline = Instant::now() + Duration::from_secs(30);
            while last < N && Instant::now() < deadline {
                let s = r.read();
                assert!(s.value.count >= last, "an older value after a newer one");
                if s.value.count != last {
                    seen += 1;
                }
                assert_eq!(s.writer_cycle, s.value.count);
                last = s.value.count;
                std::thread::yield_now();
            }
            (last, seen)
        })
    };
    for i in 1..=N {
        let v = Ship {
            speed: i as f64,
            ahead: i % 2 == 0,
            count: i,
        };
        w.write(v, i);
        if i % 100 == 0 {
            ba.signal().raise();
        }
    }
    let (last, seen) = watcher.join().expect("watcher");
    assert_eq!(last, N, "the last value written arrived");
    assert!(seen <= N);
    let s = r.read();
    assert_eq!(s.value.count, N);
    assert_eq!(s.value.speed, N as f64);
    assert!(bb.errors().is_empty());
}

// ---------------------------------------------------------------------------
// Hostile samples: a raw Zenoh session puts crafted bytes on an imported
// key. Each is refused, counted by kind, and leaves the cell as it was.

/// An importing bridge `b` of `Ship` (written by process `a`) and a raw
/// session connected to it.
fn victim(sys: &str) -> (GlobalMemory, Bridge, zenoh::Session, String) {
    let (ca, mut cb) = pair(sys);
    cb.resend_period = Duration::from_millis(20);
    let gm = GlobalMemory::new();
    gm.declare::<Ship>("ship").unwrap();
    gm.declare::<crate::StatusBuffer>("TB.status").unwrap();
    // The importer listens; the raw session (config of `a`) connects.
    let ep = ca.listen[0].clone();
    let mut cb_listen = BridgeConfig::new(sys, "b").listen(&ep).insecure();
    cb_listen.resend_period = cb.resend_period;
    let mut b = Bridge::builder(cb_listen, &gm);
    b.import::<Ship>("ship", "a").unwrap();
    b.import_checked::<crate::StatusBuffer>("TB.status", "a", |s: &crate::StatusBuffer| {
        s.check_range(1, 1, 2, 3)
    })
    .unwrap();
    let b = b.start().unwrap();
    let raw_config = BridgeConfig::new(sys, "a").connect(&ep).insecure();
    let session = zenoh::open(raw_config.zenoh_config().unwrap())
        .wait()
        .unwrap();
    within("the raw session's peer", || (b.peers() > 0).then_some(()));
    (gm, b, session, raw_config.key("ship"))
}

fn sample<T: Serialize>(writer: &str, instance: u64, generation: u64, value: T) -> Vec<u8> {
    let mut out = Vec::new();
    let s = crate::Stamped {
        value,
        generation,
        writer_cycle: generation,
    };
    wire::encode(&mut out, Ship::SCHEMA, writer, instance, &s).unwrap();
    out
}

fn ship(count: u64) -> Ship {
    Ship {
        speed: count as f64,
        ahead: true,
        count,
    }
}

/// Put `bytes` and wait until the bridge has received one more sample.
fn put(b: &Bridge, session: &zenoh::Session, key: &str, bytes: Vec<u8>) {
    let before = b.stats().received;
    session.put(key, bytes).wait().unwrap();
    within("the sample", || (b.stats().received > before).then_some(()));
}

fn refused(b: &Bridge, kind: &str) -> u64 {
    b.refusals()
        .iter()
        .filter(|r| r.kind == kind)
        .map(|r| r.count)
        .sum()
}

#[test]
fn malformed_oversized_and_trailing_samples_are_refused_and_counted() {
    let (gm, b, session, key) = victim("hostile_bytes");
    let r = gm.reader::<Ship>("ship").unwrap();
    let good = sample("a", 7, 1, ship(1));
    put(&b, &session, &key, vec![0xA5; 8 << 20]);
    assert_eq!(refused(&b, "oversized"), 1);
    let mut trailing = good.clone();
    trailing.extend_from_slice(b"junk");
    put(&b, &session, &key, trailing);
    assert_eq!(refused(&b, "trailing_bytes"), 1);
    put(&b, &session, &key, good[..good.len() - 3].to_vec());
    put(&b, &session, &key, vec![]);
    assert_eq!(refused(&b, "decode"), 2);
    assert_eq!(r.generation(), 0, "nothing was written");
    // A flood of junk is counted, sample by sample.
    let before = b.stats().refused;
    for _ in 0..500 {
        session.put(&key, vec![0xFFu8; 64]).wait().unwrap();
    }
    within("the flood counted", || {
        (b.stats().refused >= before + 500).then_some(())
    });
    assert_eq!(r.generation(), 0);
    // The good sample still goes through.
    put(&b, &session, &key, good);
    assert_eq!(r.read().value, ship(1));
    assert_eq!(b.stats().imported, 1);
}

#[test]
fn generations_from_the_wire_never_become_local_ones() {
    let (gm, b, session, key) = victim("hostile_generations");
    let r = gm.reader::<Ship>("ship").unwrap();
    // From the future, and zero: refused, the cell stays "never written".
    put(&b, &session, &key, sample("a", 7, u64::MAX, ship(9)));
    put(&b, &session, &key, sample("a", 7, (1 << 63) + 1, ship(9)));
    put(&b, &session, &key, sample("a", 7, 0, ship(9)));
    assert_eq!(refused(&b, "generation"), 3);
    assert_eq!(r.generation(), 0);
    // A large but possible generation is taken, as local generation 1.
    put(&b, &session, &key, sample("a", 7, 1_000_000, ship(1)));
    assert_eq!((r.read().value, r.generation()), (ship(1), 1));
    // A replay or reordering from the same writer: refused.
    put(&b, &session, &key, sample("a", 7, 999_999, ship(2)));
    assert_eq!(refused(&b, "generation"), 4);
    // An exact resend: dropped silently, not news to a watchdog.
    put(&b, &session, &key, sample("a", 7, 1_000_000, ship(1)));
    assert_eq!(r.generation(), 1);
    assert_eq!(b.stats().refused, 4);
    // The next write: local generation 2.
    put(&b, &session, &key, sample("a", 7, 1_000_001, ship(3)));
    assert_eq!((r.read().value, r.generation()), (ship(3), 2));
}

#[test]
fn wrong_writer_second_writer_and_out_of_range_are_refused() {
    let (gm, b, session, key) = victim("hostile_writers");
    let r = gm.reader::<Ship>("ship").unwrap();
    put(&b, &session, &key, sample("b", 7, 1, ship(1)));
    assert_eq!(refused(&b, "wrong_writer"), 1);
    assert!(b.errors()[0].to_string().contains("only `a` writes it"));
    put(&b, &session, &key, sample("a", 7, 1, ship(1)));
    assert_eq!(r.read().value, ship(1));
    // Another instance claiming `a` while instance 7 is alive.
    put(&b, &session, &key, sample("a", 8, 50, ship(66)));
    assert_eq!(refused(&b, "second_writer"), 1);
    assert_eq!(r.read().value, ship(1));
    // Instance 7 falls silent for longer than three resends (60 ms): a
    // restarted writer takes over, counting from 1 again.
    std::thread::sleep(Duration::from_millis(200));
    put(&b, &session, &key, sample("a", 8, 1, ship(2)));
    assert_eq!((r.read().value, r.generation()), (ship(2), 2));
    // A status its controller cannot have.
    let status_key = key.replace("ship", "TB.status");
    let status = |s: crate::StatusBuffer, g: u64| {
        let mut out = Vec::new();
        let stamped = crate::Stamped {
            value: s,
            generation: g,
            writer_cycle: g,
        };
        wire::encode(&mut out, crate::StatusBuffer::SCHEMA, "a", 7, &stamped).unwrap();
        put(&b, &session, &status_key, out);
    };
    let ok = crate::StatusBuffer {
        echo_serial: 1,
        status: crate::Status::DONE,
        ..Default::default()
    };
    status(
        crate::StatusBuffer {
            status: crate::Status(u16::MAX),
            ..ok
        },
        1,
    );
    status(crate::StatusBuffer { verb: 9, ..ok }, 2);
    assert_eq!(refused(&b, "out_of_range"), 2);
    let st = gm.reader::<crate::StatusBuffer>("TB.status").unwrap();
    assert_eq!(st.generation(), 0);
    status(ok, 3);
    assert_eq!(st.read().value, ok);
}

#[test]
fn a_bridge_without_chosen_security_refuses_to_start() {
    let gm = GlobalMemory::new();
    let e = Bridge::builder(BridgeConfig::new("s", "p"), &gm)
        .start()
        .unwrap_err();
    assert!(matches!(e, BridgeError::NoIdentity { .. }));
    assert!(e.to_string().contains("rcsc certs"));
    // TLS with a plain endpoint, or without a policy: refused too.
    let dir = std::env::temp_dir().join(format!("rcs-bridge-tls-{}", std::process::id()));
    #[cfg(feature = "certs")]
    crate::acl::certs::make_dev_certs(&dir, &["p"], &[]).unwrap();
    #[cfg(feature = "certs")]
    {
        let c = BridgeConfig::new("s", "p")
            .certs(&dir)
            .listen("tcp/127.0.0.1:1");
        let e = Bridge::builder(c, &gm).start().unwrap_err();
        assert!(e.to_string().contains("not encrypted"), "{e}");
        let c = BridgeConfig::new("s", "p")
            .certs(&dir)
            .listen("tls/127.0.0.1:1");
        let e = Bridge::builder(c, &gm).start().unwrap_err();
        assert!(e.to_string().contains("no access-control policy"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
    let c = BridgeConfig::new("s", "q")
        .certs(&dir)
        .listen("tls/127.0.0.1:1");
    let e = Bridge::builder(c, &gm).start().unwrap_err();
    assert!(e.to_string().contains("cannot read"), "{e}");
}

#[test]
fn a_restarted_writer_process_is_heard_again() {
    // A listens and imports; B exports, dies, and a new B (a new bridge
    // instance, counting from 1 again) takes over once the old one has been
    // silent for three resends.
    let (ca, cb) = pair("restart");
    let gm_a = GlobalMemory::new();
    gm_a.declare::<Ship>("ship").unwrap();
    let mut ba = Bridge::builder(ca, &gm_a);
    ba.import::<Ship>("ship", "b").unwrap();
    let ba = ba.start().unwrap();
    let r = gm_a.reader::<Ship>("ship").unwrap();
    for life in 1..=2u64 {
        let gm_b = GlobalMemory::new();
        gm_b.declare::<Ship>("ship").unwrap();
        let mut w = gm_b.writer::<Ship>("ship").unwrap();
        let mut bb = Bridge::builder(cb.clone(), &gm_b);
        bb.export::<Ship>("ship").unwrap();
        let bb = bb.start().unwrap();
        let mut i = 0;
        within("the value of this life", || {
            i += 1;
            w.write(ship(life * 1000 + i), i);
            std::thread::sleep(Duration::from_millis(5));
            (r.read().value.count > life * 1000).then_some(())
        });
        drop(bb);
    }
    assert!(ba.errors().iter().all(|e| e.kind() == "second_writer"));
}
