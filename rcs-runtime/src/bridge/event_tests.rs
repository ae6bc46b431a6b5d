//! The event-driven export, tested without timing: the bridges under test
//! have a fallback poll and a resend of an hour, so a value that arrives at
//! all came through the path under test (the cycle signal, a raise by hand,
//! or the one timer left short). Waits are bounded by generous deadlines.
//! Also: a buffer with arrays longer than serde's 32 crosses.

use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use super::tests::{free_endpoint, Ship};
use super::*;
use crate::exec::{Controller, CycleContext, Executive, ExecutiveConfig};
use crate::gm::Writer;
use crate::schema::combine;
use crate::serde_array::{Array, Leaf};

const HOUR: Duration = Duration::from_secs(3600);

/// Poll `f` until it returns `Some` or 60 s pass.
fn within<R>(what: &str, mut f: impl FnMut() -> Option<R>) -> R {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        if let Some(r) = f() {
            return r;
        }
        assert!(Instant::now() < deadline, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// `a` listens and exports with the given fallback poll and resend, `b`
/// connects.
fn pair(sys: &str, poll: Duration, resend: Duration) -> (BridgeConfig, BridgeConfig) {
    let ep = free_endpoint();
    let mut a = BridgeConfig::new(sys, "a").listen(&ep).insecure();
    a.poll_period = Some(poll);
    a.resend_period = resend;
    (a, BridgeConfig::new(sys, "b").connect(&ep).insecure())
}

/// What the scripted controller writes in its next cycles.
#[derive(Clone, Copy)]
enum Script {
    /// `ship` every cycle, counting cycles.
    Ship,
    /// `tick` once, with this value, then nothing.
    Tick(u64),
    Idle,
}

struct Scripted {
    ship: Writer<Ship>,
    tick: Writer<u64>,
    script: Script,
}

impl Controller for Scripted {
    fn name(&self) -> &str {
        "script"
    }
    fn cycle(&mut self, ctx: &CycleContext) {
        match self.script {
            Script::Ship => {
                let v = Ship {
                    speed: 1.0,
                    ahead: true,
                    count: ctx.cycle + 1,
                };
                self.ship.write(v, ctx.cycle);
            }
            Script::Tick(n) => {
                self.tick.write(n, ctx.cycle);
                self.script = Script::Idle;
            }
            Script::Idle => {}
        }
    }
}

fn set_script(exec: &mut Executive, script: Script) {
    exec.controller_as_mut::<Scripted>("script")
        .expect("the scripted controller")
        .script = script;
}

#[test]
fn a_cycles_writes_are_published_when_it_ends_and_only_what_changed() {
    let (ca, cb) = pair("signal", HOUR, HOUR);
    let (gm_a, gm_b) = (GlobalMemory::new(), GlobalMemory::new());
    for gm in [&gm_a, &gm_b] {
        gm.declare::<Ship>("ship").unwrap();
        gm.declare::<u64>("tick").unwrap();
        gm.declare::<u64>("idle").unwrap();
    }
    let mut ba = Bridge::builder(ca, &gm_a);
    ba.export::<Ship>("ship").unwrap();
    ba.export::<u64>("tick").unwrap();
    ba.export::<u64>("idle").unwrap();
    let a = ba.start().unwrap();
    // `tick` first: its subscription reaches A no later than `ship`'s.
    let mut bb = Bridge::builder(cb, &gm_b);
    bb.import::<u64>("tick", "a").unwrap();
    bb.import::<Ship>("ship", "a").unwrap();
    bb.import::<u64>("idle", "a").unwrap();
    let b = bb.start().unwrap();
    let mut exec = Executive::new(ExecutiveConfig::new("cpu", Duration::from_millis(5))).unwrap();
    exec.add(Box::new(Scripted {
        ship: gm_a.writer("ship").unwrap(),
        tick: gm_a.writer("tick").unwrap(),
        script: Script::Ship,
    }))
    .unwrap();
    exec.set_cycle_signal(a.signal());

    // 1. Cycles write `ship` until B has it: until the link is up, samples
    //    go nowhere, and no timer of A fires within the hour.
    let ship_b = gm_b.reader::<Ship>("ship").unwrap();
    let (mut ship_writes, deadline) = (0u64, Instant::now() + Duration::from_secs(60));
    while ship_b.generation() == 0 {
        assert!(Instant::now() < deadline, "`ship` never crossed");
        exec.step().expect("no controller panics");
        ship_writes += 1;
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(ship_b.read().value.count >= 1);

    // 2. Now that the link is up, each single write in a cycle arrives: a
    //    sample per signal. `ship` no longer changes and must not be sent
    //    again; if it were, each tick would add a sample of it.
    let ticks = ship_writes + 5;
    let tick_b = gm_b.reader::<u64>("tick").unwrap();
    for n in 1..=ticks {
        set_script(&mut exec, Script::Tick(n));
        exec.step().expect("no controller panics");
        within("the tick", || (tick_b.read().value == n).then_some(()));
    }
    let published = a.close().published;
    assert!(
        (ticks + 1..=ship_writes + ticks).contains(&published),
        "published {published}: ship written {ship_writes} times, {ticks} ticks"
    );
    assert_eq!(gm_b.reader::<u64>("idle").unwrap().generation(), 0);
    assert!(b.errors().is_empty());
}

#[test]
fn a_late_joiner_gets_the_latest_value_through_the_resend() {
    let (ca, cb) = pair("late", HOUR, Duration::from_millis(50));
    let (gm_a, gm_b) = (GlobalMemory::new(), GlobalMemory::new());
    gm_a.declare::<Ship>("ship").unwrap();
    gm_a.declare::<u64>("tick").unwrap();
    gm_b.declare::<Ship>("ship").unwrap();
    let mut ba = Bridge::builder(ca, &gm_a);
    ba.export::<Ship>("ship").unwrap();
    let a = ba.start().unwrap();
    let mut exec = Executive::new(ExecutiveConfig::new("cpu", Duration::from_millis(5))).unwrap();
    exec.add(Box::new(Scripted {
        ship: gm_a.writer("ship").unwrap(),
        tick: gm_a.writer("tick").unwrap(),
        script: Script::Ship,
    }))
    .unwrap();
    exec.set_cycle_signal(a.signal());
    exec.run_cycles(2).expect("no controller panics"); // published to nobody: B does not exist yet
    set_script(&mut exec, Script::Idle);
    exec.run_cycles(2).expect("no controller panics");
    let mut bb = Bridge::builder(cb, &gm_b);
    bb.import::<Ship>("ship", "a").unwrap();
    let _b = bb.start().unwrap();
    let r = gm_b.reader::<Ship>("ship").unwrap();
    let s = within("the resend", || (r.generation() > 0).then(|| r.read()));
    // The latest value with its writer's cycle stamp; the local generation
    // counts this process's imports (the first), never the writer's 2.
    assert_eq!((s.value.count, s.generation, s.writer_cycle), (2, 1, 1));
}

#[test]
fn a_write_outside_an_executive_leaves_on_a_raise() {
    let (ca, cb) = pair("raise", HOUR, HOUR);
    let (gm_a, gm_b) = (GlobalMemory::new(), GlobalMemory::new());
    gm_a.declare::<u64>("input").unwrap();
    gm_b.declare::<u64>("input").unwrap();
    let mut w = gm_a.writer::<u64>("input").unwrap();
    let mut ba = Bridge::builder(ca, &gm_a);
    ba.export::<u64>("input").unwrap();
    let a = ba.start().unwrap();
    let mut bb = Bridge::builder(cb, &gm_b);
    bb.import::<u64>("input", "a").unwrap();
    let _b = bb.start().unwrap();
    let (signal, r) = (a.signal(), gm_b.reader::<u64>("input").unwrap());
    let mut n = 0;
    within("the raised write", || {
        n += 1;
        w.write(n, n);
        signal.raise();
        std::thread::sleep(Duration::from_millis(5));
        (r.generation() > 0).then_some(())
    });
}

#[test]
fn a_write_nobody_signals_leaves_with_the_fallback_poll() {
    let (ca, cb) = pair("fallback", Duration::from_millis(20), HOUR);
    let (gm_a, gm_b) = (GlobalMemory::new(), GlobalMemory::new());
    gm_a.declare::<u64>("input").unwrap();
    gm_b.declare::<u64>("input").unwrap();
    let mut w = gm_a.writer::<u64>("input").unwrap();
    let mut ba = Bridge::builder(ca, &gm_a);
    ba.export::<u64>("input").unwrap();
    let _a = ba.start().unwrap();
    let mut bb = Bridge::builder(cb, &gm_b);
    bb.import::<u64>("input", "a").unwrap();
    let _b = bb.start().unwrap();
    let r = gm_b.reader::<u64>("input").unwrap();
    let mut n = 0;
    within("the polled write", || {
        n += 1;
        w.write(n, n);
        std::thread::sleep(Duration::from_millis(5));
        (r.generation() > 0).then_some(())
    });
}

/// Arrays past serde's 32, flat and nested, as rcsc generates them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct Scan {
    #[serde(with = "Array::<Leaf<f64>, 100>")]
    ranges: [f64; 100],
    #[serde(with = "Array::<Array<Leaf<u8>, 40>, 3>")]
    rows: [[u8; 40]; 3],
    label: u16,
}

impl Default for Scan {
    fn default() -> Self {
        Self {
            ranges: [0.0; 100],
            rows: [[0; 40]; 3],
            label: 0,
        }
    }
}

impl Schema for Scan {
    const SCHEMA: u64 = combine(
        "Scan{ranges:[f64;100],rows:[[u8;40];3],label:u16}",
        &[<[f64; 100]>::SCHEMA, <[[u8; 40]; 3]>::SCHEMA],
    );
}

#[test]
fn a_buffer_of_long_and_nested_arrays_crosses() {
    let (ca, cb) = pair("arrays", HOUR, Duration::from_millis(20));
    let (gm_a, gm_b) = (GlobalMemory::new(), GlobalMemory::new());
    gm_a.declare::<Scan>("scan").unwrap();
    gm_b.declare::<Scan>("scan").unwrap();
    let mut w = gm_a.writer::<Scan>("scan").unwrap();
    let mut ba = Bridge::builder(ca, &gm_a);
    ba.export::<Scan>("scan").unwrap();
    let a = ba.start().unwrap();
    let mut bb = Bridge::builder(cb, &gm_b);
    bb.import::<Scan>("scan", "a").unwrap();
    let b = bb.start().unwrap();
    let v = Scan {
        ranges: std::array::from_fn(|i| i as f64 * 0.25 - 3.0),
        rows: std::array::from_fn(|r| std::array::from_fn(|c| (r * 40 + c) as u8)),
        label: 513,
    };
    w.write(v, 9);
    a.signal().raise();
    let r = gm_b.reader::<Scan>("scan").unwrap();
    let s = within("the scan", || (r.generation() > 0).then(|| r.read()));
    assert_eq!(s.value, v);
    assert_eq!((s.generation, s.writer_cycle), (1, 9));
    assert!(b.errors().is_empty());
    // The same bytes through the wire functions alone.
    let mut out = Vec::new();
    wire::encode(&mut out, Scan::SCHEMA, "a", 1, &s).unwrap();
    assert!(out.len() <= wire::max_len::<Scan>());
    let (header, value) = wire::decode::<Scan>(&out, Scan::SCHEMA).unwrap();
    assert_eq!((header.generation, header.writer_cycle), (1, 9));
    assert_eq!(value, s.value);
}
