//! The export side: local cells → Zenoh publishers, off the cycle path.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use serde::Serialize;
use zenoh::pubsub::Publisher;
use zenoh::Wait;

use super::error::Counters;
use super::wire;
use crate::gm::{BufferData, Reader};
use crate::schema::Schema;

/// One exported buffer: its reader and the generation last published.
pub(super) trait Export: Send {
    /// Encode the buffer into `out` if it changed since the last call (or
    /// `resend` and it was ever written); false if there is nothing to send.
    fn poll(&mut self, out: &mut Vec<u8>, resend: bool) -> bool;
}

pub(super) struct ExportSlot<T> {
    pub(super) reader: Reader<T>,
    pub(super) last: u64,
    /// This process's name and the bridge's instance, sent with each sample.
    pub(super) writer: String,
    pub(super) instance: u64,
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
        wire::encode(out, T::SCHEMA, &self.writer, self.instance, &s).is_ok()
    }
}

/// The export thread: poll, publish what changed, sleep.
pub(super) fn export_loop(
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
