//! The process side of a remote console: the figures thread and the
//! control subscriber (see the module docs of [`super`]).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

use zenoh::pubsub::Subscriber;
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

use super::{
    ControllerFiguresWire, ExecutiveAction, ExecutiveControl, ExecutiveFigures, ProcessFigures,
    RootCommand, CONTROL, CONTROL_MAX_LEN, DISPLAY_PERIOD, MAX_STEPS, OPERATOR,
};
use crate::bridge::error::ErrorLog;
use crate::bridge::{wire, BridgeError};
use crate::gm::{GlobalMemory, Reader};
use crate::handshake::StatusBuffer;
use crate::schema::Schema;
use crate::{ExecutiveHandle, ExecutiveMonitor};

/// One executive a console watches: its handle, its monitor, and its
/// controllers' status readers in monitor order.
pub(in crate::bridge) struct Watched {
    handle: ExecutiveHandle,
    monitor: Arc<ExecutiveMonitor>,
    status: Vec<Option<Reader<StatusBuffer>>>,
}

impl Watched {
    pub(in crate::bridge) fn new(
        gm: &GlobalMemory,
        handle: ExecutiveHandle,
        monitor: Arc<ExecutiveMonitor>,
    ) -> Self {
        let status = monitor
            .controllers()
            .iter()
            .map(|c| gm.status_reader(c.name()).ok())
            .collect();
        Self {
            handle,
            monitor,
            status,
        }
    }

    fn figures(&self) -> ExecutiveFigures {
        let m = &self.monitor;
        let h = &self.handle;
        ExecutiveFigures {
            name: m.name().to_owned(),
            period_ns: u64::try_from(m.period().as_nanos()).unwrap_or(u64::MAX),
            cycle: h.cycle(),
            paused: h.is_paused(),
            pending_steps: h.pending_steps(),
            overruns: h.overruns(),
            missed: h.missed_heartbeats(),
            cycle_last_ns: m.cycle_last_ns(),
            cycle_max_ns: m.cycle_max_ns(),
            lateness_last_ns: m.lateness_last_ns(),
            lateness_max_ns: m.lateness_max_ns(),
            controllers: m
                .controllers()
                .iter()
                .zip(&self.status)
                .map(|(c, status)| {
                    let f = c.figures();
                    let s = status.as_ref().map(Reader::read);
                    let narrow = |v: usize| u16::try_from(v).unwrap_or(u16::MAX);
                    ControllerFiguresWire {
                        name: c.name().to_owned(),
                        has_plans: f.has_plans,
                        verb: f.verb,
                        state: f.state,
                        status: f.status.0,
                        error: f.error.0,
                        last_fired: f.last_fired,
                        exec_last_ns: f.exec_last_ns,
                        exec_max_ns: f.exec_max_ns,
                        overruns: f.overruns,
                        panics: f.panics,
                        status_generation: s.map_or(0, |s| s.generation),
                        status_writer_cycle: s.map_or(0, |s| s.writer_cycle),
                        has_status: s.is_some(),
                        hits: (0..c.verbs())
                            .map(|v| {
                                (0..c.rows_per_verb())
                                    .map(|r| c.hits(narrow(v), narrow(r)).unwrap_or(0))
                                    .collect()
                            })
                            .collect(),
                    }
                })
                .collect(),
        }
    }
}

/// Every watched executive's figures and the operator's roots, now.
pub(in crate::bridge) fn process_figures(
    watched: &[Watched],
    roots: &[RootCommand],
) -> ProcessFigures {
    ProcessFigures {
        executives: watched.iter().map(Watched::figures).collect(),
        roots: roots.to_vec(),
    }
}

/// The control subscriber's state: the executives by name, and the last
/// control taken (sender instance, generation) to refuse replays.
pub(in crate::bridge) struct ControlImport {
    executives: Vec<(String, ExecutiveHandle)>,
    last: Option<(u64, u64)>,
    errors: Arc<ErrorLog>,
}

impl ControlImport {
    pub(in crate::bridge) fn new(
        executives: Vec<(String, ExecutiveHandle)>,
        errors: Arc<ErrorLog>,
    ) -> Self {
        Self {
            executives,
            last: None,
            errors,
        }
    }

    /// Check and apply one control sample; a refusal is recorded.
    pub(in crate::bridge) fn receive(&mut self, bytes: &[u8]) {
        if let Err(e) = self.apply(bytes) {
            self.errors.record(CONTROL, e);
        }
    }

    fn apply(&mut self, bytes: &[u8]) -> Result<(), BridgeError> {
        let buffer = || CONTROL.to_owned();
        let (h, control) = crate::bridge::import::decode_checked::<ExecutiveControl>(
            CONTROL,
            bytes,
            CONTROL_MAX_LEN,
            ExecutiveControl::SCHEMA,
        )?;
        if h.writer != OPERATOR {
            return Err(BridgeError::WrongWriter {
                buffer: buffer(),
                expected: OPERATOR.to_owned(),
                got: h.writer.chars().take(wire::MAX_NAME).collect(),
            });
        }
        // A control is an event, not a value: a replayed or reordered one
        // of the same console must not pause or step again.
        let last = self
            .last
            .filter(|(instance, _)| *instance == h.instance)
            .map_or(0, |(_, g)| g);
        if h.generation == 0 || h.generation > wire::MAX_GENERATION || h.generation <= last {
            return Err(BridgeError::Generation {
                buffer: buffer(),
                got: h.generation,
                last,
            });
        }
        let Some((_, handle)) = self
            .executives
            .iter()
            .find(|(name, _)| *name == control.executive)
        else {
            return Err(BridgeError::OutOfRange {
                buffer: buffer(),
                what: format!(
                    "no executive `{}` in this process",
                    control
                        .executive
                        .chars()
                        .take(wire::MAX_NAME)
                        .collect::<String>()
                ),
            });
        };
        match control.action {
            ExecutiveAction::Pause => handle.pause(),
            ExecutiveAction::Resume => handle.go(),
            ExecutiveAction::Step(n) if (1..=MAX_STEPS).contains(&n) => handle.step_by(n),
            ExecutiveAction::Step(n) => {
                return Err(BridgeError::OutOfRange {
                    buffer: buffer(),
                    what: format!("step {n} (1 to {MAX_STEPS})"),
                })
            }
        }
        self.last = Some((h.instance, h.generation));
        Ok(())
    }
}

/// A running console service of a bridge: the figures thread and the
/// control subscriber. Shut down before the bridge's session closes.
pub(in crate::bridge) struct ConsoleService {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    subscriber: Option<Subscriber<()>>,
}

impl ConsoleService {
    /// Declare the publisher and the subscriber on `session` and start the
    /// figures thread.
    pub(in crate::bridge) fn start(
        session: &Session,
        system: &str,
        process: &str,
        instance: u64,
        watched: Vec<Watched>,
        roots: Vec<RootCommand>,
        errors: Arc<ErrorLog>,
    ) -> Result<Self, BridgeError> {
        let zenoh_err = |e: zenoh::Error| BridgeError::Zenoh(e.to_string());
        let mut control = ControlImport::new(
            watched
                .iter()
                .map(|w| (w.monitor.name().to_owned(), w.handle.clone()))
                .collect(),
            errors,
        );
        let subscriber = session
            .declare_subscriber(super::control_key(system, process))
            .callback_mut(move |sample| control.receive(&sample.payload().to_bytes()))
            .wait()
            .map_err(zenoh_err)?;
        let publisher = session
            .declare_publisher(super::figures_key(system, process))
            .congestion_control(CongestionControl::Drop)
            .wait()
            .map_err(zenoh_err)?;
        let stop = Arc::new(AtomicBool::new(false));
        let thread = {
            let stop = Arc::clone(&stop);
            let writer = process.to_owned();
            std::thread::Builder::new()
                .name(format!("rcs-console-{process}"))
                .spawn(move || {
                    let mut tick = 0u64;
                    while !stop.load(Ordering::Acquire) {
                        tick += 1;
                        let figures = process_figures(&watched, &roots);
                        if let Ok(bytes) = super::encode_sample(
                            ProcessFigures::SCHEMA,
                            &writer,
                            instance,
                            tick,
                            tick,
                            &figures,
                        ) {
                            let _ = publisher.put(bytes).wait();
                        }
                        std::thread::park_timeout(DISPLAY_PERIOD);
                    }
                })
                .map_err(|e| BridgeError::Zenoh(format!("console thread: {e}")))?
        };
        Ok(Self {
            stop,
            thread: Some(thread),
            subscriber: Some(subscriber),
        })
    }

    pub(in crate::bridge) fn shut_down(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            t.thread().unpark();
            let _ = t.join();
        }
        if let Some(s) = self.subscriber.take() {
            let _ = s.undeclare().wait();
        }
    }
}

/// The largest figures sample a console accepts (a process of a thousand
/// controllers fits many times over).
pub const MAX_FIGURES_LEN: usize = 8 << 20;

/// Why a figures sample was not taken.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ConsoleFiguresError {
    /// Longer than [`MAX_FIGURES_LEN`].
    #[error("a figures sample of {0} bytes (at most {MAX_FIGURES_LEN})")]
    Oversized(usize),
    /// Another schema: the process runs another version of rcs-runtime.
    #[error("figures of schema {got:#018x}, this console reads {expected:#018x}")]
    Schema {
        /// This console's.
        expected: u64,
        /// The sample's.
        got: u64,
    },
    /// Not figures.
    #[error("undecodable figures: {0}")]
    Decode(String),
    /// Signed by another process than the key names.
    #[error("figures of process `{expected}` signed by `{got}`")]
    WrongWriter {
        /// The process the key names.
        expected: String,
        /// The one the sample names.
        got: String,
    },
}

/// Decode a figures sample of process `process` (console side): the
/// sender's instance and generation, and the figures.
pub fn decode_figures(
    bytes: &[u8],
    process: &str,
) -> Result<(u64, u64, ProcessFigures), ConsoleFiguresError> {
    if bytes.len() > MAX_FIGURES_LEN {
        return Err(ConsoleFiguresError::Oversized(bytes.len()));
    }
    let (h, figures) =
        wire::decode::<ProcessFigures>(bytes, ProcessFigures::SCHEMA).map_err(|e| match e {
            wire::WireError::Schema(got) => ConsoleFiguresError::Schema {
                expected: ProcessFigures::SCHEMA,
                got,
            },
            wire::WireError::Decode(m) => ConsoleFiguresError::Decode(m),
            wire::WireError::Trailing(n) => {
                ConsoleFiguresError::Decode(format!("{n} bytes after the figures"))
            }
        })?;
    if h.writer != process {
        return Err(ConsoleFiguresError::WrongWriter {
            expected: process.to_owned(),
            got: h.writer.chars().take(wire::MAX_NAME).collect(),
        });
    }
    Ok((h.instance, h.generation, figures))
}
