//! What a console costs a running hierarchy (issue 31; BENCHMARKS.md,
//! "rcs-console"): 100 axis controllers (`fleet/`, one controller type) on
//! one executive at 1 kHz, its heartbeat lateness with the operator's
//! console attached against without, in alternated windows of one run; and
//! the console's own CPU use while it watches them.
//!
//! The console here is what `rcsc console` and `--console` run every
//! refresh (100 ms): a snapshot through [`InProcess`] (the executive's
//! monitor atomics and the seqlocked status buffers), the model update, and
//! a full redraw of the tree and the selected plan table — into ratatui's
//! `TestBackend` (240 × 70 cells) rather than a terminal, so that the figure
//! is the console's work and not the terminal emulator's.
//!
//! The executive runs as `Executive::run` does, on its heartbeat (sleep and
//! spin), on this thread; its lateness is recorded per cycle for the p99.
//!
//! ```text
//! cargo run --release -p rcs-plan-sets --example console_load [SECONDS_PER_WINDOW] [ROUNDS]
//! ```

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use ratatui::backend::TestBackend;
use ratatui::Terminal;
use rcs_console::{App, Catalog, InProcess, Model, Source};
use rcs_runtime::{Heartbeat, Wait};

include!(concat!(env!("OUT_DIR"), "/fleet/rust/fleet.rs"));

/// The console's refresh period (as in `rcs-console`'s terminal loop).
const REFRESH: Duration = Duration::from_millis(100);

fn percentile(sorted: &[u64], p: f64) -> u64 {
    if sorted.is_empty() {
        return 0;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

/// CPU time (user + system) of the calling thread, from
/// `/proc/thread-self/stat` (clock ticks, 100 per second on Linux).
fn thread_cpu() -> Duration {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap_or_default();
    // The command name may hold spaces: the fields count from after ')'.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|f| f.parse::<u64>().ok())
            .unwrap_or(0)
    };
    // utime and stime are fields 14 and 15 of the whole line, 12 and 13 here.
    Duration::from_millis((ticks(11) + ticks(12)) * 10)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let window_s: u64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(3);
    let rounds: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(4);
    let window = Duration::from_secs(window_s);

    let plans = Path::new(env!("CARGO_MANIFEST_DIR")).join("fleet");
    let catalog = Catalog::load(&plans)?;
    let system = fleet::System::new(fleet::Hooks::default())?;
    let fleet::System {
        gm,
        mut executives,
        inputs,
        operators,
        ..
    } = system;
    drop(inputs);
    let mut exec = executives.pop().ok_or("the fleet has one CPU")?;
    let monitor = exec.attach_monitor(catalog.max_rows());
    let controllers = monitor.controllers().len();
    let period = exec.period();

    // Every axis holds its position from the first cycle on.
    let mut operators = operators;
    macro_rules! hold_all {
        ($($a:ident)*) => { $( operators.$a.command(fleet::$a::Command::Hold); )* };
    }
    hold_all!(a0 a1 a2 a3 a4 a5 a6 a7 a8 a9 a10 a11 a12 a13 a14 a15 a16 a17 a18 a19
        a20 a21 a22 a23 a24 a25 a26 a27 a28 a29 a30 a31 a32 a33 a34 a35 a36 a37 a38 a39
        a40 a41 a42 a43 a44 a45 a46 a47 a48 a49 a50 a51 a52 a53 a54 a55 a56 a57 a58 a59
        a60 a61 a62 a63 a64 a65 a66 a67 a68 a69 a70 a71 a72 a73 a74 a75 a76 a77 a78 a79
        a80 a81 a82 a83 a84 a85 a86 a87 a88 a89 a90 a91 a92 a93 a94 a95 a96 a97 a98 a99);

    // The console on a thread of its own, watching while `watching` is set.
    let watching = Arc::new(AtomicBool::new(false));
    let done = Arc::new(AtomicBool::new(false));
    let console = {
        let watching = Arc::clone(&watching);
        let done = Arc::clone(&done);
        let mut source = InProcess::new(
            &gm,
            vec![(exec.handle(), Arc::clone(&monitor))],
            Box::new(|_: &str, _: &str, _: &[rcs_console::ArgValue]| {
                Err("the benchmark sends no command".to_owned())
            }),
        );
        std::thread::spawn(move || {
            let mut app = App::new(Model::new(catalog));
            let mut terminal = Terminal::new(TestBackend::new(240, 70)).expect("a test backend");
            let (mut cpu, mut wall, mut frames) = (Duration::ZERO, Duration::ZERO, 0u64);
            while !done.load(Ordering::Relaxed) {
                if !watching.load(Ordering::Relaxed) {
                    std::thread::sleep(Duration::from_millis(5));
                    continue;
                }
                let (c0, w0) = (thread_cpu(), Instant::now());
                let mut next = w0;
                while watching.load(Ordering::Relaxed) {
                    app.model.update(source.snapshot());
                    let _ = terminal.draw(|f| rcs_console::view::draw(f, &app));
                    frames += 1;
                    next += REFRESH;
                    std::thread::sleep(next.saturating_duration_since(Instant::now()));
                }
                cpu += thread_cpu().saturating_sub(c0);
                wall += w0.elapsed();
            }
            (cpu, wall, frames)
        })
    };

    println!(
        "{controllers} controllers on one executive, period {} µs; {rounds} rounds of a {window_s} s window without the console and one with it",
        period.as_micros()
    );
    let mut heartbeat = Heartbeat::new(period, Wait::default())?;
    heartbeat.start(Instant::now());
    let beats = window.as_nanos() / period.as_nanos().max(1);
    let (mut without, mut with) = (Vec::new(), Vec::new());
    for round in 0..rounds * 2 {
        // Alternate which comes first, so that drift favours neither.
        let attached = (round % 2 == 0) == (round / 2 % 2 == 0);
        watching.store(attached, Ordering::Relaxed);
        let late = if attached { &mut with } else { &mut without };
        for _ in 0..beats {
            late.push(u64::try_from(heartbeat.wait().as_nanos()).unwrap_or(u64::MAX));
            exec.step().map_err(|f| format!("a cycle faulted: {f:?}"))?;
        }
    }
    watching.store(false, Ordering::Relaxed);
    done.store(true, Ordering::Relaxed);
    let (cpu, wall, frames) = console.join().map_err(|_| "the console thread panicked")?;

    let us = |ns: u64| ns as f64 / 1000.0;
    for (label, late) in [
        ("without console", &mut without),
        ("with console", &mut with),
    ] {
        late.sort_unstable();
        println!(
            "heartbeat lateness {label:<16} p50 {:>7.1} µs  p99 {:>7.1} µs  max {:>8.1} µs  ({} cycles)",
            us(percentile(late, 0.50)),
            us(percentile(late, 0.99)),
            us(late.last().copied().unwrap_or(0)),
            late.len()
        );
    }
    println!(
        "console: {frames} frames, {:.1} ms CPU each, {:.2} % of one core while attached ({:.1} s CPU in {:.1} s)",
        cpu.as_secs_f64() * 1000.0 / frames.max(1) as f64,
        100.0 * cpu.as_secs_f64() / wall.as_secs_f64().max(1e-9),
        cpu.as_secs_f64(),
        wall.as_secs_f64()
    );
    Ok(())
}
