//! Where the console's [`Snapshot`]s come from and where its actions go:
//! the [`Source`] trait, and [`InProcess`], the attachment to executives
//! running on threads of the console's own process.
//!
//! The Zenoh source, [`Remote`](crate::remote::Remote) (feature `zenoh`),
//! is the console as a process of its own: it reads the figures each
//! process's bridge publishes and sends executive controls and the
//! operator's commands back. The view and the model only ever see this
//! trait.

use std::sync::Arc;

use crate::catalog::ArgValue;
use crate::model::{ControllerSnapshot, CpuSnapshot, Snapshot};
use rcs_runtime::{ExecutiveHandle, ExecutiveMonitor, GlobalMemory, Reader, StatusBuffer};

/// A running system the console watches and acts on.
pub trait Source {
    /// The system now.
    fn snapshot(&mut self) -> Snapshot;
    /// Pause executive `cpu` (its heartbeat keeps ticking, no cycles run).
    fn pause(&mut self, cpu: &str) -> Result<(), String>;
    /// Run `n` more cycles of executive `cpu`, paused (single step: 1).
    fn step(&mut self, cpu: &str, n: u64) -> Result<(), String>;
    /// Let executive `cpu` run freely again.
    fn resume(&mut self, cpu: &str) -> Result<(), String>;
    /// Send root `root` the command `verb(args)` (checked by the caller
    /// against the catalog): the serial sent, or why not.
    fn command(&mut self, root: &str, verb: &str, args: &[ArgValue]) -> Result<u32, String>;
}

/// Sends a checked command to a root through the hand-written program's
/// typed [`Operator`](rcs_runtime::Operator)s (the console knows verbs by
/// name; only the program knows its generated command types).
pub type Commander = Box<dyn FnMut(&str, &str, &[ArgValue]) -> Result<u32, String> + Send>;

/// One executive the console attaches to in-process.
struct Cpu {
    handle: ExecutiveHandle,
    monitor: Arc<ExecutiveMonitor>,
    /// Status readers of its controllers, in monitor order (`None`: the
    /// controller has no status buffer).
    status: Vec<Option<Reader<StatusBuffer>>>,
}

/// Executives on threads of this process: their handles (pause, step, go),
/// monitors (figures) and the status buffers in Global Memory (staleness).
/// Reading takes no lock the executives take: atomics and seqlock reads.
pub struct InProcess {
    cpus: Vec<Cpu>,
    commander: Commander,
}

impl std::fmt::Debug for InProcess {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InProcess")
            .field("cpus", &self.cpus.len())
            .finish()
    }
}

impl InProcess {
    /// Attach to executives through their `handle`s and `monitor`s
    /// ([`rcs_runtime::Executive::attach_monitor`], before spawning), with
    /// `gm` for their controllers' status buffers and `commander` for the
    /// operator's commands.
    pub fn new(
        gm: &GlobalMemory,
        executives: Vec<(ExecutiveHandle, Arc<ExecutiveMonitor>)>,
        commander: Commander,
    ) -> Self {
        let cpus = executives
            .into_iter()
            .map(|(handle, monitor)| Cpu {
                status: monitor
                    .controllers()
                    .iter()
                    .map(|c| gm.status_reader(c.name()).ok())
                    .collect(),
                handle,
                monitor,
            })
            .collect();
        Self { cpus, commander }
    }

    fn cpu(&self, name: &str) -> Result<&Cpu, String> {
        self.cpus
            .iter()
            .find(|c| c.monitor.name() == name)
            .ok_or_else(|| format!("no executive `{name}` in this process"))
    }
}

impl Source for InProcess {
    fn snapshot(&mut self) -> Snapshot {
        let mut snap = Snapshot::default();
        for cpu in &self.cpus {
            let m = &cpu.monitor;
            let cycle = cpu.handle.cycle();
            snap.cpus.push(CpuSnapshot {
                name: m.name().to_owned(),
                period_ns: u64::try_from(m.period().as_nanos()).unwrap_or(u64::MAX),
                cycle,
                paused: cpu.handle.is_paused(),
                overruns: cpu.handle.overruns(),
                missed: cpu.handle.missed_heartbeats(),
                cycle_last_ns: m.cycle_last_ns(),
                cycle_max_ns: m.cycle_max_ns(),
                lateness_last_ns: m.lateness_last_ns(),
                lateness_max_ns: m.lateness_max_ns(),
                silent_ms: None,
            });
            for (c, status) in m.controllers().iter().zip(&cpu.status) {
                let f = c.figures();
                // A status written in cycle k is fresh until cycle k + 1
                // has run; never written: stale since the start.
                let stale_cycles = status.as_ref().map(|r| {
                    let s = r.read();
                    if s.generation == 0 {
                        cycle
                    } else {
                        cycle.saturating_sub(s.writer_cycle.saturating_add(1))
                    }
                });
                let hits = (0..c.verbs())
                    .map(|v| {
                        let v = u16::try_from(v).unwrap_or(u16::MAX);
                        (0..c.rows_per_verb())
                            .map(|r| c.hits(v, u16::try_from(r).unwrap_or(u16::MAX)).unwrap_or(0))
                            .collect()
                    })
                    .collect();
                snap.controllers.push(ControllerSnapshot {
                    name: c.name().to_owned(),
                    cpu: m.name().to_owned(),
                    has_plans: f.has_plans,
                    verb: f.verb,
                    state: f.state,
                    status: f.status,
                    error: f.error,
                    stale_cycles,
                    exec_last_ns: f.exec_last_ns,
                    exec_max_ns: f.exec_max_ns,
                    overruns: f.overruns,
                    panics: f.panics,
                    last_fired: f.last_fired,
                    hits,
                });
            }
        }
        snap
    }

    fn pause(&mut self, cpu: &str) -> Result<(), String> {
        self.cpu(cpu)?.handle.pause();
        Ok(())
    }

    fn step(&mut self, cpu: &str, n: u64) -> Result<(), String> {
        let handle = &self.cpu(cpu)?.handle;
        handle.pause();
        for _ in 0..n {
            handle.step();
        }
        Ok(())
    }

    fn resume(&mut self, cpu: &str) -> Result<(), String> {
        self.cpu(cpu)?.handle.go();
        Ok(())
    }

    fn command(&mut self, root: &str, verb: &str, args: &[ArgValue]) -> Result<u32, String> {
        (self.commander)(root, verb, args)
    }
}
