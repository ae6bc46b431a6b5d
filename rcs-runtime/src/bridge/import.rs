//! The import side: a Zenoh sample → the local cell, in Zenoh's callback.
//!
//! Defence in depth behind the access-control policy: whatever reaches the
//! callback is checked before it touches the cell, in this order — length
//! (before decoding), schema, decoding with nothing left over, the writer
//! process named by the plan set, a generation a writer can have, one
//! instance of the writer at a time, ranges of the value — and each refusal
//! is counted by buffer and kind ([`Bridge::refusals`](super::Bridge::refusals)),
//! never applied, never a panic.
//!
//! The cell's generation is always the local count of imports (one more per
//! sample written), never a number from the wire: a forged or corrupt
//! generation cannot make a reader think the buffer was never written, nor
//! hide a write from the seqlock. The remote stamps are kept here to order
//! samples: a sample not after the last one of the same writer instance is a
//! replay or a reordering and is refused, except an exact resend of the
//! last one, which is dropped silently (it would look like news to the
//! watchdog).

use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use serde::de::DeserializeOwned;
use zenoh::bytes::ZBytes;

use super::{wire, BridgeError, Shared};
use crate::gm::{BufferData, ErasedWriter, Writer};
use crate::schema::Schema;

/// A range check of an imported value: `Err(what)` names the field out of
/// range. Generated code checks status buffers (statuses, error codes,
/// verbs and states that the controller has).
pub type Check<T> = fn(&T) -> Result<(), &'static str>;

/// Where an import writes: the local buffer's own writer, or a root's
/// command writer shared with the local operator.
pub(super) enum Sink<T> {
    Own(Writer<T>),
    Shared(Arc<Mutex<ErasedWriter>>),
}

impl<T: BufferData> Sink<T> {
    fn write(&mut self, value: T, cycle: u64) {
        match self {
            Sink::Own(w) => {
                w.write(value, cycle);
            }
            Sink::Shared(w) => {
                // The operator's writer holds this buffer's type (the
                // bridge takes it for the same `CommandBuffer<C>`).
                w.lock()
                    .unwrap_or_else(|p| p.into_inner())
                    .write(value, cycle);
            }
        }
    }
}

/// The writer instance that owns the buffer now.
#[derive(Debug, Clone, Copy)]
struct Owner {
    instance: u64,
    generation: u64,
    writer_cycle: u64,
    seen: Instant,
}

/// The import side of one buffer, owned by its subscriber's callback.
pub(super) struct Import<T> {
    pub(super) writer: Sink<T>,
    /// The buffer's name, for refusals.
    pub(super) name: String,
    /// The process that writes this buffer in the plan set.
    pub(super) expected_writer: String,
    pub(super) check: Check<T>,
    /// How long the owner must be silent before another instance (a
    /// restarted writer) may take the buffer over.
    pub(super) takeover: Duration,
    owner: Option<Owner>,
    pub(super) shared: Shared,
}

impl<T: BufferData + Schema + DeserializeOwned> Import<T> {
    pub(super) fn new(
        writer: Sink<T>,
        name: String,
        expected_writer: String,
        check: Check<T>,
        takeover: Duration,
        shared: Shared,
    ) -> Self {
        Self {
            writer,
            name,
            expected_writer,
            check,
            takeover,
            owner: None,
            shared,
        }
    }

    pub(super) fn receive(&mut self, payload: &ZBytes) {
        self.shared
            .counters
            .received
            .fetch_add(1, Ordering::Relaxed);
        // Measured before copying: an 8 MiB sample is refused, not copied.
        let max = wire::max_len::<T>();
        let result = if payload.len() > max {
            Err(BridgeError::Oversized {
                buffer: self.name.clone(),
                len: payload.len(),
                max,
            })
        } else {
            self.apply(&payload.to_bytes(), Instant::now())
        };
        if let Err(e) = result {
            let buffer = self.name.clone();
            self.shared.errors.record(&buffer, e);
        }
    }

    /// Check the sample and write it. `Ok` also for a resend dropped.
    fn apply(&mut self, bytes: &[u8], now: Instant) -> Result<(), BridgeError> {
        let buffer = || self.name.clone();
        let (h, value) = decode_checked::<T>(&self.name, bytes, wire::max_len::<T>(), T::SCHEMA)?;
        if h.writer != self.expected_writer {
            return Err(BridgeError::WrongWriter {
                buffer: buffer(),
                expected: self.expected_writer.clone(),
                got: h.writer.chars().take(wire::MAX_NAME).collect(),
            });
        }
        let same_instance = self.owner.filter(|o| o.instance == h.instance);
        let last = same_instance.map_or(0, |o| o.generation);
        if h.generation == 0 || h.generation > wire::MAX_GENERATION {
            return Err(BridgeError::Generation {
                buffer: buffer(),
                got: h.generation,
                last,
            });
        }
        match (self.owner, same_instance) {
            (_, Some(o)) => {
                if (h.generation, h.writer_cycle) == (o.generation, o.writer_cycle) {
                    // A resend of what the cell holds: the owner is alive.
                    self.owner = Some(Owner { seen: now, ..o });
                    return Ok(());
                }
                if h.generation <= o.generation {
                    return Err(BridgeError::Generation {
                        buffer: buffer(),
                        got: h.generation,
                        last,
                    });
                }
            }
            (Some(o), None) if now.saturating_duration_since(o.seen) < self.takeover => {
                return Err(BridgeError::SecondWriter {
                    buffer: buffer(),
                    writer: self.expected_writer.clone(),
                });
            }
            // No owner yet, or the owner fell silent: a (re)started writer.
            _ => {}
        }
        if let Err(what) = (self.check)(&value) {
            return Err(BridgeError::OutOfRange {
                buffer: buffer(),
                what: what.to_owned(),
            });
        }
        self.owner = Some(Owner {
            instance: h.instance,
            generation: h.generation,
            writer_cycle: h.writer_cycle,
            seen: now,
        });
        self.writer.write(value, h.writer_cycle);
        self.shared
            .counters
            .imported
            .fetch_add(1, Ordering::Relaxed);
        Ok(())
    }
}

/// The check of a buffer whose every value is valid.
pub(super) fn any_value<T>(_: &T) -> Result<(), &'static str> {
    Ok(())
}

/// The first checks of every sample taken from the wire, before it is
/// decoded and after: no longer than `max` (the longest encoding of its
/// type), the expected `schema`, decodable with nothing left over. Each
/// refusal names `buffer`.
pub(super) fn decode_checked<'a, T: serde::de::DeserializeOwned>(
    buffer: &str,
    bytes: &'a [u8],
    max: usize,
    schema: u64,
) -> Result<(wire::Header<'a>, T), BridgeError> {
    if bytes.len() > max {
        return Err(BridgeError::Oversized {
            buffer: buffer.to_owned(),
            len: bytes.len(),
            max,
        });
    }
    wire::decode::<T>(bytes, schema).map_err(|e| match e {
        wire::WireError::Schema(got) => BridgeError::SchemaMismatch {
            buffer: buffer.to_owned(),
            expected: schema,
            got,
        },
        wire::WireError::Decode(message) => BridgeError::Decode {
            buffer: buffer.to_owned(),
            message,
        },
        wire::WireError::Trailing(extra) => BridgeError::TrailingBytes {
            buffer: buffer.to_owned(),
            extra,
        },
    })
}
