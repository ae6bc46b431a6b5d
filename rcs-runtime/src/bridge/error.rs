//! What a bridge reports: setup errors, refused samples and counters.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use crate::SetupError;

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
    /// A sample of `buffer` was longer than any encoding of its type can be
    /// (a flood of junk, or a sender built from another plan set). Not
    /// decoded.
    #[error("buffer `{buffer}`: refused a sample of {len} bytes (at most {max} for its type)")]
    Oversized {
        /// The buffer's name.
        buffer: String,
        /// The sample's length.
        len: usize,
        /// The longest encoding the type allows.
        max: usize,
    },
    /// A sample of `buffer` had bytes after its value. Not written.
    #[error("buffer `{buffer}`: refused a sample with {extra} bytes after its value")]
    TrailingBytes {
        /// The buffer's name.
        buffer: String,
        /// How many.
        extra: usize,
    },
    /// A sample of `buffer` named a writer process that does not write it
    /// in this plan set. Not written.
    #[error(
        "buffer `{buffer}`: refused a sample from process `{got}`; only `{expected}` writes it"
    )]
    WrongWriter {
        /// The buffer's name.
        buffer: String,
        /// The process that writes it in this plan set.
        expected: String,
        /// The process the sample named.
        got: String,
    },
    /// A sample of `buffer` came from a second instance of its writer
    /// process while the first is still alive (two processes with one
    /// identity). Not written; the first keeps the buffer until it has been
    /// silent for three resend periods (then a restarted writer takes
    /// over).
    #[error("buffer `{buffer}`: refused a sample from a second instance of process `{writer}` while the first is alive")]
    SecondWriter {
        /// The buffer's name.
        buffer: String,
        /// The writer process.
        writer: String,
    },
    /// A sample of `buffer` carried a generation that cannot be a writer's
    /// (0, or beyond what any writer reaches) or one not after the last
    /// sample of the same writer (a replay or reordering). Not written.
    #[error(
        "buffer `{buffer}`: refused generation {got} (last accepted from this writer: {last})"
    )]
    Generation {
        /// The buffer's name.
        buffer: String,
        /// The generation the sample carried.
        got: u64,
        /// The last generation accepted from the same writer instance (0:
        /// none).
        last: u64,
    },
    /// A sample of `buffer` decoded, but a field is outside what its
    /// controller can write (a status, error code, verb or state that does
    /// not exist). Not written.
    #[error("buffer `{buffer}`: refused a value out of range ({what})")]
    OutOfRange {
        /// The buffer's name.
        buffer: String,
        /// Which check failed.
        what: String,
    },
    /// A bridge was started without choosing its security (mutual TLS, or
    /// the explicit opt-out).
    #[error("process `{process}`: no identity; give the bridge certificates (`BridgeConfig::certs(DIR)`, made with `rcsc certs DIR`) or opt out with `BridgeConfig::insecure()`")]
    NoIdentity {
        /// The process.
        process: String,
    },
    /// The identity or policy cannot be used (a missing file, a plain
    /// endpoint under TLS, a malformed policy).
    #[error("security: {0}")]
    Identity(String),
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

impl BridgeError {
    /// A short name of the kind of error, for counting refusals by kind.
    pub fn kind(&self) -> &'static str {
        match self {
            BridgeError::SchemaMismatch { .. } => "schema",
            BridgeError::Decode { .. } => "decode",
            BridgeError::Oversized { .. } => "oversized",
            BridgeError::TrailingBytes { .. } => "trailing_bytes",
            BridgeError::WrongWriter { .. } => "wrong_writer",
            BridgeError::SecondWriter { .. } => "second_writer",
            BridgeError::Generation { .. } => "generation",
            BridgeError::OutOfRange { .. } => "out_of_range",
            BridgeError::NoIdentity { .. } => "no_identity",
            BridgeError::Identity(_) => "identity",
            BridgeError::UnknownProcess { .. } => "unknown_process",
            BridgeError::Zenoh(_) => "zenoh",
            BridgeError::Setup(_) => "setup",
        }
    }
}

/// Refused samples of one buffer for one reason: how many, and the latest.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refusal {
    /// The buffer.
    pub buffer: String,
    /// [`BridgeError::kind`] of the refusals counted here.
    pub kind: &'static str,
    /// How many samples were refused so.
    pub count: u64,
    /// The latest of them.
    pub latest: BridgeError,
}

/// Refusals by `(buffer, kind)`: how many, and the latest.
type RefusalCounts = BTreeMap<(String, &'static str), (u64, BridgeError)>;

/// Every refusal, counted by buffer and kind. Written by Zenoh's threads,
/// read by the application: a lock is fine here, it is not the cycle path.
#[derive(Default)]
pub(super) struct ErrorLog {
    pub(super) by_buffer: Mutex<RefusalCounts>,
    pub(super) refused: AtomicU64,
}

impl ErrorLog {
    pub(super) fn record(&self, buffer: &str, e: BridgeError) {
        self.refused.fetch_add(1, Ordering::Relaxed);
        let mut map = self.by_buffer.lock().unwrap_or_else(|p| p.into_inner());
        let entry = map
            .entry((buffer.to_owned(), e.kind()))
            .or_insert_with(|| (0, e.clone()));
        entry.0 = entry.0.saturating_add(1);
        entry.1 = e;
    }

    pub(super) fn refusals(&self) -> Vec<Refusal> {
        let map = self.by_buffer.lock().unwrap_or_else(|p| p.into_inner());
        map.iter()
            .map(|((buffer, kind), (count, latest))| Refusal {
                buffer: buffer.clone(),
                kind,
                count: *count,
                latest: latest.clone(),
            })
            .collect()
    }
}

/// Counters of a running bridge.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BridgeStats {
    /// Samples published (exports, resends included).
    pub published: u64,
    /// Samples written into local cells (imports).
    pub imported: u64,
    /// Samples received for imported buffers (written, refused, or a
    /// resend of what the cell holds).
    pub received: u64,
    /// Samples refused ([`Bridge::refusals`](super::Bridge::refusals) says
    /// which and why).
    pub refused: u64,
}

#[derive(Default)]
pub(super) struct Counters {
    pub(super) published: AtomicU64,
    pub(super) imported: AtomicU64,
    pub(super) received: AtomicU64,
}
