//! Watchdogs on `reads` buffers (LANGUAGE.md §8, SEMANTICS.md step 6):
//! `B.stale_cycles` counts the reading controller's cycles since B's writer
//! last wrote it, following the buffer's write generation exactly as
//! [`crate::SubordinateLink::observe`] does for a subordinate's status.
//! Plain values, no Global Memory: generated controllers feed it the
//! generation of each cycle's read, the reference interpreter the
//! generation of its scripted writes, so the rule exists once.

/// One reader's watch on one buffer.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BufferWatch {
    seen_generation: u64,
    stale_cycles: u32,
}

impl BufferWatch {
    /// A watch that has seen nothing: a buffer never written (generation
    /// 0) is stale from the first cycle, as a subordinate that never spoke.
    pub const fn new() -> Self {
        Self {
            seen_generation: 0,
            stale_cycles: 0,
        }
    }

    /// Step 1 for this buffer: take the generation of this cycle's read
    /// (call once per cycle of the reader). `stale_cycles` becomes 0 when
    /// the generation is one not seen before, else one more (saturating).
    #[inline]
    pub fn observe(&mut self, generation: u64) -> u32 {
        if generation != self.seen_generation {
            self.seen_generation = generation;
            self.stale_cycles = 0;
        } else {
            self.stale_cycles = self.stale_cycles.saturating_add(1);
        }
        self.stale_cycles
    }

    /// `B.stale_cycles` as of the last [`observe`](Self::observe).
    #[inline]
    pub fn stale_cycles(&self) -> u32 {
        self.stale_cycles
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_cycles_follow_the_generation() {
        let mut w = BufferWatch::new();
        // Never written: stale from the first cycle on.
        assert_eq!(w.observe(0), 1);
        assert_eq!(w.observe(0), 2);
        // Written: 0 on the cycle that sees it, then growing.
        assert_eq!(w.observe(1), 0);
        assert_eq!(w.observe(1), 1);
        assert_eq!(w.observe(1), 2);
        // Written twice between two reads: still one new generation.
        assert_eq!(w.observe(3), 0);
        assert_eq!(w.observe(4), 0);
        assert_eq!(w.stale_cycles(), 0);
    }

    #[test]
    fn stale_cycles_saturate() {
        let mut w = BufferWatch {
            seen_generation: 5,
            stale_cycles: u32::MAX - 1,
        };
        assert_eq!(w.observe(5), u32::MAX);
        assert_eq!(w.observe(5), u32::MAX);
    }
}
