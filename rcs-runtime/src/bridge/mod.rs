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
//! * **Console** ([`console`]): [`Bridge::serve_console`] publishes the
//!   executives' figures for a remote console (the `operator` identity) and
//!   applies its pause / step / resume, from a thread of the bridge.
//!
//! The cycle path is untouched: an executive's reads and writes stay
//! lock-free, allocation-free seqlock copies, and raising the signal is an
//! atomic swap plus, at most, one futex wake; decoding, encoding and Zenoh
//! itself run on the bridge's and Zenoh's threads.

mod config;
pub mod console;
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

use crate::acl::Security;
use crate::gm::{BufferData, GlobalMemory};
use crate::schema::Schema;
use crate::signal::CycleSignal;

pub use config::BridgeConfig;
pub use error::{BridgeError, BridgeStats, Refusal};
use error::{Counters, ErrorLog};
use export::{export_loop, Export, ExportSlot, Pacing, DEFAULT_FALLBACK_POLL};
pub use import::Check;
use import::{any_value, Import, Sink};

/// The identity (certificate name, and writer name on the wire) of the
/// operator: a console, or any program commanding the roots from another
/// process.
pub const OPERATOR: &str = "operator";
/// The Zenoh this bridge is built on, for programs that open sessions of
/// their own beside it (an operator console, tests playing a rogue peer).
pub use zenoh;

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
    /// This bridge's random instance number, sent with every sample so that
    /// importers tell a restarted (or duplicated) writer apart.
    instance: u64,
    /// The roots whose commands a remote operator may send here, for a
    /// console ([`Bridge::serve_console`]).
    roots: Vec<console::RootCommand>,
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
            Box::new(ExportSlot {
                reader,
                last: 0,
                writer: self.config.process.clone(),
                instance: self.instance,
            }),
        ));
        Ok(self)
    }

    /// Feed the local buffer `buffer` from process `writer`, the one that
    /// writes it in the plan set (samples naming another are refused).
    /// Takes the buffer's one writer, so nothing in this process can write
    /// it too.
    pub fn import<T>(&mut self, buffer: &str, writer: &str) -> Result<&mut Self, BridgeError>
    where
        T: BufferData + Schema + DeserializeOwned + Sync,
    {
        self.import_checked::<T>(buffer, writer, any_value::<T>)
    }

    /// As [`import`](Self::import), refusing values that `check` rejects
    /// (the generated code checks the ranges of status buffers).
    pub fn import_checked<T>(
        &mut self,
        buffer: &str,
        writer: &str,
        check: Check<T>,
    ) -> Result<&mut Self, BridgeError>
    where
        T: BufferData + Schema + DeserializeOwned + Sync,
    {
        let local = Sink::Own(self.gm.writer::<T>(buffer)?);
        self.subscribe(buffer, writer, local, check);
        Ok(self)
    }

    /// Take the commands of a remote operator (a process with the identity
    /// `operator`, such as a console) for root controller `root`, which runs
    /// in this process and whose local operator is `operator`: both write
    /// the root's command buffer through its one writer.
    pub fn import_operator<C>(
        &mut self,
        root: &str,
        operator: &crate::Operator<C>,
    ) -> Result<&mut Self, BridgeError>
    where
        C: crate::handshake::Command + Schema + DeserializeOwned + Sync,
    {
        let name = crate::command_buffer_name(root);
        self.roots.push(console::RootCommand {
            root: root.to_owned(),
            schema: <crate::CommandBuffer<C> as Schema>::SCHEMA,
        });
        self.subscribe(
            &name,
            OPERATOR,
            Sink::Shared(operator.shared_writer()),
            any_value::<crate::CommandBuffer<C>>,
        );
        Ok(self)
    }

    fn subscribe<T>(&mut self, buffer: &str, writer: &str, local: Sink<T>, check: Check<T>)
    where
        T: BufferData + Schema + DeserializeOwned + Sync,
    {
        let key = self.config.key(buffer);
        let expected = writer.to_owned();
        let name = buffer.to_owned();
        // A restarted writer takes the buffer over once the old instance
        // has missed three resends.
        let takeover = self.config.resend_period.saturating_mul(3);
        self.imports.push(Box::new(move |session, shared| {
            let mut import = Import::new(local, name, expected, check, takeover, shared.clone());
            session
                .declare_subscriber(key)
                .callback_mut(move |sample| import.receive(sample.payload()))
                .wait()
                .map_err(|e| BridgeError::Zenoh(e.to_string()))
        }));
    }

    /// Open the Zenoh session, declare the subscribers and publishers, and
    /// start the export thread. Attach [`Bridge::signal`] to the executives
    /// that write exported buffers.
    pub fn start(self) -> Result<Bridge, BridgeError> {
        let zenoh_config = self.config.zenoh_config()?;
        if self.config.security == Security::Insecure {
            eprintln!(
                "rcs-runtime: WARNING: process `{}` of system `{}` runs its bridge WITHOUT TLS, \
                 authentication or access control (BridgeConfig::insecure): anyone who reaches \
                 {} can read every buffer and command every controller",
                self.config.process,
                self.config.system,
                if self.config.listen.is_empty() {
                    "its peers".to_string()
                } else {
                    self.config.listen.join(", ")
                }
            );
        }
        let session = zenoh::open(zenoh_config)
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
            instance: self.instance,
            roots: self.roots,
            console: None,
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
    instance: u64,
    roots: Vec<console::RootCommand>,
    /// The remote console's service, once [`Bridge::serve_console`] ran.
    console: Option<console::ConsoleService>,
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
            instance: random_instance(),
            roots: Vec::new(),
        }
    }

    /// The configuration it was started with.
    pub fn config(&self) -> &BridgeConfig {
        &self.config
    }

    /// The latest refusal of each kind for each buffer, by buffer name.
    /// Empty while all is well.
    pub fn errors(&self) -> Vec<BridgeError> {
        self.shared
            .errors
            .refusals()
            .into_iter()
            .map(|r| r.latest)
            .collect()
    }

    /// Every refused sample, counted by buffer and kind, with the latest
    /// of each (for the console and the importing process's status).
    pub fn refusals(&self) -> Vec<Refusal> {
        self.shared.errors.refusals()
    }

    /// Whether this bridge runs without TLS and access control
    /// ([`BridgeConfig::insecure`]).
    pub fn is_insecure(&self) -> bool {
        self.config.security == Security::Insecure
    }

    /// Counters: samples published, imported, refused.
    pub fn stats(&self) -> BridgeStats {
        BridgeStats {
            published: self.shared.counters.published.load(Ordering::Relaxed),
            imported: self.shared.counters.imported.load(Ordering::Relaxed),
            received: self.shared.counters.received.load(Ordering::Relaxed),
            refused: self.shared.errors.refused.load(Ordering::Relaxed),
        }
    }

    /// How many peer processes this bridge's session is connected to now.
    pub fn peers(&self) -> usize {
        self.session
            .as_ref()
            .map_or(0, |s| s.info().peers_zid().wait().count())
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
        if let Some(mut c) = self.console.take() {
            c.shut_down();
        }
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

    /// Let a remote console (the `operator` identity, under the generated
    /// access-control policy) watch `executives` and pause, step and resume
    /// them ([`console`]): attaches a monitor to each (hit counters for
    /// `rows_per_verb` rows of each verb's plan, the plan set's longest) and
    /// starts publishing their figures, with the stamps of their
    /// controllers' status buffers in `gm`, every
    /// [`console::DISPLAY_PERIOD`] from a thread of the bridge. Call once
    /// the executives are set up, before they run or are spawned (a
    /// program that drives them from its own loop calls
    /// [`Executive::step_unless_paused`](crate::Executive::step_unless_paused)
    /// so that pause and step apply). Calling again replaces the service.
    pub fn serve_console(
        &mut self,
        gm: &GlobalMemory,
        executives: &mut [crate::Executive],
        rows_per_verb: usize,
    ) -> Result<(), BridgeError> {
        let watched = executives
            .iter_mut()
            .map(|e| {
                let monitor = e.attach_monitor(rows_per_verb);
                (e.handle(), monitor)
            })
            .collect();
        self.serve_console_of(gm, watched)
    }

    /// As [`serve_console`](Self::serve_console), for executives whose
    /// monitors are already attached (e.g. shared with an in-process
    /// console).
    pub fn serve_console_of(
        &mut self,
        gm: &GlobalMemory,
        executives: Vec<(crate::ExecutiveHandle, Arc<crate::ExecutiveMonitor>)>,
    ) -> Result<(), BridgeError> {
        if let Some(mut old) = self.console.take() {
            old.shut_down();
        }
        let session = self
            .session
            .as_ref()
            .ok_or_else(|| BridgeError::Zenoh("the bridge is closed".into()))?;
        let watched = executives
            .into_iter()
            .map(|(handle, monitor)| console::serve::Watched::new(gm, handle, monitor))
            .collect();
        self.console = Some(console::ConsoleService::start(
            session,
            &self.config.system,
            &self.config.process,
            self.instance,
            watched,
            self.roots.clone(),
            Arc::clone(&self.shared.errors),
        )?);
        Ok(())
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

/// A random number for this bridge instance: the standard library's
/// randomly keyed hasher over the time and the process id (no dependency,
/// and no need for more than "different from the last run").
fn random_instance() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u128(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos()),
    );
    h.write_u32(std::process::id());
    h.finish()
}
