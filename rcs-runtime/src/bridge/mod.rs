//! Global Memory across processes over Zenoh (feature `zenoh`).
//!
//! Where it sits: beside the executives, off the cycle path. A plan set
//! whose manifest places CPUs in more than one process runs one program per
//! process; each declares every buffer in its own [`GlobalMemory`] and runs a
//! [`Bridge`] that carries the buffers whose writer and readers sit in
//! different processes. Controllers never see the bridge: they read and write
//! their local cells exactly as in one process.
//!
//! * **Keys**: buffer `B` of system `S` travels under the key expression
//!   `rcs/S/B` (for example `rcs/submarine/TB.status`).
//! * **Samples**: postcard of `(schema, generation, writer_cycle, value)`:
//!   the [`Schema::SCHEMA`] of the buffer type, then the writer's stamps,
//!   then the value ([`wire`]).
//! * **Export** (local writer → Zenoh): one bridge thread publishes a
//!   buffer when its generation changed. It sleeps until woken: by the
//!   bridge's [`CycleSignal`] ([`Bridge::signal`]), which every executive
//!   of a generated `System::process` raises at the end of each cycle
//!   ([`Executive::set_cycle_signal`](crate::Executive::set_cycle_signal)),
//!   so a cycle's writes leave at once; by the *fallback poll* every
//!   [`BridgeConfig::poll_period`] (10 ms by default), for writes nobody
//!   signalled (a main loop writing inputs can raise the signal itself);
//!   and by the *resend* every [`BridgeConfig::resend_period`], which
//!   publishes every buffer again so that a process that joins late (or
//!   restarts) gets the latest values. Publishers use
//!   `CongestionControl::Drop`: a value the network cannot take now is
//!   dropped, never queued behind newer ones (commands are not queued,
//!   §3.8.5).
//! * **Import** (Zenoh → local cell): the bridge holds the local buffer's one
//!   [`Writer`](crate::Writer); a subscriber callback decodes the sample and
//!   writes it straight into the seqlock cell *with the remote stamps*, so
//!   `stale_cycles` and the serial handshake behave as in one process. A
//!   resent sample (same generation and cycle as the last one imported) is
//!   not written again: it would look like news to the watchdog. A sample
//!   whose schema hash differs from the local type's is refused: the cell is
//!   not written and [`Bridge::errors`] reports
//!   [`BridgeError::SchemaMismatch`].
//!
//! The cycle path is untouched: an executive's reads and writes stay
//! lock-free, allocation-free seqlock copies, and raising the signal is an
//! atomic swap plus, at most, one futex wake; decoding, encoding and Zenoh
//! itself run on the bridge's and Zenoh's threads.

mod config;
mod error;
mod export;
mod import;
mod wire;

#[cfg(test)]
mod event_tests;
#[cfg(test)]
mod tests;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

use serde::de::DeserializeOwned;
use serde::Serialize;
use zenoh::pubsub::Subscriber;
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

use crate::gm::{BufferData, GlobalMemory};
use crate::schema::Schema;
use crate::signal::CycleSignal;

pub use config::BridgeConfig;
pub use error::{BridgeError, BridgeStats};
use error::{Counters, ErrorLog};
use export::{export_loop, Export, ExportSlot, Pacing, DEFAULT_FALLBACK_POLL};
use import::Import;

/// An import waiting for [`BridgeBuilder::start`] to declare its subscriber.
type Declare = Box<dyn FnOnce(&Session, &Shared) -> Result<Subscriber<()>, BridgeError>>;

/// What the subscriber callbacks share with the [`Bridge`].
#[derive(Clone)]
struct Shared {
    pub(super) errors: Arc<ErrorLog>,
    pub(super) counters: Arc<Counters>,
}

/// Collects the buffers to export and import, then starts the [`Bridge`].
pub struct BridgeBuilder<'a> {
    config: BridgeConfig,
    gm: &'a GlobalMemory,
    exports: Vec<(String, Box<dyn Export>)>,
    imports: Vec<Declare>,
}

impl std::fmt::Debug for BridgeBuilder<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BridgeBuilder")
            .field("config", &self.config)
            .field("exports", &self.exports.len())
            .field("imports", &self.imports.len())
            .finish()
    }
}

impl<'a> BridgeBuilder<'a> {
    /// Publish the local buffer `buffer` (written in this process) for the
    /// other processes. Takes a reader of it.
    pub fn export<T>(&mut self, buffer: &str) -> Result<&mut Self, BridgeError>
    where
        T: BufferData + Schema + Serialize + Sync,
    {
        let reader = self.gm.reader::<T>(buffer)?;
        self.exports.push((
            self.config.key(buffer),
            Box::new(ExportSlot { reader, last: 0 }),
        ));
        Ok(self)
    }

    /// Feed the local buffer `buffer` from the process that writes it.
    /// Takes the buffer's one writer, so nothing in this process can write
    /// it too.
    pub fn import<T>(&mut self, buffer: &str) -> Result<&mut Self, BridgeError>
    where
        T: BufferData + Schema + DeserializeOwned + Sync,
    {
        let writer = self.gm.writer::<T>(buffer)?;
        let key = self.config.key(buffer);
        self.imports.push(Box::new(move |session, shared| {
            let mut import = Import {
                writer,
                last: None,
                shared: shared.clone(),
            };
            session
                .declare_subscriber(key)
                .callback_mut(move |sample| import.receive(&sample.payload().to_bytes()))
                .wait()
                .map_err(|e| BridgeError::Zenoh(e.to_string()))
        }));
        Ok(self)
    }

    /// Open the Zenoh session, declare the subscribers and publishers, and
    /// start the export thread. Attach [`Bridge::signal`] to the executives
    /// that write exported buffers.
    pub fn start(self) -> Result<Bridge, BridgeError> {
        let session = zenoh::open(self.config.zenoh_config()?)
            .wait()
            .map_err(|e| BridgeError::Zenoh(e.to_string()))?;
        let shared = Shared {
            errors: Arc::default(),
            counters: Arc::default(),
        };
        let subscribers = self
            .imports
            .into_iter()
            .map(|declare| declare(&session, &shared))
            .collect::<Result<Vec<_>, _>>()?;
        let mut exports = Vec::new();
        for (key, slot) in self.exports {
            let publisher = session
                .declare_publisher(key)
                .congestion_control(CongestionControl::Drop)
                .wait()
                .map_err(|e| BridgeError::Zenoh(e.to_string()))?;
            exports.push((publisher, slot));
        }
        let stop = Arc::new(AtomicBool::new(false));
        let signal = CycleSignal::new();
        let exporter = {
            let stop = Arc::clone(&stop);
            let signal = signal.clone();
            let counters = Arc::clone(&shared.counters);
            let pacing = Pacing {
                fallback_poll: self.config.poll_period.unwrap_or(DEFAULT_FALLBACK_POLL),
                resend: self.config.resend_period,
            };
            std::thread::Builder::new()
                .name(format!("rcs-bridge-{}", self.config.process))
                .spawn(move || export_loop(exports, &stop, &signal, &counters, pacing))
                .map_err(|e| BridgeError::Zenoh(format!("bridge thread: {e}")))?
        };
        Ok(Bridge {
            config: self.config,
            session: Some(session),
            subscribers,
            stop,
            signal,
            exporter: Some(exporter),
            shared,
        })
    }
}

/// A running bridge: a Zenoh session, a subscriber per imported buffer and
/// the export thread. Dropping it stops the thread and closes the session.
pub struct Bridge {
    config: BridgeConfig,
    /// `None` once closed.
    session: Option<Session>,
    subscribers: Vec<Subscriber<()>>,
    stop: Arc<AtomicBool>,
    signal: CycleSignal,
    exporter: Option<JoinHandle<()>>,
    shared: Shared,
}

impl std::fmt::Debug for Bridge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bridge")
            .field("config", &self.config)
            .field("stats", &self.stats())
            .finish()
    }
}

impl Bridge {
    /// Start describing a bridge for `gm` with `config`.
    pub fn builder(config: BridgeConfig, gm: &GlobalMemory) -> BridgeBuilder<'_> {
        BridgeBuilder {
            config,
            gm,
            exports: Vec::new(),
            imports: Vec::new(),
        }
    }

    /// The configuration it was started with.
    pub fn config(&self) -> &BridgeConfig {
        &self.config
    }

    /// The latest error each buffer's received samples caused, by buffer
    /// name. Empty while all is well.
    pub fn errors(&self) -> Vec<BridgeError> {
        let map = self
            .shared
            .errors
            .latest
            .lock()
            .unwrap_or_else(|p| p.into_inner());
        map.values().cloned().collect()
    }

    /// Counters: samples published, imported, refused.
    pub fn stats(&self) -> BridgeStats {
        BridgeStats {
            published: self.shared.counters.published.load(Ordering::Relaxed),
            imported: self.shared.counters.imported.load(Ordering::Relaxed),
            refused: self.shared.errors.refused.load(Ordering::Relaxed),
        }
    }

    /// The signal that wakes the export thread: raise it after writing
    /// exported buffers and they are published at once, instead of at the
    /// next fallback poll ([`BridgeConfig::poll_period`]). Give a clone to
    /// each executive ([`Executive::set_cycle_signal`](crate::Executive::set_cycle_signal),
    /// as the generated `System::process` does) and to any loop that writes
    /// exported buffers outside an executive. Raising is lock- and
    /// allocation-free.
    pub fn signal(&self) -> CycleSignal {
        self.signal.clone()
    }

    /// Stop the export thread, undeclare the subscribers, close the session
    /// and return the final counters (every publish the thread made is
    /// counted by then). Dropping the bridge does the same.
    pub fn close(mut self) -> BridgeStats {
        self.shut_down();
        self.stats()
    }

    fn shut_down(&mut self) {
        self.stop.store(true, Ordering::Release);
        self.signal.raise();
        if let Some(t) = self.exporter.take() {
            let _ = t.join();
        }
        for s in self.subscribers.drain(..) {
            let _ = s.undeclare().wait();
        }
        if let Some(session) = self.session.take() {
            let _ = session.close().wait();
        }
    }

    /// The name of the export thread, `rcs-bridge-<process>` (what
    /// `/proc/self/task/*/comm` shows, cut to 15 bytes), for measurements.
    pub fn thread_name(&self) -> String {
        format!("rcs-bridge-{}", self.config.process)
    }
}

impl Drop for Bridge {
    fn drop(&mut self) {
        self.shut_down();
    }
}
