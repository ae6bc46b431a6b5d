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
//! * **Export** (local writer → Zenoh): one bridge thread polls the exported
//!   cells' generation every [`BridgeConfig::poll_period`] and publishes a
//!   buffer only when its generation changed, plus every buffer again every
//!   [`BridgeConfig::resend_period`] so that a process that joins late (or
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
//! lock-free, allocation-free seqlock copies; decoding, encoding and Zenoh
//! itself run on the bridge's and Zenoh's threads.

mod wire;

#[cfg(test)]
mod tests;

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serde::de::DeserializeOwned;
use serde::Serialize;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

use crate::gm::{BufferData, GlobalMemory, Reader, Writer};
use crate::schema::Schema;
use crate::SetupError;

/// How a process joins the others: its names and Zenoh endpoints.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BridgeConfig {
    /// The system (the manifest's `system:`): the second part of every key.
    pub system: String,
    /// This process's name (the manifest's `process:`), for thread names
    /// and messages.
    pub process: String,
    /// Zenoh endpoints to listen on, e.g. `tcp/127.0.0.1:7447`.
    pub listen: Vec<String>,
    /// Zenoh endpoints of other processes to connect to (retried in the
    /// background until they answer).
    pub connect: Vec<String>,
    /// Find peers by UDP multicast scouting as well (off: explicit
    /// endpoints only, which is what tests and most plants want).
    pub multicast_scouting: bool,
    /// How often the bridge thread looks for new writes of exported
    /// buffers. `None`: the generated `System::process` puts the period of
    /// the fastest CPU in another process that reads one; a bridge started
    /// with `None` polls every 1 ms.
    pub poll_period: Option<Duration>,
    /// How often every exported buffer is published again even if
    /// unchanged, for processes that join late or restart.
    pub resend_period: Duration,
}

impl BridgeConfig {
    /// A configuration for process `process` of system `system`, with no
    /// endpoints, multicast scouting off, the default polling and a 100 ms
    /// resend.
    pub fn new(system: &str, process: &str) -> Self {
        Self {
            system: system.to_owned(),
            process: process.to_owned(),
            listen: Vec::new(),
            connect: Vec::new(),
            multicast_scouting: false,
            poll_period: None,
            resend_period: Duration::from_millis(100),
        }
    }

    /// Add an endpoint to listen on.
    pub fn listen(mut self, endpoint: &str) -> Self {
        self.listen.push(endpoint.to_owned());
        self
    }

    /// Add an endpoint to connect to.
    pub fn connect(mut self, endpoint: &str) -> Self {
        self.connect.push(endpoint.to_owned());
        self
    }

    /// The key expression of buffer `buffer`: `rcs/<system>/<buffer>`.
    pub fn key(&self, buffer: &str) -> String {
        format!("rcs/{}/{}", self.system, buffer)
    }

    fn zenoh_config(&self) -> Result<zenoh::Config, BridgeError> {
        let list = |v: &[String]| -> Result<String, BridgeError> {
            serde_json::to_string(v).map_err(|e| BridgeError::Zenoh(e.to_string()))
        };
        let mut c = zenoh::Config::default();
        let mut set = |key: &str, value: String| {
            c.insert_json5(key, &value)
                .map_err(|e| BridgeError::Zenoh(format!("config `{key}`: {e}")))
        };
        set("mode", "\"peer\"".into())?;
        set("listen/endpoints", list(&self.listen)?)?;
        set("connect/endpoints", list(&self.connect)?)?;
        set(
            "scouting/multicast/enabled",
            self.multicast_scouting.to_string(),
        )?;
        Ok(c)
    }
}

/// What can go wrong in a bridge: at setup (returned), or with a received
/// sample (recorded, see [`Bridge::errors`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BridgeError {
    /// A sample of `buffer` carried another type's schema hash: the two
    /// processes were built from different declarations. Not written.
    #[error("buffer `{buffer}`: refused a sample of schema {got:#018x}, this process's type has schema {expected:#018x} (were both processes built from the same plan set?)")]
    SchemaMismatch {
        /// The buffer's name.
        buffer: String,
        /// The local type's schema hash.
        expected: u64,
        /// The hash the sample carried.
        got: u64,
    },
    /// A sample of `buffer` could not be decoded. Not written.
    #[error("buffer `{buffer}`: refused an undecodable sample ({message})")]
    Decode {
        /// The buffer's name.
        buffer: String,
        /// What postcard said.
        message: String,
    },
    /// `System::process` was asked for a process the manifest does not name.
    #[error("no process `{name}` in this plan set; its processes are: {}", known.join(", "))]
    UnknownProcess {
        /// The name asked for.
        name: String,
        /// The manifest's processes.
        known: Vec<String>,
    },
    /// Zenoh refused the configuration or a declaration.
    #[error("zenoh: {0}")]
    Zenoh(String),
    /// A buffer to bridge is unknown, of another type, or already written.
    #[error(transparent)]
    Setup(#[from] SetupError),
}

/// The errors received samples caused, the latest per buffer, and how many
/// samples were refused in all. Written by Zenoh's threads, read by the
/// application: a lock is fine here, it is not the cycle path.
#[derive(Default)]
struct ErrorLog {
    latest: Mutex<BTreeMap<String, BridgeError>>,
    refused: AtomicU64,
}

impl ErrorLog {
    fn record(&self, buffer: &str, e: BridgeError) {
        self.refused.fetch_add(1, Ordering::Relaxed);
        let mut map = self.latest.lock().unwrap_or_else(|p| p.into_inner());
        map.insert(buffer.to_owned(), e);
    }
}

/// Counters of a running bridge.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BridgeStats {
    /// Samples published (exports, resends included).
    pub published: u64,
    /// Samples written into local cells (imports).
    pub imported: u64,
    /// Samples refused (schema mismatch or undecodable).
    pub refused: u64,
}

#[derive(Default)]
struct Counters {
    published: AtomicU64,
    imported: AtomicU64,
}

/// One exported buffer: its reader and the generation last published.
trait Export: Send {
    /// Encode the buffer into `out` if it changed since the last call (or
    /// `resend` and it was ever written); false if there is nothing to send.
    fn poll(&mut self, out: &mut Vec<u8>, resend: bool) -> bool;
}

struct ExportSlot<T> {
    reader: Reader<T>,
    last: u64,
}

impl<T: BufferData + Schema + Serialize> Export for ExportSlot<T> {
    fn poll(&mut self, out: &mut Vec<u8>, resend: bool) -> bool {
        let generation = self.reader.generation();
        if generation == 0 || (generation == self.last && !resend) {
            return false;
        }
        let s = self.reader.read();
        self.last = s.generation;
        out.clear();
        wire::encode(out, T::SCHEMA, &s).is_ok()
    }
}

/// An import waiting for [`BridgeBuilder::start`] to declare its subscriber.
type Declare = Box<dyn FnOnce(&Session, &Shared) -> Result<Subscriber<()>, BridgeError>>;

/// What the subscriber callbacks share with the [`Bridge`].
#[derive(Clone)]
struct Shared {
    errors: Arc<ErrorLog>,
    counters: Arc<Counters>,
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
    /// start the export thread.
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
        let exporter = {
            let stop = Arc::clone(&stop);
            let counters = Arc::clone(&shared.counters);
            let poll = self.config.poll_period.unwrap_or(Duration::from_millis(1));
            let resend = self.config.resend_period;
            std::thread::Builder::new()
                .name(format!("rcs-bridge-{}", self.config.process))
                .spawn(move || export_loop(exports, &stop, &counters, poll, resend))
                .map_err(|e| BridgeError::Zenoh(format!("bridge thread: {e}")))?
        };
        Ok(Bridge {
            config: self.config,
            session,
            subscribers,
            stop,
            exporter: Some(exporter),
            shared,
        })
    }
}

/// The export thread: poll, publish what changed, sleep.
fn export_loop(
    mut exports: Vec<(Publisher<'static>, Box<dyn Export>)>,
    stop: &AtomicBool,
    counters: &Counters,
    poll: Duration,
    resend_every: Duration,
) {
    let mut out = Vec::with_capacity(256);
    let mut last_resend = Instant::now();
    while !stop.load(Ordering::Relaxed) {
        let resend = last_resend.elapsed() >= resend_every;
        if resend {
            last_resend = Instant::now();
        }
        for (publisher, slot) in &mut exports {
            if slot.poll(&mut out, resend) && publisher.put(out.as_slice()).wait().is_ok() {
                counters.published.fetch_add(1, Ordering::Relaxed);
            }
        }
        std::thread::sleep(poll);
    }
}

/// The import side of one buffer, owned by its subscriber's callback.
struct Import<T> {
    writer: Writer<T>,
    /// `(generation, writer_cycle)` of the last sample written.
    last: Option<(u64, u64)>,
    shared: Shared,
}

impl<T: BufferData + Schema + DeserializeOwned> Import<T> {
    fn receive(&mut self, bytes: &[u8]) {
        match wire::decode::<T>(bytes, T::SCHEMA) {
            Ok(s) => {
                if self.last == Some((s.generation, s.writer_cycle)) {
                    return; // a resend of what the cell already holds
                }
                self.last = Some((s.generation, s.writer_cycle));
                self.writer
                    .write_stamped(s.value, s.generation, s.writer_cycle);
                self.shared
                    .counters
                    .imported
                    .fetch_add(1, Ordering::Relaxed);
            }
            Err(e) => {
                let buffer = self.writer.name().to_owned();
                let e = match e {
                    wire::WireError::Schema(got) => BridgeError::SchemaMismatch {
                        buffer: buffer.clone(),
                        expected: T::SCHEMA,
                        got,
                    },
                    wire::WireError::Decode(message) => BridgeError::Decode {
                        buffer: buffer.clone(),
                        message,
                    },
                };
                self.shared.errors.record(&buffer, e);
            }
        }
    }
}

/// A running bridge: a Zenoh session, a subscriber per imported buffer and
/// the export thread. Dropping it stops the thread and closes the session.
pub struct Bridge {
    config: BridgeConfig,
    session: Session,
    subscribers: Vec<Subscriber<()>>,
    stop: Arc<AtomicBool>,
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

    /// The name of the export thread, `rcs-bridge-<process>` (what
    /// `/proc/self/task/*/comm` shows, cut to 15 bytes), for measurements.
    pub fn thread_name(&self) -> String {
        format!("rcs-bridge-{}", self.config.process)
    }
}

impl Drop for Bridge {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.exporter.take() {
            let _ = t.join();
        }
        for s in self.subscribers.drain(..) {
            let _ = s.undeclare().wait();
        }
        let _ = self.session.close().wait();
    }
}
