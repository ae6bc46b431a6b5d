//! Command epochs: the half of a command's identity that survives restarts
//! and serial wrap-around (docs/semantics.md "The handshake", docs/distribution.md
//! "Restarts").
//!
//! A serial alone is not a command's identity: a supervisor that restarts
//! counts from 1 again, and a subordinate whose status still echoes serial 1
//! of the previous incarnation would answer the new command 1 with the old
//! DONE; after `u32::MAX` commands the serials wrap and the same can happen.
//! So every [`SubordinateLink`](crate::SubordinateLink) stamps its commands
//! with an *epoch* beside the serial, and trusts a status only when both
//! echo back.
//!
//! An epoch comes from [`fresh_epoch`]: a base drawn once per process from
//! std's randomly keyed [`RandomState`] hashed with the wall clock and the
//! process id (so a restarted process almost surely draws another), plus an
//! odd multiple of a per-process counter (so epochs drawn in one process —
//! one per link, and a new one whenever a link's serials wrap — never repeat
//! within 2³² draws). Never 0, which stands for "no epoch" (a buffer never
//! written). No new dependency, no allocation, and after the first call no
//! lock: one atomic add.

use std::collections::hash_map::RandomState;
use std::hash::{BuildHasher, Hasher};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::OnceLock;

/// The per-process random base of every epoch.
static BASE: OnceLock<u32> = OnceLock::new();
/// How many epochs this process has handed out.
static DRAWN: AtomicU32 = AtomicU32::new(0);

/// Odd, so `k ↦ k × STRIDE` is a bijection on `u32`: the first 2³² draws of
/// one process are distinct. (The 32-bit golden ratio spreads them apart.)
const STRIDE: u32 = 0x9E37_79B9;

fn draw_base() -> u32 {
    let mut h = RandomState::new().build_hasher();
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    h.write_u128(now);
    h.write_u32(std::process::id());
    let v = h.finish();
    (v ^ (v >> 32)) as u32
}

/// A new epoch: nonzero, different from every other epoch this process drew
/// before (up to 2³² draws), and with overwhelming likelihood different from
/// those of any earlier incarnation of this process.
pub fn fresh_epoch() -> u32 {
    let base = *BASE.get_or_init(draw_base);
    loop {
        let k = DRAWN.fetch_add(1, Ordering::Relaxed);
        let epoch = base.wrapping_add(k.wrapping_mul(STRIDE));
        if epoch != 0 {
            return epoch;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn epochs_are_nonzero_and_do_not_repeat_in_one_process() {
        let drawn: Vec<u32> = (0..10_000).map(|_| fresh_epoch()).collect();
        assert!(drawn.iter().all(|&e| e != 0));
        let mut sorted = drawn.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), drawn.len());
    }

    #[test]
    fn two_draws_of_the_base_differ() {
        // The base mixes a randomly keyed hasher: two "processes" (two
        // draws) get different bases.
        assert_ne!(draw_base(), draw_base());
    }
}
