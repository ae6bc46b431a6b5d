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
pub(super) struct ErrorLog {
    pub(super) latest: Mutex<BTreeMap<String, BridgeError>>,
    pub(super) refused: AtomicU64,
}

impl ErrorLog {
    pub(super) fn record(&self, buffer: &str, e: BridgeError) {
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
pub(super) struct Counters {
    pub(super) published: AtomicU64,
    pub(super) imported: AtomicU64,
}
