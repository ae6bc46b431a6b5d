//! The one `unsafe` module of the crate: a sequence lock for `Copy` values.
//!
//! Global Memory ([`crate::gm`]) keeps every buffer in a [`SeqLock`]. It is
//! the classic one-writer, many-readers cell: the writer never waits for
//! anybody, readers never block the writer and retry when they overlap a
//! write, so a reader only ever returns a value that was written whole.
//!
//! # Protocol
//!
//! A 64-bit sequence counter is even while the cell is quiet and odd while a
//! write is in progress.
//!
//! * Writer: `seq = s + 1` (odd), release fence, copy the value in,
//!   `seq = s + 2` with release ordering.
//! * Reader: `s1 = seq` with acquire ordering; if odd, retry; copy the value
//!   out into a `MaybeUninit<T>`; acquire fence; `s2 = seq`; if `s1 != s2`,
//!   retry, else the copy is whole and is returned.
//!
//! This is the ordering recipe of H.-J. Boehm, "Can seqlocks get along with
//! programming language memory models?" (MSPC 2012): the release fence keeps
//! the data stores after the odd counter, the acquire fence keeps the data
//! loads before the second counter load.
//!
//! # Why this is sound in practice, and where it is not formally
//!
//! * Only one writer at a time: [`SeqLock::write`] is `unsafe` and requires
//!   it. Global Memory guarantees it by handing out exactly one non-`Clone`
//!   writer handle per buffer whose `write` takes `&mut self`.
//! * A reader may copy bytes while the writer changes them. The copy goes
//!   into a `MaybeUninit<T>` with a volatile read and is turned into a `T`
//!   (`assume_init`) only after the counter check proved that no write
//!   overlapped it. A torn copy is dropped without ever being looked at as a
//!   `T`, so a torn `bool` or enum discriminant can never become a value.
//! * The copies are volatile, not atomic. Under the letter of the Rust memory
//!   model a non-atomic read racing a write is a data race even if its result
//!   is thrown away, and `cargo miri` reports it as such in the multi-threaded
//!   stress test. Per-word atomic copies would avoid that only for types
//!   without padding (reading padding bytes into an integer is itself
//!   undefined), and buffer types with `bool` and `f64` fields have padding.
//!   This is the same trade-off `crossbeam_utils::atomic::AtomicCell` makes
//!   for large types; the proper fix is a byte-wise atomic memcpy
//!   (RFC 3301, `AtomicPerByte`) once the language has one.
//! * `T: Copy` means no destructors and no ownership are duplicated by the
//!   byte copies.
//!
//! # Why the copies go word by word
//!
//! The value is kept padded to whole 8-byte words ([`Words`]) and both sides
//! copy it as the same sequence of 8-byte volatile accesses. A reader that
//! runs right after a write on the same core (a supervisor reading what its
//! subordinate wrote a few nanoseconds earlier, or any single-threaded test
//! loop) then loads exactly the words the writer stored, which the CPU
//! forwards from its store buffer. A plain volatile copy of `T` lets the
//! compiler choose different access widths on the two sides (a 1-byte store
//! of an enum field, an 8-byte load spanning it): such a load cannot be
//! forwarded and stalls for ≈ 15 cycles, and whether it happens depended on
//! how the caller's code was inlined (measured in `BENCHMARKS.md`, the
//! servo-loop section).

use std::cell::UnsafeCell;
use std::fmt;
use std::mem::{ManuallyDrop, MaybeUninit};
use std::ptr;
use std::sync::atomic::{fence, AtomicU64, Ordering};

/// A cell with one writer and any number of concurrent readers.
pub(crate) struct SeqLock<T> {
    seq: AtomicU64,
    data: UnsafeCell<Words<T>>,
}

/// `T` padded to whole 8-byte words and aligned to at least 8, so that it
/// can be copied as `[MaybeUninit<u64>; words::<T>()]` (a union's size is a
/// multiple of its alignment).
#[repr(C, align(8))]
#[derive(Clone, Copy)]
union Words<T> {
    value: ManuallyDrop<T>,
}

impl<T> Words<T> {
    const fn new(value: T) -> Self {
        Self {
            value: ManuallyDrop::new(value),
        }
    }
}

/// The number of 8-byte words in `Words<T>`.
const fn words<T>() -> usize {
    std::mem::size_of::<Words<T>>() / 8
}

/// Store `value` into `dst` as `words::<T>()` volatile 8-byte stores
/// (volatile, or the compiler turns the word copy back into narrow field
/// stores).
///
/// # Safety
///
/// `dst` is valid for writes of a `Words<T>`, and nothing else writes it
/// meanwhile. Concurrent readers may see a mix of old and new words; they
/// must not treat what they copied as a `T` unless they know no store
/// overlapped their copy (the seqlock's counter check).
#[inline]
unsafe fn store_words<T>(dst: *mut Words<T>, value: T) {
    let src = Words::new(value);
    let src = (&raw const src).cast::<MaybeUninit<u64>>();
    let dst = dst.cast::<MaybeUninit<u64>>();
    for i in 0..words::<T>() {
        // SAFETY: `src` and `dst` point to a `Words<T>`: 8-aligned and
        // `words::<T>()` whole words long, so every word is in bounds and
        // aligned; `MaybeUninit<u64>` may hold padding bytes. The caller
        // vouches for `dst` being valid and written by nobody else.
        unsafe { ptr::write_volatile(dst.add(i), src.add(i).read()) };
    }
}

/// A `T` that is stored as whole 8-byte words, for a value written in one
/// step of a cycle and read back in a later one (a subordinate's pending
/// command, written at `send` and copied to Global Memory at `flush`). Read
/// back soon after a plain store of a struct, loads the compiler widened
/// over several narrow field stores stall the CPU (see the module docs);
/// loads from a value stored as words are always forwarded.
pub(crate) struct Staged<T> {
    words: Words<T>,
}

impl<T: Copy> Staged<T> {
    /// A slot holding `value`.
    pub(crate) const fn new(value: T) -> Self {
        Self {
            words: Words::new(value),
        }
    }

    /// Replace the value, storing it word by word.
    #[inline]
    pub(crate) fn set(&mut self, value: T) {
        // SAFETY: `&mut self` makes the slot ours alone; the words written
        // are those of a valid `T`.
        unsafe { store_words(&raw mut self.words, value) };
    }

    /// The value.
    #[inline]
    pub(crate) fn get(&self) -> T {
        // SAFETY: `new` and `set` only ever store a whole valid `T`.
        unsafe { *self.words.value }
    }
}

impl<T: Copy> Clone for Staged<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T: Copy> Copy for Staged<T> {}

impl<T: Copy + fmt::Debug> fmt::Debug for Staged<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.get().fmt(f)
    }
}

// SAFETY: readers only obtain copies of `T` (which is `Copy`, so copying is
// all that sharing means), and concurrent writes are excluded by the contract
// of `write`. `T: Send` because values written on one thread are read on
// others.
unsafe impl<T: Copy + Send> Sync for SeqLock<T> {}

impl<T: Copy> SeqLock<T> {
    /// A cell holding `value`, generation 0.
    pub(crate) const fn new(value: T) -> Self {
        Self {
            seq: AtomicU64::new(0),
            data: UnsafeCell::new(Words::new(value)),
        }
    }

    /// Store `value` and return the new generation (number of writes so far).
    ///
    /// # Safety
    ///
    /// No other call of `write` on this cell may run at the same time.
    #[inline]
    pub(crate) unsafe fn write(&self, value: T) -> u64 {
        // Only the (single) writer changes `seq`, so a relaxed load sees the
        // writer's own last store.
        let s = self.seq.load(Ordering::Relaxed);
        self.seq.store(s.wrapping_add(1), Ordering::Relaxed);
        fence(Ordering::Release);
        // SAFETY: `data` is valid for writes; the caller excludes other
        // writers; readers that overlap these stores discard what they copied.
        unsafe { store_words(self.data.get(), value) };
        let next = s.wrapping_add(2);
        self.seq.store(next, Ordering::Release);
        next / 2
    }

    /// One attempt at a consistent copy: `None` if a write overlapped.
    #[inline]
    pub(crate) fn try_read(&self) -> Option<(T, u64)> {
        let s1 = self.seq.load(Ordering::Acquire);
        if s1 & 1 != 0 {
            return None;
        }
        let mut copy = MaybeUninit::<Words<T>>::uninit();
        let src = self.data.get().cast_const().cast::<MaybeUninit<u64>>();
        let dst = copy.as_mut_ptr().cast::<MaybeUninit<u64>>();
        for i in 0..words::<T>() {
            // SAFETY: both point to a `Words<T>`, 8-aligned and
            // `words::<T>()` whole words long. The copy lands in a
            // `MaybeUninit`, which accepts any bytes, and is only assumed
            // initialised below after the sequence check.
            unsafe { dst.add(i).write(ptr::read_volatile(src.add(i))) };
        }
        fence(Ordering::Acquire);
        let s2 = self.seq.load(Ordering::Relaxed);
        if s1 == s2 {
            // SAFETY: no write started or finished while we copied (the
            // counter was even and unchanged), so the bytes are exactly those
            // of one complete `write` (or of `new`): a valid `T`.
            Some((
                unsafe { ManuallyDrop::into_inner(copy.assume_init().value) },
                s1 / 2,
            ))
        } else {
            None
        }
    }

    /// A consistent copy and its generation; retries while a write overlaps.
    ///
    /// Never blocks the writer. Spins briefly, then yields the thread, so a
    /// reader whose writer was preempted mid-write does not burn its core.
    #[inline]
    pub(crate) fn read(&self) -> (T, u64) {
        let mut spins = 0u32;
        loop {
            if let Some(v) = self.try_read() {
                return v;
            }
            if spins < 64 {
                spins += 1;
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
    }

    /// The current generation without copying the value.
    #[inline]
    pub(crate) fn generation(&self) -> u64 {
        self.seq.load(Ordering::Acquire) / 2
    }
}

#[cfg(test)]
mod tests {
    use super::{words, SeqLock, Staged};
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;

    /// Write then read `values` through a cell and a staged slot; every
    /// value must come back exactly, whatever its size and alignment.
    fn round_trip<T: Copy + PartialEq + std::fmt::Debug + Default>(values: &[T]) {
        let cell = SeqLock::new(T::default());
        let mut staged = Staged::new(T::default());
        assert_eq!(cell.read().0, T::default());
        assert_eq!(staged.get(), T::default());
        for (i, &v) in values.iter().enumerate() {
            assert_eq!(unsafe { cell.write(v) }, i as u64 + 1);
            assert_eq!(cell.read(), (v, i as u64 + 1));
            staged.set(v);
            assert_eq!(staged.get(), v);
            let copy = staged;
            assert_eq!(copy.get(), v);
        }
    }

    #[derive(Clone, Copy, Debug, Default, PartialEq)]
    struct Odd {
        a: u8,
        b: u16,
        c: bool,
    }

    #[derive(Clone, Copy, Debug, Default, PartialEq)]
    struct Mixed {
        flag: bool,
        x: f64,
        n: u32,
        tag: Option<u16>,
    }

    #[test]
    fn words_cover_the_value_padded_to_eight_bytes() {
        assert_eq!(words::<()>(), 0);
        assert_eq!(words::<u8>(), 1);
        assert_eq!(words::<[u8; 8]>(), 1);
        assert_eq!(words::<[u8; 9]>(), 2);
        assert_eq!(words::<Odd>(), 1);
        assert_eq!(words::<Mixed>(), 3);
        assert_eq!(words::<u128>(), 2);
        assert!(std::mem::align_of::<super::Words<u8>>() >= 8);
        assert!(std::mem::align_of::<super::Words<u128>>() >= 16);
    }

    #[test]
    fn values_of_every_size_and_alignment_come_back_whole() {
        round_trip(&[(), ()]);
        round_trip(&[1u8, 255, 0]);
        round_trip(&[[1u8, 2, 3], [255, 0, 7]]);
        round_trip(&[[9u8; 9], [1u8; 9]]);
        round_trip(&[
            Odd {
                a: 1,
                b: 0xBEEF,
                c: true,
            },
            Odd {
                a: 255,
                b: 1,
                c: false,
            },
        ]);
        round_trip(&[
            Mixed {
                flag: true,
                x: -0.5,
                n: u32::MAX,
                tag: Some(7),
            },
            Mixed {
                flag: false,
                x: f64::MAX,
                n: 1,
                tag: None,
            },
        ]);
        round_trip(&[u128::MAX, 1u128 << 100, 0]);
        round_trip(&[(3.5f64, 17u64), (f64::MIN_POSITIVE, u64::MAX)]);
    }

    #[test]
    fn single_thread_write_read() {
        let l = SeqLock::new([0u64; 4]);
        assert_eq!(l.read(), ([0; 4], 0));
        // SAFETY: single writer in this test.
        let g = unsafe { l.write([7; 4]) };
        assert_eq!(g, 1);
        assert_eq!(l.read(), ([7; 4], 1));
        assert_eq!(l.generation(), 1);
    }

    /// A value whose words must all agree; a torn read would mix two writes.
    #[derive(Clone, Copy)]
    struct Wide {
        words: [u64; 16],
        flag: bool,
    }

    #[test]
    fn stress_no_torn_reads() {
        // Fewer iterations under Miri, which is orders of magnitude slower.
        let writes: u64 = if cfg!(miri) { 200 } else { 200_000 };
        let lock = Arc::new(SeqLock::new(Wide {
            words: [0; 16],
            flag: false,
        }));
        let done = Arc::new(AtomicBool::new(false));
        let readers: Vec<_> = (0..3)
            .map(|_| {
                let lock = Arc::clone(&lock);
                let done = Arc::clone(&done);
                std::thread::spawn(move || {
                    let mut reads = 0u64;
                    let mut last_gen = 0;
                    loop {
                        let stop = done.load(Ordering::Relaxed);
                        let (v, g) = lock.read();
                        let w0 = v.words[0];
                        assert!(v.words.iter().all(|&w| w == w0), "torn read");
                        assert_eq!(v.flag, w0 % 2 == 1, "torn flag");
                        // The value written by the n-th write is n.
                        assert_eq!(w0, g, "value and generation disagree");
                        assert!(g >= last_gen, "generation went back");
                        last_gen = g;
                        reads += 1;
                        if stop {
                            break reads;
                        }
                    }
                })
            })
            .collect();
        for i in 1..=writes {
            // SAFETY: this thread is the only writer.
            unsafe {
                lock.write(Wide {
                    words: [i; 16],
                    flag: i % 2 == 1,
                })
            };
        }
        done.store(true, Ordering::Relaxed);
        for r in readers {
            let reads = r.join().expect("reader thread panicked");
            assert!(reads > 0);
        }
        assert_eq!(lock.read().1, writes);
    }
}
