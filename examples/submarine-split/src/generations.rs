//! `--report-generations`: does anything the bridge imports arrive out of
//! order?
//!
//! Where it sits: in the loop of `helm` and `engine` (`split.rs`), once per
//! cycle, beside the executive. The bridge writes each imported sample into
//! the local cell with the remote writer's stamps; the local generation can
//! never go back (the cell keeps the larger one), so a sample applied after a
//! newer one shows as the *writer's cycle stamp* going back while the
//! generation moves on. The fault tests (`tests/netns_faults.rs`) run both
//! processes with this flag through delays, stalls, resets and partitions
//! and check that neither figure ever went back.
//!
//! Output, one line each: `out of order: BUFFER generation A -> B, writer
//! cycle C -> D` at once when either goes back, and every
//! [`SUMMARY_EVERY`] cycles (and at the end of a `--cycles` run)
//! `generations cycle=N BUFFER=GEN/WRITER_CYCLE … generation_back=G
//! cycle_back=C tb_stale=S`, where `generation_back` and `cycle_back` are
//! the largest decreases seen so far (0: never).

use rcs_runtime::{BufferData, Reader};

/// Cycles between two summary lines (3 s at the example's 30 ms period).
pub(crate) const SUMMARY_EVERY: u64 = 100;

/// The stamps of one imported buffer, whatever its type.
trait Stamps {
    /// `(generation, writer_cycle)` of the buffer's current value.
    fn stamps(&self) -> (u64, u64);
}

impl<T: BufferData> Stamps for Reader<T> {
    fn stamps(&self) -> (u64, u64) {
        let s = self.read();
        (s.generation, s.writer_cycle)
    }
}

/// One watched buffer: its name, reader and the stamps seen last.
struct Watched {
    name: String,
    reader: Box<dyn Stamps>,
    last: (u64, u64),
}

/// The imported buffers of one process and the largest decreases of their
/// stamps seen so far.
pub(crate) struct GenerationWatch {
    buffers: Vec<Watched>,
    generation_back: u64,
    cycle_back: u64,
}

impl GenerationWatch {
    pub(crate) fn new() -> Self {
        Self {
            buffers: Vec::new(),
            generation_back: 0,
            cycle_back: 0,
        }
    }

    /// Watch `reader`, a reader of the imported buffer `name`.
    pub(crate) fn watch<T: BufferData + 'static>(&mut self, name: &str, reader: Reader<T>) {
        self.buffers.push(Watched {
            name: name.to_owned(),
            reader: Box::new(reader),
            last: (0, 0),
        });
    }

    /// Read every watched buffer's stamps; print a line at once for each
    /// that went back since the last call.
    pub(crate) fn check(&mut self) {
        for w in &mut self.buffers {
            let now = w.reader.stamps();
            let (g0, c0) = w.last;
            let (g1, c1) = now;
            if now == w.last {
                continue;
            }
            if g1 < g0 || c1 < c0 {
                println!(
                    "out of order: {} generation {g0} -> {g1}, writer cycle {c0} -> {c1}",
                    w.name
                );
                self.generation_back = self.generation_back.max(g0.saturating_sub(g1));
                self.cycle_back = self.cycle_back.max(c0.saturating_sub(c1));
            }
            w.last = now;
        }
    }

    /// The summary line (see the module's docs); `tb_stale` is PR's
    /// watchdog count in the helm, `None` in the engine.
    pub(crate) fn summary(&self, cycle: u64, tb_stale: Option<u32>) -> String {
        let mut line = format!("generations cycle={cycle}");
        for w in &self.buffers {
            line.push_str(&format!(" {}={}/{}", w.name, w.last.0, w.last.1));
        }
        line.push_str(&format!(
            " generation_back={} cycle_back={}",
            self.generation_back, self.cycle_back
        ));
        if let Some(s) = tb_stale {
            line.push_str(&format!(" tb_stale={s}"));
        }
        line
    }
}

#[cfg(test)]
mod tests {
    use super::GenerationWatch;
    use rcs_runtime::GlobalMemory;

    /// A value written with an older writer cycle after a newer one (what a
    /// stale sample applied late looks like) is caught and measured.
    #[test]
    fn a_writer_cycle_going_back_is_reported() {
        let gm = GlobalMemory::new();
        gm.declare::<u64>("b").expect("declare");
        let mut w = gm.writer::<u64>("b").expect("writer");
        let mut watch = GenerationWatch::new();
        watch.watch("b", gm.reader::<u64>("b").expect("reader"));
        w.write(1, 10);
        watch.check();
        w.write(2, 11);
        watch.check();
        assert!(watch
            .summary(2, None)
            .ends_with("generation_back=0 cycle_back=0"));
        w.write(3, 7);
        watch.check();
        assert_eq!(
            watch.summary(3, Some(4)),
            "generations cycle=3 b=3/7 generation_back=0 cycle_back=4 tb_stale=4"
        );
    }
}
