//! The import side: a Zenoh sample → the local cell, in Zenoh's callback.

use std::sync::atomic::Ordering;

use serde::de::DeserializeOwned;

use super::{wire, BridgeError, Shared};
use crate::gm::{BufferData, Writer};
use crate::schema::Schema;

/// The import side of one buffer, owned by its subscriber's callback.
pub(super) struct Import<T> {
    pub(super) writer: Writer<T>,
    /// `(generation, writer_cycle)` of the last sample written.
    pub(super) last: Option<(u64, u64)>,
    pub(super) shared: Shared,
}

impl<T: BufferData + Schema + DeserializeOwned> Import<T> {
    pub(super) fn receive(&mut self, bytes: &[u8]) {
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
