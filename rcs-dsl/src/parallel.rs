//! The one way the pipeline uses both cores: an order-preserving parallel
//! map. Parsing (per file), lowering (per controller body) and the analyses
//! (per controller) each call [`map_ordered`]; the results come back in the
//! order of the input, so every later stage — and every diagnostic — is the
//! same whatever the threads did.

use std::sync::atomic::{AtomicUsize, Ordering};

/// `items.iter().map(f).collect()`, on as many threads as the machine has
/// when `worth_threads` says the work outweighs starting them. Workers take
/// the next item from a shared counter (items differ in size: a file of ten
/// controllers beside a types file), and the results are put back in input
/// order. A panic in `f` is resumed on the calling thread.
pub(crate) fn map_ordered<'a, T, R, F>(items: &'a [T], worth_threads: bool, f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    F: Fn(&'a T) -> R + Sync,
{
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len());
    if !worth_threads || threads < 2 {
        return items.iter().map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let work = || {
        let mut done = Vec::new();
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(item) = items.get(i) else {
                return done;
            };
            done.push((i, f(item)));
        }
    };
    let mut parts: Vec<Vec<(usize, R)>> = std::thread::scope(|scope| {
        let helpers: Vec<_> = (1..threads).map(|_| scope.spawn(work)).collect();
        let mut parts = vec![work()];
        for h in helpers {
            parts.push(h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
        }
        parts
    });
    // Each worker's results are in increasing index order: merge them.
    let mut slots: Vec<Option<R>> = (0..items.len()).map(|_| None).collect();
    for part in &mut parts {
        for (i, r) in part.drain(..) {
            slots[i] = Some(r);
        }
    }
    slots.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::map_ordered;

    #[test]
    fn results_come_back_in_input_order_with_or_without_threads() {
        let items: Vec<u64> = (0..1000).collect();
        // Uneven work, so that workers finish out of order.
        let f = |&x: &u64| (0..(x % 7) * 100).fold(x, |a, b| a.wrapping_mul(31).wrapping_add(b));
        let expected: Vec<u64> = items.iter().map(f).collect();
        assert_eq!(map_ordered(&items, true, f), expected);
        assert_eq!(map_ordered(&items, false, f), expected);
        assert!(map_ordered(&[] as &[u64], true, f).is_empty());
    }
}
