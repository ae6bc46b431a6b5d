//! Measurements of Global Memory over Zenoh for BENCHMARKS.md (feature
//! `zenoh`). Spawns itself as the second process; loopback TCP only.
//!
//! ```text
//! cargo run --release -p rcs-runtime --features zenoh --example bridge_bench -- latency
//! cargo run --release -p rcs-runtime --features zenoh --example bridge_bench -- load 64
//! cargo run --release -p rcs-runtime --features zenoh --example bridge_bench -- load 4096
//! cargo run --release -p rcs-runtime --features zenoh --example bridge_bench -- heartbeat
//! ```
//!
//! * `latency`: one buffer written every 2 ms in a child process, read by a
//!   thread spinning on the local cell here: write → read latency p50, p99
//!   and max over 2,000 writes, against the same two threads in one process
//!   sharing one Global Memory. The value carries the wall clock
//!   (`SystemTime`, one clock for every process on a host).
//! * `load SIZE`: 100 buffers of SIZE bytes (64 or 4096), each written at
//!   1 kHz for 5 s here and imported by a child process: CPU time of this
//!   process's bridge thread and of the whole process, from `/proc`.
//! * `heartbeat`: a 1 ms heartbeat for 5 s writing 100 buffers of 64 B per
//!   cycle, with and then without a bridge exporting them to a child
//!   process: p99 and max lateness of the heartbeat.

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use rcs_runtime::schema::{combine, Schema};
use rcs_runtime::serde::{Deserialize, Serialize};
use rcs_runtime::{Bridge, BridgeConfig, GlobalMemory, Heartbeat, Reader, Wait, Writer};

/// 64 bytes.
#[derive(Clone, Copy, Default, Serialize, Deserialize)]
#[serde(crate = "rcs_runtime::serde")]
struct Small([u64; 8]);
impl Schema for Small {
    const SCHEMA: u64 = combine("Small[u64;8]", &[]);
}

/// 4 KiB (serde derives arrays up to 32 long, so 16 × 32 words).
#[derive(Clone, Copy, Default, Serialize, Deserialize)]
#[serde(crate = "rcs_runtime::serde")]
struct Large([[u64; 32]; 16]);
impl Schema for Large {
    const SCHEMA: u64 = combine("Large[[u64;32];16]", &[]);
}

fn wall_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

fn free_endpoint() -> String {
    let l = std::net::TcpListener::bind("127.0.0.1:0").expect("free port");
    format!("tcp/127.0.0.1:{}", l.local_addr().expect("addr").port())
}

fn child(args: &[&str]) -> Child {
    Command::new(std::env::current_exe().expect("own path"))
        .args(args)
        .stdout(Stdio::inherit())
        .spawn()
        .expect("spawn the second process")
}

fn percentiles(mut v: Vec<u64>) -> String {
    v.sort_unstable();
    let at = |q: f64| v[((v.len() - 1) as f64 * q) as usize] as f64 / 1e3;
    format!(
        "n={} p50={:.1} µs p99={:.1} µs max={:.1} µs",
        v.len(),
        at(0.5),
        at(0.99),
        at(1.0)
    )
}

/// The writer side of `latency`: `n` writes of the wall clock, one every
/// 2 ms, after a second for the link to come up.
fn latency_writer(mut w: Writer<u64>, n: u64) {
    std::thread::sleep(Duration::from_secs(1));
    for i in 1..=n {
        w.write(wall_ns(), i);
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// The reader side: spin on the cell, one latency per new generation.
fn latency_reader(r: &Reader<u64>, n: u64) -> Vec<u64> {
    let mut out = Vec::with_capacity(n as usize);
    let mut last = 0;
    let deadline = Instant::now() + Duration::from_secs(60);
    while out.len() < n as usize && Instant::now() < deadline {
        let g = r.generation();
        if g != last {
            last = g;
            let s = r.read();
            out.push(wall_ns().saturating_sub(s.value));
        } else {
            std::hint::spin_loop();
        }
    }
    out
}

fn thread_cpu_ticks(name: &str) -> u64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    tasks
        .flatten()
        .filter_map(|t| {
            let comm = std::fs::read_to_string(t.path().join("comm")).ok()?;
            if comm.trim() != name {
                return None;
            }
            ticks(&std::fs::read_to_string(t.path().join("stat")).ok()?)
        })
        .sum()
}

fn process_cpu_ticks() -> u64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| ticks(&s))
        .unwrap_or(0)
}

/// utime + stime of a `/proc/.../stat` line (fields 14 and 15).
fn ticks(stat: &str) -> Option<u64> {
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split(' ').collect();
    Some(f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?)
}

const TICKS_PER_S: f64 = 100.0;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    match a.as_slice() {
        ["latency"] => latency(),
        ["latency-child", ep] => {
            let gm = GlobalMemory::new();
            gm.declare::<u64>("lat").unwrap();
            let w = gm.writer::<u64>("lat").unwrap();
            let mut config = BridgeConfig::new("bench", "w").connect(ep);
            let poll_us = std::env::var("RCS_BENCH_POLL_US")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(1_000);
            config.poll_period = Some(Duration::from_micros(poll_us));
            let mut b = Bridge::builder(config, &gm);
            b.export::<u64>("lat").unwrap();
            let _b = b.start().unwrap();
            latency_writer(w, 2_000);
            std::thread::sleep(Duration::from_millis(500));
        }
        ["load", size] => load(size.parse().expect("64 or 4096")),
        ["load-child", ep, size] => sink(ep, size.parse().expect("size")),
        ["heartbeat"] => heartbeat(),
        ["sink", ep] => sink(ep, 64),
        _ => eprintln!("usage: bridge_bench latency | load 64|4096 | heartbeat"),
    }
}

fn latency() {
    // In one process: two threads, one Global Memory.
    let gm = GlobalMemory::new();
    gm.declare::<u64>("lat").unwrap();
    let w = gm.writer::<u64>("lat").unwrap();
    let r = gm.reader::<u64>("lat").unwrap();
    let t = std::thread::spawn(move || latency_writer(w, 2_000));
    let local = latency_reader(&r, 2_000);
    t.join().unwrap();
    println!("in-process      {}", percentiles(local));

    for poll_us in [1_000u64, 100] {
        let ep = free_endpoint();
        let gm = GlobalMemory::new();
        gm.declare::<u64>("lat").unwrap();
        let mut b = Bridge::builder(BridgeConfig::new("bench", "r").listen(&ep), &gm);
        b.import::<u64>("lat").unwrap();
        let _b = b.start().unwrap();
        let r = gm.reader::<u64>("lat").unwrap();
        // The writer's poll period is its own: pass it through the env.
        let mut c = Command::new(std::env::current_exe().unwrap())
            .args(["latency-child", &ep])
            .env("RCS_BENCH_POLL_US", poll_us.to_string())
            .spawn()
            .unwrap();
        let v = latency_reader(&r, 2_000);
        let _ = c.wait();
        println!(
            "two processes (bridge poll {poll_us} µs) {}",
            percentiles(v)
        );
    }
}

/// A process importing 100 buffers of `size` bytes for 30 s (or until
/// killed).
fn sink(ep: &str, size: usize) {
    let gm = GlobalMemory::new();
    let mut b = Bridge::builder(BridgeConfig::new("bench", "sink").connect(ep), &gm);
    for i in 0..100 {
        let name = format!("b{i}");
        if size == 4096 {
            gm.declare::<Large>(&name).unwrap();
            b.import::<Large>(&name).unwrap();
        } else {
            gm.declare::<Small>(&name).unwrap();
            b.import::<Small>(&name).unwrap();
        }
    }
    let b = b.start().unwrap();
    std::thread::sleep(Duration::from_secs(30));
    println!("sink: imported {}", b.stats().imported);
}

/// Declare and export 100 buffers of `T`, return their writers and the bridge.
fn exporting<T>(gm: &GlobalMemory, ep: &str, bridge: bool) -> (Vec<Writer<T>>, Option<Bridge>)
where
    T: rcs_runtime::BufferData + Schema + Serialize + Sync,
{
    let mut config = BridgeConfig::new("bench", "pub").listen(ep);
    config.poll_period = Some(Duration::from_millis(1));
    let mut b = Bridge::builder(config, gm);
    let mut writers = Vec::new();
    for i in 0..100 {
        let name = format!("b{i}");
        gm.declare::<T>(&name).unwrap();
        writers.push(gm.writer::<T>(&name).unwrap());
        b.export::<T>(&name).unwrap();
    }
    (
        writers,
        if bridge {
            Some(b.start().unwrap())
        } else {
            None
        },
    )
}

fn run_load<T: rcs_runtime::BufferData + Schema + Serialize + Sync>(size: usize) {
    let ep = free_endpoint();
    let gm = GlobalMemory::new();
    let (mut writers, bridge) = exporting::<T>(&gm, &ep, true);
    let mut sink = child(&["load-child", &ep, &size.to_string()]);
    std::thread::sleep(Duration::from_secs(2));
    let (t0, p0) = (thread_cpu_ticks("rcs-bridge-pub"), process_cpu_ticks());
    let start = Instant::now();
    let mut hb = Heartbeat::new(Duration::from_millis(1), Wait::Sleep).expect("a 1 ms heartbeat");
    let mut cycle = 0;
    while start.elapsed() < Duration::from_secs(5) {
        hb.wait();
        cycle += 1;
        for w in &mut writers {
            w.write(T::default(), cycle);
        }
    }
    let secs = start.elapsed().as_secs_f64();
    let (t1, p1) = (thread_cpu_ticks("rcs-bridge-pub"), process_cpu_ticks());
    let published = bridge.as_ref().map_or(0, |b| b.stats().published);
    println!(
        "100 × {size} B at 1 kHz for {secs:.1} s ({cycle} cycles): bridge thread {:.1} % of a core, whole process {:.1} %, {published} samples published",
        (t1 - t0) as f64 / TICKS_PER_S / secs * 100.0,
        (p1 - p0) as f64 / TICKS_PER_S / secs * 100.0,
    );
    let _ = sink.kill();
    let _ = sink.wait();
}

fn load(size: usize) {
    if size == 4096 {
        run_load::<Large>(4096);
    } else {
        run_load::<Small>(64);
    }
}

fn heartbeat() {
    for with_bridge in [true, false] {
        let ep = free_endpoint();
        let gm = GlobalMemory::new();
        let (mut writers, _bridge) = exporting::<Small>(&gm, &ep, with_bridge);
        let mut sink = with_bridge.then(|| child(&["sink", &ep]));
        std::thread::sleep(Duration::from_secs(2));
        let mut hb =
            Heartbeat::new(Duration::from_millis(1), Wait::default()).expect("a 1 ms heartbeat");
        let mut late = Vec::with_capacity(5_000);
        for cycle in 0..5_000u64 {
            late.push(hb.wait().as_nanos() as u64);
            for w in &mut writers {
                w.write(Small([cycle; 8]), cycle);
            }
        }
        println!(
            "heartbeat 1 ms, 100 × 64 B written per cycle, bridge {}: lateness {}",
            if with_bridge { "on " } else { "off" },
            percentiles(late)
        );
        if let Some(s) = sink.as_mut() {
            let _ = s.kill();
            let _ = s.wait();
        }
    }
}
