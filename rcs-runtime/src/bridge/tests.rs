//! Two bridges in one test process, joined over loopback TCP. Every wait is
//! bounded by a deadline; nothing asserts on timing.

use std::net::TcpListener;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use super::*;
use crate::schema::{combine, Schema};
use crate::SetupError;

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
    let mut a = BridgeConfig::new(sys, "a").listen(&ep);
    let mut b = BridgeConfig::new(sys, "b").connect(&ep);
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
    bb.import::<Ship>("ship").unwrap();
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
    assert_eq!((s.generation, s.writer_cycle), (3, 7));
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
    bb.import::<Boat>("ship").unwrap();
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
    bb.import::<Ship>("ship").unwrap();
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
