//! Measurements of Global Memory over Zenoh for BENCHMARKS.md (feature
//! `zenoh`). Spawns itself as the second process; loopback TCP only.
//!
//! ```text
//! cargo build --release -p rcs-runtime --features zenoh --example bridge_bench
//! B=target/release/examples/bridge_bench
//! $B latency; $B load 64; $B load 4096; $B heartbeat
//! $B --config NAME latency      # another pair of configurations, see `bench_configs`
//! ```
//!
//! * `latency`: write → read across two processes, the bridge against plain
//!   Zenoh in the same run. The child process alternates, every 2 ms, (b) an
//!   executive cycle whose controller writes the wall clock into an
//!   exported buffer (the executive raises the bridge's cycle signal, as in
//!   a generated `System::process`), and (a) a plain Zenoh `put` of a
//!   payload of the same size holding the wall clock, from a session of its
//!   own. Here, a thread spinning on the imported cell timestamps (b), and a
//!   subscriber callback on another plain session timestamps (a). p50, p99
//!   and max over 2,000 of each, and the bridge/Zenoh ratios. The clock is
//!   `SystemTime`, one clock for every process on a host. First, for
//!   reference, the same two threads in one process sharing one Global
//!   Memory.
//! * `load SIZE`: 100 buffers of SIZE bytes (64 or 4096), written by an
//!   executive at 1 kHz for 5 s here (signal attached) and imported by a
//!   child process: CPU time of this process's bridge thread and of the
//!   whole process, from `/proc`.
//! * `heartbeat`: a 1 ms heartbeat for 5 s writing 100 buffers of 64 B per
//!   cycle, with and then without a bridge exporting them to a child
//!   process: p99 and max lateness of the heartbeat.
//!
//! `--config NAME` (before the mode; passed on to the child) picks the pair
//! of bridge configurations [`bench_configs`] builds; the plain Zenoh
//! sessions of `latency` are opened with the same configurations' Zenoh
//! settings ([`BridgeConfig::zenoh_config`]), so both paths pay for the
//! same transport.

use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use rcs_runtime::schema::{combine, Schema};
use rcs_runtime::serde::{Deserialize, Serialize};
use rcs_runtime::{
    Bridge, BridgeConfig, Controller, CycleContext, Executive, ExecutiveConfig, GlobalMemory,
    Heartbeat, Reader, Wait, Writer,
};
use zenoh::qos::CongestionControl;
use zenoh::Wait as _;

/// The configurations of the two processes of a measurement, by `variant`
/// (`--config`, default `plain`): `(listening, connecting)`, joined at the
/// loopback endpoint `ep`. In `latency` the listening one reads and the
/// connecting one writes; in `load` and `heartbeat` the reverse. Add a
/// variant here (TLS, access control, …) to measure it.
fn bench_configs(variant: &str, ep: &str) -> Result<(BridgeConfig, BridgeConfig), String> {
    let plain = |scheme: &str| {
        let ep = ep.replacen("tcp/", scheme, 1);
        (
            BridgeConfig::new("bench", "listen").listen(&ep),
            BridgeConfig::new("bench", "connect").connect(&ep),
        )
    };
    match variant {
        "plain" => {
            let (l, c) = plain("tcp/");
            Ok((l.insecure(), c.insecure()))
        }
        // Mutual TLS, and access control on with default deny: each side
        // may put, and subscribe to, the bench's keys only, from the other.
        #[cfg(feature = "certs")]
        "tls" => {
            let dir = bench_certs()?;
            let (mut l, mut c) = plain("tls/");
            l.policy = Some(bench_policy("connect"));
            c.policy = Some(bench_policy("listen"));
            Ok((l.certs(&dir), c.certs(&dir)))
        }
        other => Err(format!(
            "no bridge configuration `{other}` (known: plain{})",
            if cfg!(feature = "certs") { ", tls" } else { "" }
        )),
    }
}

/// A development CA and the two sides' certificates, made once in a
/// folder the parent and its child share.
#[cfg(feature = "certs")]
fn bench_certs() -> Result<std::path::PathBuf, String> {
    let dir = std::env::temp_dir().join("rcs-bridge-bench-certs");
    if !dir.join("connect.key").exists() {
        rcs_runtime::acl::certs::make_dev_certs(&dir, &["listen", "connect"], &[])
            .map_err(|e| e.to_string())?;
    }
    Ok(dir)
}

/// The access-control policy of one side: the peer `peer` may put and
/// subscribe to `rcs/bench/**`, both ways; anything else is denied.
#[cfg(feature = "certs")]
fn bench_policy(peer: &str) -> String {
    let rule = |id: &str, flow: &str, message: &str| {
        format!(
            r#"{{"id":"{id}","flows":["{flow}"],"messages":["{message}"],"permission":"allow","key_exprs":["rcs/bench/**"]}}"#
        )
    };
    format!(
        r#"{{"access_control":{{"enabled":true,"default_permission":"deny","rules":[{},{},{},{}],"subjects":[{{"id":"{peer}","cert_common_names":["{peer}"]}}],"policies":[{{"subjects":["{peer}"],"rules":["pi","pe","si","se"]}}]}}}}"#,
        rule("pi", "ingress", "put"),
        rule("pe", "egress", "put"),
        rule("si", "ingress", "declare_subscriber"),
        rule("se", "egress", "declare_subscriber"),
    )
}

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

/// This program again with `--config variant` and `args`.
fn child(variant: &str, args: &[&str]) -> Child {
    Command::new(std::env::current_exe().expect("own path"))
        .args(["--config", variant])
        .args(args)
        .stdout(Stdio::inherit())
        .spawn()
        .expect("spawn the second process")
}

/// Sorted samples in nanoseconds.
struct Figures(Vec<u64>);

impl Figures {
    fn new(mut v: Vec<u64>) -> Self {
        v.sort_unstable();
        Self(v)
    }
    fn at(&self, q: f64) -> f64 {
        self.0
            .get(((self.0.len().max(1) - 1) as f64 * q) as usize)
            .copied()
            .unwrap_or(0) as f64
    }
    fn line(&self) -> String {
        format!(
            "n={} p50={:.1} µs p99={:.1} µs max={:.1} µs",
            self.0.len(),
            self.at(0.5) / 1e3,
            self.at(0.99) / 1e3,
            self.at(1.0) / 1e3
        )
    }
}

/// An executive's controller writing the wall clock into one buffer.
struct Clock(Writer<u64>);

impl Controller for Clock {
    fn name(&self) -> &str {
        "clock"
    }
    fn cycle(&mut self, ctx: &CycleContext) {
        self.0.write(wall_ns(), ctx.cycle);
    }
}

/// The bridge's sample of a `u64` wall clock is postcard of (schema hash,
/// generation, cycle, value): 10 + 2 + 2 + 9 bytes here. The plain Zenoh
/// payload is as long.
const RAW_PAYLOAD: usize = 23;

/// The reader side of the bridge path: spin on the cell, one latency per
/// new generation, until `n` or a minute.
fn spin_reader(r: &Reader<u64>, n: usize) -> Vec<u64> {
    let mut out = Vec::with_capacity(n);
    let mut last = 0;
    let deadline = Instant::now() + Duration::from_secs(60);
    while out.len() < n && Instant::now() < deadline {
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

const LATENCY_WRITES: usize = 2_000;

fn latency(variant: &str) -> Result<(), String> {
    // In one process: a writer thread, a spinning reader, one Global Memory.
    let gm = GlobalMemory::new();
    gm.declare::<u64>("lat").map_err(|e| e.to_string())?;
    let mut w = gm.writer::<u64>("lat").map_err(|e| e.to_string())?;
    let r = gm.reader::<u64>("lat").map_err(|e| e.to_string())?;
    let t = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(200));
        for i in 1..=LATENCY_WRITES as u64 {
            w.write(wall_ns(), i);
            std::thread::sleep(Duration::from_millis(2));
        }
    });
    let local = Figures::new(spin_reader(&r, LATENCY_WRITES));
    let _ = t.join();
    println!("in one process        {}", local.line());

    // Two processes: the bridge and plain Zenoh, alternately.
    let (ep_bridge, ep_raw) = (free_endpoint(), free_endpoint());
    let (bridge_config, _) = bench_configs(variant, &ep_bridge)?;
    let (raw_config, _) = bench_configs(variant, &ep_raw)?;
    let gm = GlobalMemory::new();
    gm.declare::<u64>("lat").map_err(|e| e.to_string())?;
    let mut b = Bridge::builder(bridge_config, &gm);
    b.import::<u64>("lat", "connect")
        .map_err(|e| e.to_string())?;
    let bridge = b.start().map_err(|e| e.to_string())?;
    let r = gm.reader::<u64>("lat").map_err(|e| e.to_string())?;
    let raw = zenoh::open(raw_config.zenoh_config().map_err(|e| e.to_string())?)
        .wait()
        .map_err(|e| e.to_string())?;
    let raw_seen = Arc::new(Mutex::new(Vec::with_capacity(LATENCY_WRITES)));
    let subscriber = {
        let seen = Arc::clone(&raw_seen);
        raw.declare_subscriber("rcs/bench/raw")
            .callback(move |sample| {
                let now = wall_ns();
                let bytes = sample.payload().to_bytes();
                if let Some(stamp) = bytes.get(..8).and_then(|b| b.try_into().ok()) {
                    let sent = u64::from_le_bytes(stamp);
                    let mut seen = seen.lock().unwrap_or_else(|p| p.into_inner());
                    seen.push(now.saturating_sub(sent));
                }
            })
            .wait()
            .map_err(|e| e.to_string())?
    };
    let mut writer = child(variant, &["latency-child", &ep_bridge, &ep_raw]);
    let bridged = Figures::new(spin_reader(&r, LATENCY_WRITES));
    let _ = writer.wait();
    let _ = subscriber.undeclare().wait();
    let plain = Figures::new(std::mem::take(
        &mut *raw_seen.lock().unwrap_or_else(|p| p.into_inner()),
    ));
    println!("two processes, Zenoh  {}", plain.line());
    println!("two processes, bridge {}", bridged.line());
    let ratio = |q: f64| bridged.at(q) / plain.at(q).max(1.0);
    println!(
        "bridge / Zenoh: p50 ×{:.2}, p99 ×{:.2}, max ×{:.2} (config `{variant}`; {} errors)",
        ratio(0.5),
        ratio(0.99),
        ratio(1.0),
        bridge.errors().len()
    );
    let _ = raw.close().wait();
    Ok(())
}

/// The writing process of `latency`: a bridge exporting `lat`, written by
/// an executive with the bridge's signal attached, and a plain session
/// publishing on `rcs/bench/raw`.
fn latency_child(variant: &str, ep_bridge: &str, ep_raw: &str) -> Result<(), String> {
    let (_, bridge_config) = bench_configs(variant, ep_bridge)?;
    let (_, raw_config) = bench_configs(variant, ep_raw)?;
    let gm = GlobalMemory::new();
    gm.declare::<u64>("lat").map_err(|e| e.to_string())?;
    let mut b = Bridge::builder(bridge_config, &gm);
    b.export::<u64>("lat").map_err(|e| e.to_string())?;
    let bridge = b.start().map_err(|e| e.to_string())?;
    let mut exec = Executive::new(ExecutiveConfig::new("writer", Duration::from_millis(2)))
        .map_err(|e| e.to_string())?;
    exec.add(Box::new(Clock(
        gm.writer::<u64>("lat").map_err(|e| e.to_string())?,
    )))
    .map_err(|e| e.to_string())?;
    exec.set_cycle_signal(bridge.signal());
    let raw = zenoh::open(raw_config.zenoh_config().map_err(|e| e.to_string())?)
        .wait()
        .map_err(|e| e.to_string())?;
    let publisher = raw
        .declare_publisher("rcs/bench/raw")
        .congestion_control(CongestionControl::Drop)
        .wait()
        .map_err(|e| e.to_string())?;
    std::thread::sleep(Duration::from_secs(1)); // the links come up
    let mut payload = [0u8; RAW_PAYLOAD];
    for _ in 0..LATENCY_WRITES {
        exec.step().expect("no controller panics");
        std::thread::sleep(Duration::from_millis(2));
        payload[..8].copy_from_slice(&wall_ns().to_le_bytes());
        let _ = publisher.put(payload.as_slice()).wait();
        std::thread::sleep(Duration::from_millis(2));
    }
    std::thread::sleep(Duration::from_millis(500));
    let _ = raw.close().wait();
    Ok(())
}

/// CPU ticks of this process's threads called `name` (as `comm` shows
/// it: cut to 15 bytes).
fn thread_cpu_ticks(name: &str) -> u64 {
    let name = name.get(..15).unwrap_or(name);
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

/// A process importing 100 buffers of `size` bytes for 30 s (or until
/// killed).
fn sink(variant: &str, ep: &str, size: usize) -> Result<(), String> {
    let (_, config) = bench_configs(variant, ep)?;
    let gm = GlobalMemory::new();
    let mut b = Bridge::builder(config, &gm);
    for i in 0..100 {
        let name = format!("b{i}");
        let r = if size == 4096 {
            gm.declare::<Large>(&name)
                .map_err(Into::into)
                .and_then(|()| b.import::<Large>(&name, "listen").map(|_| ()))
        } else {
            gm.declare::<Small>(&name)
                .map_err(Into::into)
                .and_then(|()| b.import::<Small>(&name, "listen").map(|_| ()))
        };
        r.map_err(|e| e.to_string())?;
    }
    let b = b.start().map_err(|e| e.to_string())?;
    std::thread::sleep(Duration::from_secs(30));
    println!("sink: imported {}", b.stats().imported);
    Ok(())
}

/// An executive's controller writing 100 buffers every cycle.
struct Hundred<T: rcs_runtime::BufferData>(Vec<Writer<T>>, fn(u64) -> T);

impl<T: rcs_runtime::BufferData> Controller for Hundred<T> {
    fn name(&self) -> &str {
        "hundred"
    }
    fn cycle(&mut self, ctx: &CycleContext) {
        for w in &mut self.0 {
            w.write((self.1)(ctx.cycle), ctx.cycle);
        }
    }
}

/// A 1 ms executive writing 100 exported buffers of `T` per cycle, and the
/// bridge (started, its signal attached) if `bridge`.
fn exporting<T>(
    variant: &str,
    ep: &str,
    bridge: bool,
    wait: Wait,
    value: fn(u64) -> T,
) -> Result<(Executive, Option<Bridge>), String>
where
    T: rcs_runtime::BufferData + Schema + Serialize + Sync,
{
    let (config, _) = bench_configs(variant, ep)?;
    let gm = GlobalMemory::new();
    let mut b = Bridge::builder(config, &gm);
    let mut writers = Vec::new();
    for i in 0..100 {
        let name = format!("b{i}");
        gm.declare::<T>(&name).map_err(|e| e.to_string())?;
        writers.push(gm.writer::<T>(&name).map_err(|e| e.to_string())?);
        b.export::<T>(&name).map_err(|e| e.to_string())?;
    }
    let config = ExecutiveConfig::new("servo", Duration::from_millis(1)).with_wait(wait);
    let mut exec = Executive::new(config).map_err(|e| e.to_string())?;
    exec.add(Box::new(Hundred(writers, value)))
        .map_err(|e| e.to_string())?;
    let bridge = if bridge {
        let bridge = b.start().map_err(|e| e.to_string())?;
        exec.set_cycle_signal(bridge.signal());
        Some(bridge)
    } else {
        None
    };
    Ok((exec, bridge))
}

fn load<T>(variant: &str, size: usize, value: fn(u64) -> T) -> Result<(), String>
where
    T: rcs_runtime::BufferData + Schema + Serialize + Sync,
{
    let ep = free_endpoint();
    let (mut exec, bridge) = exporting::<T>(variant, &ep, true, Wait::Sleep, value)?;
    let thread = bridge.as_ref().map(Bridge::thread_name).unwrap_or_default();
    let mut sink = child(variant, &["sink", &ep, &size.to_string()]);
    std::thread::sleep(Duration::from_secs(2));
    let (t0, p0) = (thread_cpu_ticks(&thread), process_cpu_ticks());
    let start = Instant::now();
    exec.run_for(5_000);
    let secs = start.elapsed().as_secs_f64();
    let (t1, p1) = (thread_cpu_ticks(&thread), process_cpu_ticks());
    let published = bridge.as_ref().map_or(0, |b| b.stats().published);
    println!(
        "100 × {size} B at 1 kHz for {secs:.1} s ({} cycles): bridge thread {:.1} % of a core, whole process {:.1} %, {published} samples published",
        exec.cycle(),
        (t1 - t0) as f64 / TICKS_PER_S / secs * 100.0,
        (p1 - p0) as f64 / TICKS_PER_S / secs * 100.0,
    );
    let _ = sink.kill();
    let _ = sink.wait();
    Ok(())
}

fn heartbeat(variant: &str) -> Result<(), String> {
    for with_bridge in [true, false] {
        let ep = free_endpoint();
        let (mut exec, _bridge) =
            exporting::<Small>(variant, &ep, with_bridge, Wait::default(), |c| {
                Small([c; 8])
            })?;
        let mut sink = with_bridge.then(|| child(variant, &["sink", &ep, "64"]));
        std::thread::sleep(Duration::from_secs(2));
        let mut hb =
            Heartbeat::new(Duration::from_millis(1), Wait::default()).expect("a 1 ms heartbeat");
        let mut late = Vec::with_capacity(5_000);
        for _ in 0..5_000 {
            late.push(hb.wait().as_nanos() as u64);
            exec.step().expect("no controller panics");
        }
        println!(
            "heartbeat 1 ms, 100 × 64 B written per cycle, bridge {}: lateness {}",
            if with_bridge { "on " } else { "off" },
            Figures::new(late).line()
        );
        if let Some(s) = sink.as_mut() {
            let _ = s.kill();
            let _ = s.wait();
        }
    }
    Ok(())
}

fn main() -> std::process::ExitCode {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let variant = match args.iter().position(|a| a == "--config") {
        Some(i) if i + 1 < args.len() => {
            let v = args.remove(i + 1);
            args.remove(i);
            v
        }
        Some(_) => {
            eprintln!("--config needs a name");
            return std::process::ExitCode::from(2);
        }
        None => "plain".to_owned(),
    };
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let result = match a.as_slice() {
        ["latency"] => latency(&variant),
        ["latency-child", ep_bridge, ep_raw] => latency_child(&variant, ep_bridge, ep_raw),
        ["load", "64"] => load::<Small>(&variant, 64, |c| Small([c; 8])),
        ["load", "4096"] => load::<Large>(&variant, 4096, |c| Large([[c; 32]; 16])),
        ["heartbeat"] => heartbeat(&variant),
        ["sink", ep, size] => size
            .parse()
            .map_err(|_| format!("size `{size}`"))
            .and_then(|size| sink(&variant, ep, size)),
        _ => Err("usage: bridge_bench [--config NAME] latency | load 64|4096 | heartbeat".into()),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("bridge_bench: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
