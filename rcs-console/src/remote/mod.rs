//! The console as a process of its own (feature `zenoh`): [`Remote`], a
//! [`Source`] over the Zenoh transport of a distributed plan set.
//!
//! Where it sits: the other end of `rcs_runtime::bridge::console`. Each
//! process of the plan set that serves a console (`Bridge::serve_console`)
//! publishes its executives' figures 20 times a second and takes executive
//! controls; the root's process takes the operator's commands for the root
//! through its one command writer (`BridgeBuilder::import_operator`). The
//! console connects as the identity `operator` (mutual TLS with the
//! operator's certificate, under the operator's generated access-control
//! policy), subscribes to every process's figures, and
//!
//! * builds [`Snapshot`]s from the latest figures of each process:
//!   `stale_cycles` as [`InProcess`](crate::InProcess) computes it, from
//!   the status buffers' stamps the process publishes; a process silent for
//!   more than [`SILENT_AFTER`] shows its CPUs silent and its controllers'
//!   staleness growing with the time since (in its CPU's periods);
//! * sends pause / step N / resume on the process's control key;
//! * sends a root's command as the wire sample the root's process imports
//!   ([`encode`]), with the serial/epoch rules of a supervisor's link
//!   (serials from 1, a fresh epoch per session and at wrap-around), and
//!   sends its latest command again every [`RESEND`] as a bridge does (the
//!   importer drops exact repeats).
//!
//! The console's own session never touches a control cycle: everything
//! here runs on the console's thread and Zenoh's.

pub mod encode;

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use rcs_runtime::bridge::console::{
    control_key, decode_figures, encode_sample, figures_key, random_instance, ExecutiveAction,
    ExecutiveControl, ProcessFigures, OPERATOR,
};
use rcs_runtime::bridge::zenoh::{self, pubsub::Subscriber, Session, Wait};
use rcs_runtime::{BridgeConfig, ErrorCode, Schema, Status};

use crate::catalog::{ArgValue, Catalog};
use crate::model::{ControllerSnapshot, CpuSnapshot, Snapshot};
use crate::source::Source;
use encode::{encode_root_command, Stamps};

/// A process whose figures are older than this is shown silent.
pub const SILENT_AFTER: Duration = Duration::from_secs(1);

/// How often the latest command to a root is sent again.
pub const RESEND: Duration = Duration::from_millis(100);

/// The latest figures of one process.
#[derive(Debug, Default)]
struct Received {
    figures: Option<ProcessFigures>,
    at: Option<Instant>,
    /// The sender's (instance, generation), to drop reordered samples.
    stamps: Option<(u64, u64)>,
}

/// What the subscriber callbacks share with the console.
#[derive(Debug, Default)]
struct Shared {
    /// By process, in the catalog's order.
    processes: Vec<(String, Received)>,
    /// Figures samples refused, and the latest reason.
    refused: u64,
    last_refusal: Option<String>,
}

/// The operator's link to one root.
#[derive(Debug)]
struct RootLink {
    root: String,
    serial: u32,
    epoch: u32,
    /// The latest sample sent, and when.
    last: Option<(Vec<u8>, Instant)>,
}

/// The console attached over Zenoh. See the module docs.
pub struct Remote {
    catalog: Catalog,
    session: Session,
    subscribers: Vec<Subscriber<()>>,
    shared: Arc<Mutex<Shared>>,
    instance: u64,
    controls_sent: u64,
    commands_sent: u64,
    links: Vec<RootLink>,
}

impl std::fmt::Debug for Remote {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Remote")
            .field("system", &self.catalog.system)
            .field("instance", &self.instance)
            .finish()
    }
}

impl Remote {
    /// Open the console's session with `config` (process `operator`, its
    /// certificate, the endpoints of the processes to watch, and the
    /// operator's policy) and subscribe to the figures of every process of
    /// `catalog`'s plan set.
    pub fn connect(catalog: Catalog, config: &BridgeConfig) -> Result<Self, String> {
        if config.process != OPERATOR {
            return Err(format!(
                "the console connects as `{OPERATOR}`, not `{}`",
                config.process
            ));
        }
        if config.system != catalog.system {
            return Err(format!(
                "the connection is for system `{}`, the plan set is `{}`",
                config.system, catalog.system
            ));
        }
        let zenoh_config = config.zenoh_config().map_err(|e| e.to_string())?;
        let session = zenoh::open(zenoh_config)
            .wait()
            .map_err(|e| format!("zenoh: {e}"))?;
        let shared = Arc::new(Mutex::new(Shared {
            processes: catalog
                .processes
                .iter()
                .map(|p| (p.clone(), Received::default()))
                .collect(),
            ..Shared::default()
        }));
        let mut subscribers = Vec::new();
        for process in &catalog.processes {
            let shared = Arc::clone(&shared);
            let name = process.clone();
            let sub = session
                .declare_subscriber(figures_key(&catalog.system, process))
                .callback(move |sample| {
                    receive(&shared, &name, &sample.payload().to_bytes());
                })
                .wait()
                .map_err(|e| format!("zenoh: {e}"))?;
            subscribers.push(sub);
        }
        Ok(Self {
            catalog,
            session,
            subscribers,
            shared,
            instance: random_instance(),
            controls_sent: 0,
            commands_sent: 0,
            links: Vec::new(),
        })
    }

    /// Figures samples refused so far, and why the latest was.
    pub fn refused(&self) -> (u64, Option<String>) {
        let s = lock(&self.shared);
        (s.refused, s.last_refusal.clone())
    }

    /// How many processes' figures have arrived.
    pub fn heard(&self) -> usize {
        lock(&self.shared)
            .processes
            .iter()
            .filter(|(_, r)| r.figures.is_some())
            .count()
    }

    /// The process that runs executive `cpu`, from the figures.
    fn process_of(&self, cpu: &str) -> Result<String, String> {
        lock(&self.shared)
            .processes
            .iter()
            .find(|(_, r)| {
                r.figures
                    .as_ref()
                    .is_some_and(|f| f.executives.iter().any(|e| e.name == cpu))
            })
            .map(|(p, _)| p.clone())
            .ok_or_else(|| format!("no figures from the process that runs CPU `{cpu}` (yet)"))
    }

    fn control(&mut self, cpu: &str, action: ExecutiveAction) -> Result<(), String> {
        let process = self.process_of(cpu)?;
        self.controls_sent += 1;
        let bytes = encode_sample(
            ExecutiveControl::SCHEMA,
            OPERATOR,
            self.instance,
            self.controls_sent,
            self.controls_sent,
            &ExecutiveControl {
                executive: cpu.to_owned(),
                action,
            },
        )?;
        self.session
            .put(control_key(&self.catalog.system, &process), bytes)
            .wait()
            .map_err(|e| format!("zenoh: {e}"))
    }

    /// Send the latest command to each root again (see the module docs).
    fn resend(&mut self) {
        let now = Instant::now();
        for link in &mut self.links {
            if let Some((bytes, at)) = &mut link.last {
                if now.saturating_duration_since(*at) >= RESEND {
                    *at = now;
                    let key = format!(
                        "rcs/{}/{}",
                        self.catalog.system,
                        rcs_runtime::command_buffer_name(&link.root)
                    );
                    let _ = self.session.put(key, bytes.clone()).wait();
                }
            }
        }
    }
}

impl Drop for Remote {
    fn drop(&mut self) {
        for s in self.subscribers.drain(..) {
            let _ = s.undeclare().wait();
        }
        let _ = self.session.close().wait();
    }
}

fn lock(shared: &Mutex<Shared>) -> std::sync::MutexGuard<'_, Shared> {
    shared.lock().unwrap_or_else(|p| p.into_inner())
}

/// A figures sample of `process` arrived (Zenoh's thread).
fn receive(shared: &Mutex<Shared>, process: &str, bytes: &[u8]) {
    let decoded = decode_figures(bytes, process);
    let mut s = lock(shared);
    match decoded {
        Ok((instance, generation, figures)) => {
            let Some((_, r)) = s.processes.iter_mut().find(|(p, _)| p == process) else {
                return;
            };
            // An older sample of the same process instance: keep the newer.
            if r.stamps
                .is_some_and(|(i, g)| i == instance && generation <= g)
            {
                return;
            }
            r.stamps = Some((instance, generation));
            r.figures = Some(figures);
            r.at = Some(Instant::now());
        }
        Err(e) => {
            s.refused += 1;
            s.last_refusal = Some(format!("{process}: {e}"));
        }
    }
}

/// Cycles of a CPU of period `period_ns` in `silent`.
fn cycles_in(silent: Duration, period_ns: u64) -> u64 {
    u64::try_from(silent.as_nanos() / u128::from(period_ns.max(1))).unwrap_or(u64::MAX)
}

impl Source for Remote {
    fn snapshot(&mut self) -> Snapshot {
        self.resend();
        let now = Instant::now();
        let s = lock(&self.shared);
        let mut snap = Snapshot::default();
        for (_, r) in &s.processes {
            let (Some(f), Some(at)) = (&r.figures, r.at) else {
                continue;
            };
            let silent = now
                .saturating_duration_since(at)
                .checked_sub(SILENT_AFTER)
                .map(|_| now.saturating_duration_since(at));
            for e in &f.executives {
                let extra = silent.map_or(0, |d| cycles_in(d, e.period_ns));
                snap.cpus.push(CpuSnapshot {
                    name: e.name.clone(),
                    period_ns: e.period_ns,
                    cycle: e.cycle,
                    paused: e.paused,
                    overruns: e.overruns,
                    missed: e.missed,
                    cycle_last_ns: e.cycle_last_ns,
                    cycle_max_ns: e.cycle_max_ns,
                    lateness_last_ns: e.lateness_last_ns,
                    lateness_max_ns: e.lateness_max_ns,
                    silent_ms: silent.map(|d| u64::try_from(d.as_millis()).unwrap_or(u64::MAX)),
                });
                for c in &e.controllers {
                    // As InProcess: a status written in cycle k is fresh
                    // until cycle k + 1 has run; never written: stale
                    // since the start.
                    let stale_cycles = c.has_status.then(|| {
                        let behind = if c.status_generation == 0 {
                            e.cycle
                        } else {
                            e.cycle
                                .saturating_sub(c.status_writer_cycle.saturating_add(1))
                        };
                        behind.saturating_add(extra)
                    });
                    snap.controllers.push(ControllerSnapshot {
                        name: c.name.clone(),
                        cpu: e.name.clone(),
                        has_plans: c.has_plans,
                        verb: c.verb,
                        state: c.state,
                        status: Status(c.status),
                        error: ErrorCode(c.error),
                        stale_cycles,
                        exec_last_ns: c.exec_last_ns,
                        exec_max_ns: c.exec_max_ns,
                        overruns: c.overruns,
                        panics: c.panics,
                        last_fired: c.last_fired,
                        hits: c.hits.clone(),
                    });
                }
            }
        }
        snap
    }

    fn pause(&mut self, cpu: &str) -> Result<(), String> {
        self.control(cpu, ExecutiveAction::Pause)
    }

    fn step(&mut self, cpu: &str, n: u64) -> Result<(), String> {
        self.control(cpu, ExecutiveAction::Step(n))
    }

    fn resume(&mut self, cpu: &str) -> Result<(), String> {
        self.control(cpu, ExecutiveAction::Resume)
    }

    fn command(&mut self, root: &str, verb: &str, args: &[ArgValue]) -> Result<u32, String> {
        let schema = lock(&self.shared)
            .processes
            .iter()
            .filter_map(|(_, r)| r.figures.as_ref())
            .flat_map(|f| &f.roots)
            .find(|r| r.root == root)
            .map(|r| r.schema)
            .ok_or_else(|| {
                format!("no figures yet from the process that takes {root}'s commands")
            })?;
        let index = match self.links.iter().position(|l| l.root == root) {
            Some(i) => i,
            None => {
                self.links.push(RootLink {
                    root: root.to_owned(),
                    serial: 0,
                    epoch: rcs_runtime::fresh_epoch(),
                    last: None,
                });
                self.links.len() - 1
            }
        };
        let link = &mut self.links[index];
        // As a supervisor's link: serials from 1; after u32::MAX a fresh
        // epoch and serial 1 again.
        let (serial, epoch) = match link.serial.checked_add(1) {
            Some(s) => (s, link.epoch),
            None => (1, rcs_runtime::fresh_epoch()),
        };
        let stamps = Stamps {
            instance: self.instance,
            generation: self.commands_sent + 1,
            serial,
            epoch,
        };
        let bytes = encode_root_command(&self.catalog, schema, root, verb, args, stamps)?;
        let key = format!(
            "rcs/{}/{}",
            self.catalog.system,
            rcs_runtime::command_buffer_name(root)
        );
        self.session
            .put(key, bytes.clone())
            .wait()
            .map_err(|e| format!("zenoh: {e}"))?;
        self.commands_sent += 1;
        link.serial = serial;
        link.epoch = epoch;
        link.last = Some((bytes, Instant::now()));
        Ok(serial)
    }
}
