//! Heartbeat lateness at a fixed period: plain sleep against sleep+spin.
//!
//! `cargo run --release -p rcs-runtime --example heartbeat -- [CYCLES] [PERIOD_US]`
//! (defaults: 2000 cycles, 1000 µs). Prints p50 / p99 / max of how late each
//! heartbeat woke after its absolute deadline.

use std::time::Duration;

use rcs_runtime::{Heartbeat, SetupError, Wait};

fn percentile(sorted: &[u64], p: f64) -> u64 {
    if sorted.is_empty() {
        return 0;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

fn measure(period: Duration, wait: Wait, cycles: usize) -> Result<Vec<u64>, SetupError> {
    let mut hb = Heartbeat::new(period, wait)?;
    hb.start(std::time::Instant::now());
    let mut late: Vec<u64> = (0..cycles).map(|_| hb.wait().as_nanos() as u64).collect();
    late.sort_unstable();
    Ok(late)
}

fn main() -> Result<(), SetupError> {
    let mut args = std::env::args().skip(1);
    let cycles: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(2000);
    let period_us: u64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(1000);
    let period = Duration::from_micros(period_us);
    println!("period {period_us} µs, {cycles} cycles; lateness after the deadline");
    println!(
        "{:<22} {:>10} {:>10} {:>10}",
        "wait", "p50 µs", "p99 µs", "max µs"
    );
    for (label, wait) in [
        ("sleep", Wait::Sleep),
        (
            "sleep+spin 50 µs",
            Wait::SleepSpin(Duration::from_micros(50)),
        ),
        (
            "sleep+spin 200 µs",
            Wait::SleepSpin(Duration::from_micros(200)),
        ),
    ] {
        let late = measure(period, wait, cycles)?;
        let us = |ns: u64| ns as f64 / 1000.0;
        println!(
            "{:<22} {:>10.1} {:>10.1} {:>10.1}",
            label,
            us(percentile(&late, 0.50)),
            us(percentile(&late, 0.99)),
            us(*late.last().unwrap_or(&0)),
        );
    }
    Ok(())
}
