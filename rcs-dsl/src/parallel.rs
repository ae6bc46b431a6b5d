//! The one way the pipeline uses both cores: an order-preserving parallel
//! map. Parsing (per file) and the analyses (per controller) call
//! [`map_ordered`]; lowering (per controller body) calls [`map_pinned`], so
//! that each body is lowered by the worker that parsed its file. The
//! results come back in the order of the input, so every later stage — and
//! every diagnostic — is the same whatever the threads did.

use std::sync::atomic::{AtomicUsize, Ordering};

/// Which thread of a parallel map computed an item: 0 is the calling
/// thread, 1… the threads it started.
pub(crate) type Worker = usize;

/// `items.iter().map(f).collect()`, on as many threads as the machine has
/// when `worth_threads` says the work outweighs starting them. Workers take
/// the next item from a shared counter (items differ in size: a file of ten
/// controllers beside a types file), and the results are put back in input
/// order. A panic in `f` is resumed on the calling thread.
pub(crate) fn map_ordered<'a, T: Sync, R: Send, F: Fn(&'a T) -> R + Sync>(
    items: &'a [T],
    worth_threads: bool,
    f: F,
) -> Vec<R> {
    shared_out(items, worth_threads, |item, _| f(item))
}

/// [`map_ordered`], saying which worker computed each result.
pub(crate) fn map_ordered_on<'a, T: Sync, R: Send, F: Fn(&'a T) -> R + Sync>(
    items: &'a [T],
    worth_threads: bool,
    f: F,
) -> Vec<(R, Worker)> {
    shared_out(items, worth_threads, |item, w| (f(item), w))
}

/// Both of the above: `f` is given each item and the worker computing it,
/// workers taking the next item from a shared counter.
fn shared_out<'a, T: Sync, R: Send, F: Fn(&'a T, Worker) -> R + Sync>(
    items: &'a [T],
    worth_threads: bool,
    f: F,
) -> Vec<R> {
    let Some(threads) = threads_for(items.len(), worth_threads) else {
        return items.iter().map(|t| f(t, 0)).collect();
    };
    let next = AtomicUsize::new(0);
    run(items.len(), threads, |w| {
        let mut done = Vec::new();
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(item) = items.get(i) else {
                return done;
            };
            done.push((i, f(item, w)));
        }
    })
}

/// `items.iter().map(f).collect()` with item `i` computed by worker
/// `workers[i]` (a [`Worker`] from [`map_ordered_on`]). Memory is cheapest
/// to free on the thread that allocated it: glibc keeps an arena per
/// thread, a thread that frees another arena's blocks takes that arena's
/// lock against its owner, and a new thread takes over the arena of one
/// that ended. So a stage that consumes what an earlier one built (the
/// lowering of a controller frees its parsed rows) runs each item on the
/// worker that built its input. When that would leave a worker with more
/// than its share and a quarter (one file holding most controllers), the
/// items are shared out as [`map_ordered`] does instead: both cores are
/// worth more than the allocator's preference.
pub(crate) fn map_pinned<'a, T: Sync, R: Send, F: Fn(&'a T) -> R + Sync>(
    items: &'a [T],
    workers: &[Worker],
    worth_threads: bool,
    f: F,
) -> Vec<R> {
    let Some(threads) = threads_for(items.len(), worth_threads) else {
        return items.iter().map(f).collect();
    };
    let worker = |i: usize| workers.get(i).copied().unwrap_or(0) % threads;
    let mut share = vec![0usize; threads];
    (0..items.len()).for_each(|i| share[worker(i)] += 1);
    let most = share.iter().copied().max().unwrap_or(0);
    if most * threads * 4 > items.len() * 5 {
        return map_ordered(items, worth_threads, f);
    }
    run(items.len(), threads, |w| {
        items
            .iter()
            .enumerate()
            .filter(|(i, _)| worker(*i) == w)
            .map(|(i, item)| (i, f(item)))
            .collect()
    })
}

/// How many threads a map of `items` items uses; `None`: only the caller
/// (the work is not `worth_threads`, or there is one core or one item).
fn threads_for(items: usize, worth_threads: bool) -> Option<usize> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items);
    (worth_threads && threads >= 2).then_some(threads)
}

/// Run `work` as workers `0..threads` (0 on the calling thread) and put
/// the `(index, result)` pairs they return in index order.
fn run<R, W>(len: usize, threads: usize, work: W) -> Vec<R>
where
    R: Send,
    W: Fn(Worker) -> Vec<(usize, R)> + Sync,
{
    let mut parts: Vec<Vec<(usize, R)>> = std::thread::scope(|scope| {
        let work = &work;
        let helpers: Vec<_> = (1..threads).map(|w| scope.spawn(move || work(w))).collect();
        let mut parts = vec![work(0)];
        for h in helpers {
            parts.push(h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
        }
        parts
    });
    // Each worker's results are in increasing index order: merge them.
    let mut slots: Vec<Option<R>> = (0..len).map(|_| None).collect();
    for part in &mut parts {
        for (i, r) in part.drain(..) {
            slots[i] = Some(r);
        }
    }
    slots.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::{map_ordered, map_ordered_on, map_pinned, threads_for, Worker};
    use std::thread::{current, ThreadId};

    #[test]
    fn pinned_items_run_on_their_worker_and_come_back_in_order() {
        let items: Vec<u64> = (0..500).collect();
        let threads = threads_for(items.len(), true).unwrap_or(1);
        // More worker numbers than threads (they wrap around), evenly.
        let workers: Vec<Worker> = (0..items.len()).map(|i| i % (2 * threads)).collect();
        let f = |&x: &u64| (x * 3 + 1, current().id());
        let caller = current().id();
        let out = map_pinned(&items, &workers, true, f);
        let values: Vec<u64> = out.iter().map(|(v, _)| *v).collect();
        assert_eq!(values, items.iter().map(|x| x * 3 + 1).collect::<Vec<_>>());
        // Items of one worker ran on one thread, worker 0's on the caller.
        let mut thread_of: Vec<Option<ThreadId>> = vec![None; threads];
        for (w, (_, t)) in workers.iter().zip(&out) {
            let slot = &mut thread_of[w % threads];
            assert_eq!(*slot.get_or_insert(*t), *t);
        }
        assert_eq!(thread_of[0], Some(caller));
        let serial: Vec<u64> = map_pinned(&items, &workers, false, f)
            .into_iter()
            .map(|(v, t)| {
                assert_eq!(t, caller);
                v
            })
            .collect();
        assert_eq!(serial, values);
    }

    #[test]
    fn uneven_pins_are_shared_out_instead() {
        // Nearly everything pinned to worker 0 (one big file): the items
        // are shared out, and still come back in order.
        let items: Vec<u64> = (0..400).collect();
        let workers: Vec<Worker> = items.iter().map(|x| usize::from(*x == 0)).collect();
        let out = map_pinned(&items, &workers, true, |&x| x + 1);
        assert_eq!(out, items.iter().map(|x| x + 1).collect::<Vec<_>>());
    }

    #[test]
    fn workers_are_reported_as_they_ran() {
        let items: Vec<u64> = (0..300).collect();
        let caller = current().id();
        let out = map_ordered_on(&items, true, |&x| (x, current().id()));
        for (i, ((x, t), w)) in out.iter().enumerate() {
            assert_eq!(*x, i as u64);
            assert!(*w < threads_for(items.len(), true).unwrap_or(1));
            assert_eq!(*w == 0, *t == caller);
        }
    }

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
