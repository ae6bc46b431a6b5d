//! # fault-relay: a TCP relay that injects network faults, for the tests
//!
//! Where it sits: between the split submarine's `engine` and `helm`
//! (`tests/netns_faults.rs` runs it in a network namespace of its own, the
//! engine connecting to it and it to the helm). The kernel this project is
//! tested on has no `netem` qdisc, so delays, stalls, resets and reordered
//! connection attempts come from here instead; `tbf` and `ip link … down`
//! supply a thin link and a partition.
//!
//! ```text
//! fault-relay --listen ADDR:PORT --upstream ADDR:PORT
//! ```
//!
//! Each accepted connection is joined to a new connection to `--upstream`
//! and bytes are copied both ways, chunk by chunk, in order. Commands on
//! standard input, one a line, each answered with `ok …`:
//!
//! | command | effect |
//! |---|---|
//! | `delay MS JITTER` | forward each chunk MS ± JITTER ms after it arrived (uniform, order kept) |
//! | `stall` / `flow` | hold every chunk (connections stay open) / forward again, held chunks first |
//! | `reset` | reset (RST) every open connection, both sides |
//! | `close` | close (FIN) every open connection, both sides: dropped as by a peer that left |
//! | `refuse` / `accept` | reset every new connection attempt at once / join them again |
//! | `hold` / `release` | take each new attempt's first bytes (≤ 300 ms), then reset it / join new attempts again, and once the next one is joined, replay the held attempts' bytes upstream, newest first, on connections of their own: attempts reach the upstream late and out of order |
//! | `stats` | print `stats connections=… refused=… held=… replayed=… resets=… closes=… chunks=… delay_mean_ms=… delay_max_ms=…` (delay figures since the last `stats`; chunks that met a stall left out) |
//!
//! It prints `connected N` when attempt N is joined, `replayed N late
//! attempts` after a replay, and ends when standard input closes. Test
//! tooling: no `unsafe`, no dependency but `socket2` (for a reset that is an
//! RST, not a FIN).

use std::collections::HashMap;
use std::io::{BufRead, Read, Write};
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicU8, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

const USAGE: &str = "usage: fault-relay --listen ADDR:PORT --upstream ADDR:PORT
  commands on standard input: delay MS JITTER | stall | flow | reset | close | refuse | accept | hold | release | stats";

/// What the faults are now; read by every thread, changed by commands.
#[derive(Debug, Clone, Copy, Default)]
struct Settings {
    delay_ms: u64,
    jitter_ms: u64,
    stalled: bool,
    refusing: bool,
    holding: bool,
}

/// Applied delays (write time − arrival time) since the last `stats`.
#[derive(Debug, Default)]
struct DelayStats {
    chunks: u64,
    sum: Duration,
    max: Duration,
}

/// A joined connection's two sockets (clones, for `reset`) and its flag.
struct Live {
    client: TcpStream,
    upstream: TcpStream,
    reset: Arc<AtomicBool>,
}

/// Everything the relay's threads share.
struct Relay {
    upstream: SocketAddr,
    settings: Mutex<Settings>,
    live: Mutex<HashMap<u64, Live>>,
    held: Mutex<Vec<Vec<u8>>>,
    replay_armed: AtomicBool,
    delays: Mutex<DelayStats>,
    connections: AtomicU64,
    refused: AtomicU64,
    held_count: AtomicU64,
    replayed: AtomicU64,
    resets: AtomicU64,
    closes: AtomicU64,
}

/// Lock, whether or not another thread panicked holding the lock (the data
/// are counters and flags: still meaningful).
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// Close `s` with an RST rather than a FIN.
fn reset_socket(s: &TcpStream) {
    let _ = socket2::SockRef::from(s).set_linger(Some(Duration::ZERO));
    let _ = s.shutdown(Shutdown::Read);
}

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let (mut listen, mut upstream) = (None, None);
    while let Some(a) = args.next() {
        match (a.as_str(), args.next()) {
            ("--listen", Some(v)) => listen = v.parse::<SocketAddr>().ok(),
            ("--upstream", Some(v)) => upstream = v.parse::<SocketAddr>().ok(),
            _ => {
                eprintln!("fault-relay: bad argument `{a}`\n{USAGE}");
                return ExitCode::from(2);
            }
        }
    }
    let (Some(listen), Some(upstream)) = (listen, upstream) else {
        eprintln!("fault-relay: --listen and --upstream need ADDR:PORT\n{USAGE}");
        return ExitCode::from(2);
    };
    let listener = match TcpListener::bind(listen) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("fault-relay: cannot listen on {listen}: {e}");
            return ExitCode::from(2);
        }
    };
    let relay = Arc::new(Relay {
        upstream,
        settings: Mutex::default(),
        live: Mutex::default(),
        held: Mutex::default(),
        replay_armed: AtomicBool::new(false),
        delays: Mutex::default(),
        connections: AtomicU64::new(0),
        refused: AtomicU64::new(0),
        held_count: AtomicU64::new(0),
        replayed: AtomicU64::new(0),
        resets: AtomicU64::new(0),
        closes: AtomicU64::new(0),
    });
    {
        let relay = Arc::clone(&relay);
        std::thread::spawn(move || accept_loop(&listener, &relay));
    }
    println!("relay: listening on {listen}, upstream {upstream}");
    for line in std::io::stdin().lock().lines().map_while(Result::ok) {
        match command(&relay, &line) {
            Ok(reply) => println!("ok {reply}"),
            Err(e) => println!("error: {e}"),
        }
    }
    ExitCode::SUCCESS
}

/// Carry out one command line; the text after `ok`.
fn command(relay: &Arc<Relay>, line: &str) -> Result<String, String> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let mut s = lock(&relay.settings);
    match words.as_slice() {
        ["delay", ms, jitter] => {
            let num = |w: &str| w.parse::<u64>().map_err(|_| format!("`{w}` is not ms"));
            s.delay_ms = num(ms)?;
            s.jitter_ms = num(jitter)?.min(s.delay_ms);
        }
        ["stall"] => s.stalled = true,
        ["flow"] => s.stalled = false,
        ["refuse"] => s.refusing = true,
        ["accept"] => s.refusing = false,
        ["hold"] => s.holding = true,
        ["release"] => {
            s.holding = false;
            let any = !lock(&relay.held).is_empty();
            relay.replay_armed.store(any, Ordering::SeqCst);
        }
        ["reset"] => {
            let live: Vec<Live> = lock(&relay.live).drain().map(|(_, l)| l).collect();
            for l in &live {
                l.reset.store(true, Ordering::SeqCst);
                reset_socket(&l.client);
                reset_socket(&l.upstream);
            }
            relay.resets.fetch_add(live.len() as u64, Ordering::SeqCst);
        }
        ["close"] => {
            let live: Vec<Live> = lock(&relay.live).drain().map(|(_, l)| l).collect();
            for l in &live {
                let _ = l.client.shutdown(Shutdown::Both);
                let _ = l.upstream.shutdown(Shutdown::Both);
            }
            relay.closes.fetch_add(live.len() as u64, Ordering::SeqCst);
        }
        ["stats"] => {
            let mut d = lock(&relay.delays);
            let ms = |t: Duration| t.as_secs_f64() * 1e3;
            let mean = if d.chunks == 0 {
                0.0
            } else {
                ms(d.sum) / d.chunks as f64
            };
            let reply = format!(
                "stats connections={} refused={} held={} replayed={} resets={} closes={} chunks={} delay_mean_ms={mean:.1} delay_max_ms={:.1}",
                relay.connections.load(Ordering::SeqCst),
                relay.refused.load(Ordering::SeqCst),
                relay.held_count.load(Ordering::SeqCst),
                relay.replayed.load(Ordering::SeqCst),
                relay.resets.load(Ordering::SeqCst),
                relay.closes.load(Ordering::SeqCst),
                d.chunks,
                ms(d.max),
            );
            *d = DelayStats::default();
            return Ok(reply);
        }
        _ => return Err(format!("unknown command `{line}`")),
    }
    Ok(line.trim().to_owned())
}

/// Accept attempts and treat each as the settings say.
fn accept_loop(listener: &TcpListener, relay: &Arc<Relay>) {
    for client in listener.incoming() {
        let Ok(client) = client else { continue };
        let s = *lock(&relay.settings);
        let relay = Arc::clone(relay);
        if s.refusing {
            reset_socket(&client);
            relay.refused.fetch_add(1, Ordering::SeqCst);
        } else if s.holding {
            std::thread::spawn(move || hold(client, &relay));
        } else {
            std::thread::spawn(move || join(client, &relay));
        }
    }
}

/// Keep an attempt's first bytes, then reset it.
fn hold(mut client: TcpStream, relay: &Relay) {
    let _ = client.set_read_timeout(Some(Duration::from_millis(300)));
    let mut bytes = Vec::new();
    let mut buf = [0u8; 4096];
    while bytes.len() < 65536 {
        match client.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => bytes.extend_from_slice(&buf[..n]),
        }
    }
    reset_socket(&client);
    let n = relay.held_count.fetch_add(1, Ordering::SeqCst) + 1;
    println!("held attempt {n} ({} bytes)", bytes.len());
    lock(&relay.held).push(bytes);
}

/// Join an attempt to a new upstream connection and pump both ways.
fn join(client: TcpStream, relay: &Arc<Relay>) {
    let upstream = match TcpStream::connect_timeout(&relay.upstream, Duration::from_secs(5)) {
        Ok(u) => u,
        Err(e) => {
            println!("upstream unreachable: {e}");
            reset_socket(&client);
            return;
        }
    };
    let _ = client.set_nodelay(true);
    let _ = upstream.set_nodelay(true);
    let id = relay.connections.fetch_add(1, Ordering::SeqCst) + 1;
    let reset = Arc::new(AtomicBool::new(false));
    let clones = (client.try_clone(), upstream.try_clone());
    let (Ok(c2), Ok(u2)) = clones else {
        return;
    };
    lock(&relay.live).insert(
        id,
        Live {
            client: c2,
            upstream: u2,
            reset: Arc::clone(&reset),
        },
    );
    println!("connected {id}");
    let ends = Arc::new(AtomicU8::new(0));
    for (from, to, direction) in [(&client, &upstream, 0u64), (&upstream, &client, 1)] {
        let (Ok(from), Ok(to)) = (from.try_clone(), to.try_clone()) else {
            continue;
        };
        let (relay, reset, ends) = (Arc::clone(relay), Arc::clone(&reset), Arc::clone(&ends));
        std::thread::spawn(move || {
            pump(from, to, &relay, &reset, id * 2 + direction);
            // The second direction to end forgets the connection.
            if ends.fetch_add(1, Ordering::SeqCst) == 1 {
                lock(&relay.live).remove(&id);
            }
        });
    }
    if relay.replay_armed.swap(false, Ordering::SeqCst) {
        let relay = Arc::clone(relay);
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_secs(1));
            replay(&relay);
        });
    }
}

/// A chunk on its way, or the end of the stream.
enum Chunk {
    Data {
        arrived: Instant,
        due: Instant,
        /// Arrived during a stall: its delay is the stall's, not the relay's.
        stalled: bool,
        bytes: Vec<u8>,
    },
    End,
}

/// One direction: a reader thread stamps chunks with their due time; this
/// thread writes them when due (and not stalled), in arrival order.
fn pump(from: TcpStream, mut to: TcpStream, relay: &Arc<Relay>, reset: &AtomicBool, seed: u64) {
    let (tx, rx) = mpsc::channel();
    {
        let relay = Arc::clone(relay);
        std::thread::spawn(move || read_chunks(from, &tx, &relay, seed));
    }
    write_chunks(&rx, &mut to, relay, reset);
}

fn read_chunks(mut from: TcpStream, tx: &Sender<Chunk>, relay: &Relay, seed: u64) {
    // xorshift64*: a fixed sequence per connection and direction.
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut buf = vec![0u8; 16384];
    loop {
        let n = match from.read(&mut buf) {
            Ok(0) | Err(_) => 0,
            Ok(n) => n,
        };
        if n == 0 {
            let _ = tx.send(Chunk::End);
            return;
        }
        let s = *lock(&relay.settings);
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        let r = x.wrapping_mul(0x2545_F491_4F6C_DD1D);
        let span_us = 2 * s.jitter_ms * 1000 + 1;
        let delay_us = (s.delay_ms * 1000 + r % span_us).saturating_sub(s.jitter_ms * 1000);
        let arrived = Instant::now();
        let chunk = Chunk::Data {
            arrived,
            due: arrived + Duration::from_micros(delay_us),
            stalled: s.stalled,
            bytes: buf[..n].to_vec(),
        };
        if tx.send(chunk).is_err() {
            return;
        }
    }
}

fn write_chunks(rx: &Receiver<Chunk>, to: &mut TcpStream, relay: &Relay, reset: &AtomicBool) {
    for chunk in rx {
        if reset.load(Ordering::SeqCst) {
            return;
        }
        let Chunk::Data {
            arrived,
            due,
            stalled: mut stalled_on_it,
            bytes,
        } = chunk
        else {
            let _ = to.shutdown(Shutdown::Write);
            return;
        };
        loop {
            let stalled = lock(&relay.settings).stalled;
            stalled_on_it |= stalled;
            let now = Instant::now();
            if !stalled && now >= due {
                break;
            }
            let wait = due
                .saturating_duration_since(now)
                .max(Duration::from_millis(1));
            std::thread::sleep(wait.min(Duration::from_millis(2)));
            if reset.load(Ordering::SeqCst) {
                return;
            }
        }
        if to.write_all(&bytes).is_err() {
            return;
        }
        if !stalled_on_it {
            let mut d = lock(&relay.delays);
            let took = arrived.elapsed();
            d.chunks += 1;
            d.sum += took;
            d.max = d.max.max(took);
        }
    }
}

/// Send the held attempts' bytes upstream, newest first, each on a new
/// connection, and report how the upstream answered.
fn replay(relay: &Relay) {
    let held: Vec<Vec<u8>> = std::mem::take(&mut *lock(&relay.held));
    let n = held.len();
    for (i, bytes) in held.iter().enumerate().rev() {
        let Ok(mut up) = TcpStream::connect_timeout(&relay.upstream, Duration::from_secs(5)) else {
            println!("replay of attempt {}: upstream unreachable", i + 1);
            continue;
        };
        let _ = up.write_all(bytes);
        let _ = up.set_read_timeout(Some(Duration::from_secs(2)));
        let mut answered = 0usize;
        let mut buf = [0u8; 4096];
        // Closed by the upstream (EOF or reset), or still open at the timeout.
        let closed = loop {
            match up.read(&mut buf) {
                Ok(0) => break true,
                Ok(k) => answered += k,
                Err(e) => {
                    break !matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                    )
                }
            }
        };
        relay.replayed.fetch_add(1, Ordering::SeqCst);
        println!(
            "replayed attempt {} late: sent={} answered={answered} upstream_closed={closed}",
            i + 1,
            bytes.len()
        );
    }
    println!("replayed {n} late attempts");
}
