//! The two processes of the split submarine and the one-process run (see
//! the crate's docs in `main.rs`).

use std::io::BufRead;
use std::process::ExitCode;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use rcs_runtime::{BridgeConfig, CommandBuffer, Heartbeat, StatusBuffer, Wait};

use crate::generations::{GenerationWatch, SUMMARY_EVERY};

/// The generated plan set: this binary uses only part of its API.
#[allow(dead_code)]
mod plans {
    rcs_runtime::include_plans!("submarine_split");
}

use plans::submarine_split;
use submarine_split::types::{Ship, ShipDirection, SpeedError, TurbineDrive, TurbineSensors};
use submarine_split::{pr, sm, tb, Hooks, System};

/// The split submarine with PR's hooks.
type Sub = System<Propulsion>;

const USAGE: &str = "usage: submarine-split helm|engine|one-process (--certs DIR | --insecure) [--listen ENDPOINT] [--connect ENDPOINT] [--speed KNOTS] [--cycles N] [--report-every N] [--report-generations] [--no-order]

  helm         SM and PR; listens on tls/127.0.0.1:7447; orders SM <- TRANSIT(speed) once TB answers;
               `transit KNOTS` on standard input orders again
  engine       TB with the turbine and ship simulators; connects to tls/127.0.0.1:7447
  one-process  the whole hierarchy in this process, flat out, until AT_GOAL
  --certs DIR  mutual TLS with DIR/ca.pem, DIR/PROCESS.pem and DIR/PROCESS.key
               (`rcsc certs DIR examples/submarine-split/plans` makes development ones),
               and the access-control policy rcsc generated for the process
  --insecure   no TLS, no access control (tcp/ endpoints): anyone on the network can command the ship
  --cycles N   stop after N cycles (default: run until killed; one-process: 2000)
  --no-order   the helm orders nothing itself: orders come from standard input or an operator
               (a console: `rcsc console PLANS --connect …`)
  --report-every N  also print a `report` line every N cycles: the helm the ship's speed and age,
               the engine the turbine's drive, both the bridge's refused samples
  --report-generations
               check every cycle that the stamps of the buffers the bridge imports never go
               back; print `out of order: …` if they do and a `generations …` summary every
               100 cycles (the fault tests use it)";

/// PR's watchdog row E2 fires when `TB.stale_cycles` exceeds this
/// (`plans/propulsion.rcs`).
const WATCHDOG_BOUND: u32 = 30;

/// Hit counters per verb for a remote console: more than the longest plan
/// of `plans/` (rows beyond would be counted as dropped, not shown).
const CONSOLE_ROWS: usize = 16;

/// The helm's port, which the engine connects to.
const DEFAULT_PORT: &str = "127.0.0.1:7447";

// ---------------------------------------------------------------------------
// PR's hooks and the simulated world (as in examples/submarine)

/// PR's propulsion model: RPM per knot (the ship needs 10: 5 % low, so
/// Appendix C's ±1 RPM loop has work to do), and its dead band in knots.
#[derive(Debug, Clone, Copy)]
struct Propulsion {
    rpm_per_knot: f64,
    dead_band: f64,
}

const PROPULSION: Propulsion = Propulsion {
    rpm_per_knot: 9.5,
    dead_band: 0.1,
};

impl pr::Hooks for Propulsion {
    fn required_rpm(&mut self, _data: &pr::Data, speed: f64) -> f64 {
        self.rpm_per_knot * speed
    }

    fn speed_error(&mut self, data: &pr::Data) -> SpeedError {
        let pr::Command::Ahead { speed: ordered } = data.command else {
            return SpeedError::At;
        };
        let error = data.reads.ship.speed - ordered;
        if error < -self.dead_band {
            SpeedError::Below
        } else if error > self.dead_band {
            SpeedError::Above
        } else {
            SpeedError::At
        }
    }
}

/// The turbine and the ship: first-order lags stepped once per cycle, with
/// compressed time constants (seconds) so that a run takes a few seconds.
#[derive(Debug, Clone, Copy, Default)]
struct Plant {
    rpm: f64,
    speed: f64,
}

impl Plant {
    fn step(&mut self, drive: TurbineDrive, dt: f64) {
        let lag = |tau: f64| 1.0 - (-dt / tau).exp();
        let (target, tau) = if drive.engaged {
            (drive.rpm_setpoint, 0.05)
        } else {
            (0.0, 2.0)
        };
        self.rpm += (target - self.rpm) * lag(tau);
        self.speed += (0.1 * self.rpm - self.speed) * lag(0.05);
    }

    fn ship(&self) -> Ship {
        let direction = if self.speed > 0.01 {
            ShipDirection::Ahead
        } else if self.speed < -0.01 {
            ShipDirection::Backward
        } else {
            ShipDirection::Stopped
        };
        Ship {
            direction,
            speed: self.speed,
        }
    }

    fn turbine(&self) -> TurbineSensors {
        TurbineSensors { rpm: self.rpm }
    }
}

// ---------------------------------------------------------------------------
// Options

#[derive(Debug, Clone)]
struct Options {
    role: String,
    listen: Option<String>,
    connect: Option<String>,
    speed: f64,
    cycles: Option<u64>,
    certs: Option<std::path::PathBuf>,
    insecure: bool,
    report_every: Option<u64>,
    report_generations: bool,
    /// The helm waits for orders (stdin, or a remote operator) instead of
    /// ordering TRANSIT(speed) itself.
    no_order: bool,
}

impl Options {
    fn parse(args: impl IntoIterator<Item = String>) -> Result<Option<Self>, String> {
        let mut args = args.into_iter();
        let role = match args.next() {
            None => return Err("which process? helm, engine or one-process".into()),
            Some(a) if a == "-h" || a == "--help" => return Ok(None),
            Some(a) => a,
        };
        let mut opts = Options {
            role,
            listen: None,
            connect: None,
            speed: 15.0,
            cycles: None,
            certs: None,
            insecure: false,
            report_every: None,
            report_generations: false,
            no_order: false,
        };
        while let Some(arg) = args.next() {
            let mut value = || args.next().ok_or(format!("{arg} needs a value"));
            match arg.as_str() {
                "--report-generations" => opts.report_generations = true,
                "--no-order" => opts.no_order = true,
                "--listen" => opts.listen = Some(value()?),
                "--certs" => opts.certs = Some(value()?.into()),
                "--insecure" => opts.insecure = true,
                "--report-every" => {
                    let v = value()?;
                    opts.report_every = Some(
                        v.parse::<u64>()
                            .ok()
                            .filter(|n| *n > 0)
                            .ok_or(format!("--report-every: `{v}` is not a number of cycles"))?,
                    );
                }
                "--connect" => opts.connect = Some(value()?),
                "--speed" => {
                    let v = value()?;
                    opts.speed = v
                        .parse::<f64>()
                        .ok()
                        .filter(|s| s.is_finite() && *s > 0.0)
                        .ok_or(format!("--speed: `{v}` is not a positive number of knots"))?;
                }
                "--cycles" => {
                    let v = value()?;
                    opts.cycles = Some(
                        v.parse::<u64>()
                            .map_err(|_| format!("--cycles: `{v}` is not a number of cycles"))?,
                    );
                }
                other => return Err(format!("unexpected argument `{other}`")),
            }
        }
        if opts.role != "one-process" && opts.certs.is_some() == opts.insecure {
            return Err(
                "choose --certs DIR (mutual TLS and access control) or --insecure (neither)".into(),
            );
        }
        Ok(Some(opts))
    }

    fn bridge(&self) -> BridgeConfig {
        let mut c = BridgeConfig::new("submarine_split", &self.role);
        c = match &self.certs {
            Some(dir) => c.certs(dir),
            None => c.insecure(),
        };
        let default = format!(
            "{}/{DEFAULT_PORT}",
            if self.insecure { "tcp" } else { "tls" }
        );
        let (listen, connect) = match self.role.as_str() {
            "helm" => (
                Some(self.listen.as_deref().unwrap_or(&default)),
                self.connect.as_deref(),
            ),
            _ => (
                self.listen.as_deref(),
                Some(self.connect.as_deref().unwrap_or(&default)),
            ),
        };
        if let Some(l) = listen {
            c = c.listen(l);
        }
        if let Some(e) = connect {
            c = c.connect(e);
        }
        c
    }
}

pub(crate) fn main() -> ExitCode {
    let opts = match Options::parse(std::env::args().skip(1)) {
        Ok(Some(opts)) => opts,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(msg) => {
            eprintln!("submarine-split: {msg}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let result = match opts.role.as_str() {
        "helm" => helm(&opts),
        "engine" => engine(&opts),
        "one-process" => one_process(&opts),
        other => Err(format!("unknown process `{other}`")),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("submarine-split: {e}");
            ExitCode::from(2)
        }
    }
}

// ---------------------------------------------------------------------------
// Display

/// `SM=VERB/STATE/STATUS PR=VERB/STATE/STATUS` for the controllers this
/// process runs.
fn statuses(system: &Sub) -> String {
    let mut parts = Vec::new();
    if let Some(c) = system.sm() {
        let status = c.status().map_or("?", sm::Status::name);
        parts.push(part("SM", c.verb_name(), c.state_name(), status));
    }
    if let Some(c) = system.pr() {
        let status = c.status().map_or("?", pr::Status::name);
        parts.push(part("PR", c.verb_name(), c.state_name(), status));
    }
    if let Some(c) = system.tb() {
        let status = c.status().map_or("?", tb::Status::name);
        parts.push(part("TB", c.verb_name(), c.state_name(), status));
    }
    parts.join(" ")
}

/// `NAME=VERB/STATE/STATUS`, `-` for no verb or state yet.
fn part(name: &str, verb: Option<&str>, state: Option<&str>, status: &str) -> String {
    format!(
        "{name}={}/{}/{status}",
        verb.unwrap_or("-"),
        state.unwrap_or("-")
    )
}

/// Whether PR reports AT_GOAL.
fn at_goal(system: &Sub) -> bool {
    system.pr().and_then(pr::Controller::status) == Some(pr::Status::AtGoal)
}

/// The bridge's refusals, a line whenever a count grows (a schema mismatch
/// means the other process was built from other plans; a wrong writer or a
/// second writer, that something impersonates a process).
fn report_bridge_errors(bridge: &rcs_runtime::Bridge, shown: &mut u64) {
    let refused = bridge.stats().refused;
    if refused == *shown {
        return;
    }
    *shown = refused;
    for r in bridge.refusals() {
        println!(
            "bridge refused {} sample(s) of {} ({}): {}",
            r.count, r.buffer, r.kind, r.latest
        );
    }
}

// ---------------------------------------------------------------------------
// The processes

/// SM and PR: wait for TB, order TRANSIT, print status changes; orders from
/// standard input. Returns whether PR reached AT_GOAL at least once.
fn helm(opts: &Options) -> Result<bool, String> {
    let (mut system, mut bridge) =
        Sub::process("helm", opts.bridge(), Hooks { pr: PROPULSION }).map_err(|e| e.to_string())?;
    bridge
        .serve_console(&system.gm, &mut system.executives, CONSOLE_ROWS)
        .map_err(|e| e.to_string())?;
    let tb_status = system
        .gm
        .reader::<StatusBuffer>(&rcs_runtime::status_buffer_name(tb::NAME))
        .map_err(|e| e.to_string())?;
    println!("helm: waiting for the engine process");
    let deadline = Instant::now() + Duration::from_secs(120);
    while tb_status.generation() == 0 {
        if Instant::now() > deadline {
            return Err("the engine process did not answer within 120 s".into());
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    println!("helm: engine answered");
    let mut watch = GenerationWatch::new();
    if opts.report_generations {
        watch.watch("TB.status", tb_status.clone());
        watch.watch(
            "ship",
            system
                .gm
                .reader::<Ship>("ship")
                .map_err(|e| e.to_string())?,
        );
    }

    // Orders typed on standard input, read on a thread of their own.
    let (orders, order_rx) = mpsc::channel::<f64>();
    std::thread::spawn(move || {
        for line in std::io::stdin().lock().lines().map_while(Result::ok) {
            let mut words = line.split_whitespace();
            if let (Some("transit"), Some(Ok(kn))) = (words.next(), words.next().map(str::parse)) {
                if orders.send(kn).is_err() {
                    break;
                }
            }
        }
    });

    let order = |system: &mut Sub, speed: f64| {
        system.operators.sm.command(sm::Command::Transit { speed });
        println!("order SM <- TRANSIT(speed: {speed:.2})");
    };
    if !opts.no_order {
        order(&mut system, opts.speed);
    }
    let period = system
        .executives
        .first()
        .map_or(Duration::from_millis(30), |e| e.period());
    let mut heartbeat = Heartbeat::new(period, Wait::default()).map_err(|e| e.to_string())?;
    let mut last = String::new();
    let mut reached = false;
    let mut goal_seen = false;
    let mut errors_shown = 0u64;
    let mut silent = 0u32;
    let mut cycle = 0u64;
    while opts.cycles.is_none_or(|n| cycle < n) {
        let late = heartbeat.wait();
        if let Ok(speed) = order_rx.try_recv() {
            order(&mut system, speed);
            goal_seen = false;
        }
        if let Err(fault) = cycle_unless_paused(&mut system, late, heartbeat.missed()) {
            // Contained: the faulty controller's plan ended with HOOK_PANIC.
            eprintln!("submarine-split: {fault}");
        }
        let now = statuses(&system);
        // PR's watchdog count on TB: cycles since TB's status last changed.
        let stale = system.pr().map_or(0, |c| c.data().subs.tb.stale_cycles);
        if now != last {
            println!("cycle {cycle} {now} tb_stale={stale}");
            last = now;
        }
        if opts.report_every.is_some_and(|n| cycle.is_multiple_of(n)) {
            let ship = system.pr().map_or(0.0, |c| c.data().reads.ship.speed);
            // `ship.stale_cycles` as PR saw it this cycle (its `ship_age`).
            let ship_stale = system.pr().map_or(0, |c| c.data().vars.ship_age);
            let stats = bridge.stats();
            println!(
                "report cycle={cycle} speed={ship:.2} tb_stale={stale} ship_stale={ship_stale} received={} imported={} refused={}",
                stats.received, stats.imported, stats.refused
            );
        }
        // Past PR's watchdog bound (E2: > 30) and news again: say so, for
        // whoever waits to order again.
        if stale == 0 && silent > WATCHDOG_BOUND {
            println!("helm: engine answered again after {silent} silent cycles");
        }
        silent = stale;
        if opts.report_generations {
            watch.check();
            if (cycle + 1).is_multiple_of(SUMMARY_EVERY) || opts.cycles == Some(cycle + 1) {
                println!("{}", watch.summary(cycle + 1, Some(stale)));
            }
        }
        if at_goal(&system) && !goal_seen {
            goal_seen = true;
            reached = true;
            println!("goal {}", statuses(&system));
        }
        report_bridge_errors(&bridge, &mut errors_shown);
        cycle += 1;
    }
    Ok(reached)
}

/// TB with the simulated turbine and ship, on its own heartbeat.
fn engine(opts: &Options) -> Result<bool, String> {
    let (mut system, mut bridge) = Sub::process("engine", opts.bridge(), Hooks { pr: PROPULSION })
        .map_err(|e| e.to_string())?;
    bridge
        .serve_console(&system.gm, &mut system.executives, CONSOLE_ROWS)
        .map_err(|e| e.to_string())?;
    let period = system
        .executives
        .first()
        .map_or(Duration::from_millis(30), |e| e.period());
    let dt = period.as_secs_f64();
    let mut plant = Plant::default();
    let (Some(mut ship), Some(mut turbine)) =
        (system.inputs.ship.take(), system.inputs.turbine.take())
    else {
        return Err("the manifest places `ship` and `turbine` in another process".into());
    };
    ship.write(plant.ship(), 0);
    turbine.write(plant.turbine(), 0);
    let mut watch = GenerationWatch::new();
    if opts.report_generations {
        let name = rcs_runtime::command_buffer_name(tb::NAME);
        let reader = system
            .gm
            .reader::<CommandBuffer<tb::Command>>(&name)
            .map_err(|e| e.to_string())?;
        watch.watch(&name, reader);
    }
    let inputs_written = bridge.signal();
    println!("engine: running");
    let mut heartbeat = Heartbeat::new(period, Wait::default()).map_err(|e| e.to_string())?;
    let mut last = String::new();
    let mut errors_shown = 0u64;
    let mut cycle = 0u64;
    while opts.cycles.is_none_or(|n| cycle < n) {
        let late = heartbeat.wait();
        if let Err(fault) = cycle_unless_paused(&mut system, late, heartbeat.missed()) {
            // Contained: the faulty controller's plan ended with HOOK_PANIC.
            eprintln!("submarine-split: {fault}");
        }
        plant.step(system.outputs.drive.read().value, dt);
        ship.write(plant.ship(), cycle + 1);
        turbine.write(plant.turbine(), cycle + 1);
        // Written outside an executive: publish them now rather than with
        // the next cycle's signal or the bridge's fallback poll.
        inputs_written.raise();
        let now = statuses(&system);
        if now != last {
            println!("cycle {cycle} {now}");
            last = now;
        }
        if opts.report_every.is_some_and(|n| cycle.is_multiple_of(n)) {
            let drive = system.outputs.drive.read().value;
            println!(
                "report cycle={cycle} rpm_setpoint={:.1} refused={}",
                drive.rpm_setpoint,
                bridge.stats().refused
            );
        }
        if opts.report_generations {
            watch.check();
            if (cycle + 1).is_multiple_of(SUMMARY_EVERY) || opts.cycles == Some(cycle + 1) {
                println!("{}", watch.summary(cycle + 1, None));
            }
        }
        report_bridge_errors(&bridge, &mut errors_shown);
        cycle += 1;
    }
    Ok(true)
}

/// One cycle of each executive of this process, unless a console paused
/// it (a single step it asked for runs): `System::run_cycles(1)` for a
/// main loop that a remote console may pause. The loop's heartbeat (`late`,
/// `missed`) goes into the executives' figures.
fn cycle_unless_paused(
    system: &mut Sub,
    late: Duration,
    missed: u64,
) -> Result<(), rcs_runtime::CycleFault> {
    let mut fault: Option<rcs_runtime::CycleFault> = None;
    for exec in &mut system.executives {
        exec.note_heartbeat(late, missed);
        if let Err(f) = exec.step_unless_paused() {
            match &mut fault {
                Some(first) => first.merge(f),
                None => fault = Some(f),
            }
        }
    }
    fault.map_or(Ok(()), Err)
}

/// The same hierarchy and simulators in one process, flat out: prints the
/// same `goal` line as `helm` when PR first reports AT_GOAL.
fn one_process(opts: &Options) -> Result<bool, String> {
    let mut system = Sub::new(Hooks { pr: PROPULSION }).map_err(|e| e.to_string())?;
    let period = system
        .executives
        .first()
        .map_or(Duration::from_millis(30), |e| e.period());
    let dt = period.as_secs_f64();
    let mut plant = Plant::default();
    let (Some(ship), Some(turbine)) = (system.inputs.ship.as_mut(), system.inputs.turbine.as_mut())
    else {
        return Err("`System::new` holds every input".into());
    };
    ship.write(plant.ship(), 0);
    turbine.write(plant.turbine(), 0);
    system
        .operators
        .sm
        .command(sm::Command::Transit { speed: opts.speed });
    for cycle in 0..opts.cycles.unwrap_or(2_000) {
        if let Err(fault) = system.run_cycles(1) {
            // Contained: the faulty controller's plan ended with HOOK_PANIC.
            eprintln!("submarine-split: {fault}");
        }
        plant.step(system.outputs.drive.read().value, dt);
        if let (Some(ship), Some(turbine)) =
            (system.inputs.ship.as_mut(), system.inputs.turbine.as_mut())
        {
            ship.write(plant.ship(), cycle + 1);
            turbine.write(plant.turbine(), cycle + 1);
        }
        if at_goal(&system) {
            println!("goal {}", statuses_of_helm(&system));
            return Ok(true);
        }
    }
    Ok(false)
}

/// `statuses` restricted to the helm's controllers (SM and PR), for
/// comparing a one-process run with the helm process.
fn statuses_of_helm(system: &Sub) -> String {
    statuses(system)
        .split(' ')
        .filter(|p| !p.starts_with("TB="))
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod restart_tests;
