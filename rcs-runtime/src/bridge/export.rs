//! The export side: local cells → Zenoh publishers, off the cycle path.
//!
//! One thread per bridge. It sleeps on the bridge's [`CycleSignal`] and
//! wakes when an executive raises it at the end of a cycle (or anyone else
//! does, e.g. a main loop after writing inputs), then publishes every
//! exported buffer whose generation changed since it last looked. Two
//! timers wake it too: the *fallback poll* (for writes nobody signalled)
//! and the *resend* (every buffer ever written, for late joiners).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use serde::Serialize;
use zenoh::pubsub::Publisher;
use zenoh::Wait;

use super::error::Counters;
use super::wire;
use crate::gm::{BufferData, Reader};
use crate::schema::Schema;
use crate::signal::CycleSignal;

/// The fallback poll of a bridge whose [`poll_period`] is `None`.
///
/// [`poll_period`]: super::BridgeConfig::poll_period
pub(super) const DEFAULT_FALLBACK_POLL: Duration = Duration::from_millis(10);

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

/// One pass over the exports: `put` the sample of every buffer that changed
/// (every buffer ever written if `resend`). Returns how many `put` took.
/// Generic over the publisher so that the pass is tested without Zenoh.
pub(super) fn publish_changed<P>(
    exports: &mut [(P, Box<dyn Export>)],
    out: &mut Vec<u8>,
    resend: bool,
    mut put: impl FnMut(&P, &[u8]) -> bool,
) -> u64 {
    let mut published = 0;
    for (publisher, slot) in exports.iter_mut() {
        if slot.poll(out, resend) && put(publisher, out.as_slice()) {
            published += 1;
        }
    }
    published
}

/// How the export thread is paced besides the signal.
#[derive(Debug, Clone, Copy)]
pub(super) struct Pacing {
    /// Look for unsignalled writes this often.
    pub(super) fallback_poll: Duration,
    /// Publish every written buffer again this often.
    pub(super) resend: Duration,
}

/// `now + d`, or a day on if that is past what `Instant` holds (a period
/// of `Duration::MAX` means "never", not a panic).
fn later(now: Instant, d: Duration) -> Instant {
    now.checked_add(d)
        .or_else(|| now.checked_add(Duration::from_secs(86_400)))
        .unwrap_or(now)
}

/// The export thread: publish what changed, then wait for the signal, the
/// fallback poll or the resend, whichever comes first; until `stop` (which
/// the bridge sets and then raises the signal, so the thread ends at once).
pub(super) fn export_loop(
    mut exports: Vec<(Publisher<'static>, Box<dyn Export>)>,
    stop: &AtomicBool,
    signal: &CycleSignal,
    counters: &Counters,
    pacing: Pacing,
) {
    let mut out = Vec::with_capacity(256);
    let mut next_resend = later(Instant::now(), pacing.resend);
    while !stop.load(Ordering::Acquire) {
        let now = Instant::now();
        let resend = now >= next_resend;
        if resend {
            next_resend = later(now, pacing.resend);
        }
        publish_changed(&mut exports, &mut out, resend, |publisher, bytes| {
            let ok = publisher.put(bytes).wait().is_ok();
            if ok {
                counters.published.fetch_add(1, Ordering::Relaxed);
            }
            ok
        });
        let now = Instant::now();
        let wake = later(now, pacing.fallback_poll).min(next_resend);
        signal.wait(wake.saturating_duration_since(now));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gm::GlobalMemory;

    fn slot(gm: &GlobalMemory, name: &str) -> (String, Box<dyn Export>) {
        let reader = gm.reader::<u64>(name).expect("declared");
        (
            name.to_owned(),
            Box::new(ExportSlot {
                reader,
                last: 0,
                writer: "p".to_owned(),
                instance: 1,
            }),
        )
    }

    /// The names `publish_changed` put, in order.
    fn pass(exports: &mut [(String, Box<dyn Export>)], resend: bool) -> Vec<String> {
        let mut out = Vec::new();
        let mut names = Vec::new();
        let n = publish_changed(exports, &mut out, resend, |name, bytes| {
            assert!(!bytes.is_empty());
            names.push(name.clone());
            true
        });
        assert_eq!(n as usize, names.len());
        names
    }

    #[test]
    fn only_buffers_whose_generation_changed_are_published() {
        let gm = GlobalMemory::new();
        for name in ["a", "b", "c"] {
            gm.declare::<u64>(name).expect("declare");
        }
        let mut a = gm.writer::<u64>("a").expect("writer");
        let mut b = gm.writer::<u64>("b").expect("writer");
        let mut exports = vec![slot(&gm, "a"), slot(&gm, "b"), slot(&gm, "c")];
        assert!(pass(&mut exports, false).is_empty(), "nothing written");
        assert!(pass(&mut exports, true).is_empty(), "nothing to resend");
        a.write(1, 1);
        assert_eq!(pass(&mut exports, false), ["a"]);
        assert!(pass(&mut exports, false).is_empty(), "a unchanged");
        b.write(2, 2);
        b.write(3, 3); // two writes between passes: one sample, the newest
        assert_eq!(pass(&mut exports, false), ["b"]);
        // The resend carries every buffer ever written, c never.
        assert_eq!(pass(&mut exports, true), ["a", "b"]);
        assert!(pass(&mut exports, false).is_empty());
    }

    #[test]
    fn a_put_that_fails_is_not_counted() {
        let gm = GlobalMemory::new();
        gm.declare::<u64>("a").expect("declare");
        gm.writer::<u64>("a").expect("writer").write(1, 1);
        let mut exports = vec![slot(&gm, "a")];
        let mut out = Vec::new();
        assert_eq!(
            publish_changed(&mut exports, &mut out, false, |_, _| false),
            0
        );
    }

    #[test]
    fn a_period_past_what_instant_holds_is_a_day() {
        let now = Instant::now();
        assert_eq!(later(now, Duration::MAX), now + Duration::from_secs(86_400));
        assert_eq!(
            later(now, Duration::from_secs(1)),
            now + Duration::from_secs(1)
        );
    }
}
