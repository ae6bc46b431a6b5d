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
//! # Why the copies go chunk by chunk
//!
//! The value is kept padded to whole chunks ([`Words`]): 16 bytes on
//! x86_64 (an SSE2 register, which every x86_64 CPU has), 8 bytes
//! elsewhere. Both sides copy it as the same sequence of volatile accesses:
//! whole chunks, then one 8-byte word if the value's size rounded up to 8
//! leaves one (a 72-byte buffer with its cycle stamp is four 16-byte
//! chunks and a word). A reader that runs right after a write on the same
//! core (a supervisor reading what its subordinate wrote a few nanoseconds
//! earlier, or any single-threaded test loop) then loads exactly the chunks
//! the writer stored, which the CPU forwards from its store buffer. A plain
//! volatile copy of `T` lets the compiler choose different access widths
//! on the two sides (a 1-byte store of an enum field, an 8-byte load
//! spanning it): such a load cannot be forwarded and stalls for ≈ 15
//! cycles, and whether it happens depended on how the caller's code was
//! inlined (measured in `BENCHMARKS.md`, the servo-loop section).
//!
//! 16-byte chunks halve the instructions of 8-byte words: a 64-byte write
//! plus read went from ≈ 7.4 ns to ≈ 4.7 ns on the project's machine
//! (BENCHMARKS.md). Tried and measured slower: volatile loads on the
//! writer's side too (they force the value through the stack), volatile
//! stores into the reader's copy (it then costs one more copy out), and a
//! `memcpy` on both sides for large values (its access widths differ
//! between the two sides, so the reader's loads are not forwarded), 32-byte
//! AVX chunks chosen at run time for values over 256 bytes, and a reader
//! copying into memory it keeps out of registers. At 512 bytes none of
//! these beat the 16-byte chunks (≈ 35 ns for a write and a read, against
//! 19–39 ns for a plain copy of the value in and out, depending on how the
//! run's stack happens to be aligned).

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

/// The widest access a load or store can make in one instruction on every
/// CPU of the target, without a target feature: a 16-byte SSE2 register on
/// x86_64 (SSE2 is part of x86_64 itself), an 8-byte word elsewhere.
#[cfg(target_arch = "x86_64")]
type Chunk = std::arch::x86_64::__m128i;
/// See the x86_64 definition.
#[cfg(not(target_arch = "x86_64"))]
type Chunk = u64;

/// `T` padded to whole chunks and aligned to at least a chunk (a union's
/// size is a multiple of its alignment), so that it can be copied as
/// [`chunks`]`::<T>()` chunks and, if [`tail_word`]`::<T>()`, one 8-byte
/// word after them.
#[cfg_attr(target_arch = "x86_64", repr(C, align(16)))]
#[cfg_attr(not(target_arch = "x86_64"), repr(C, align(8)))]
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

/// `T`'s size rounded up to whole 8-byte words: the bytes a copy covers.
const fn copied_bytes<T>() -> usize {
    std::mem::size_of::<T>().next_multiple_of(8)
}

/// The number of whole chunks in the copied bytes of a `T`.
const fn chunks<T>() -> usize {
    copied_bytes::<T>() / std::mem::size_of::<Chunk>()
}

/// Whether the copied bytes of a `T` end with one 8-byte word after the
/// chunks (a 72-byte value is four 16-byte chunks and one word, not five
/// chunks: one access fewer on each side).
const fn tail_word<T>() -> bool {
    !copied_bytes::<T>().is_multiple_of(std::mem::size_of::<Chunk>())
}

// The copies below rely on these: the chunks and the tail word fit in a
// `Words<T>`, at offsets aligned for their type.
const _: () = {
    assert!(std::mem::size_of::<Chunk>().is_multiple_of(8));
    assert!(std::mem::align_of::<Words<[u8; 1]>>() >= std::mem::align_of::<Chunk>());
    assert!(std::mem::align_of::<Chunk>() >= std::mem::align_of::<u64>());
};

/// Store `value` into `dst` as [`chunks`] volatile chunk stores and
/// maybe one volatile 8-byte store (volatile, or the compiler turns the
/// copy back into narrow field stores, which a reader's chunk loads cannot
/// take from the store buffer).
///
/// # Safety
///
/// `dst` is valid for writes of a `Words<T>`, and nothing else writes it
/// meanwhile. Concurrent readers may see a mix of old and new chunks; they
/// must not treat what they copied as a `T` unless they know no store
/// overlapped their copy (the seqlock's counter check).
#[inline(always)]
unsafe fn store_chunks<T>(dst: *mut Words<T>, value: T) {
    let src = Words::new(value);
    let src = &raw const src;
    let (src_chunks, dst_chunks) = (
        src.cast::<MaybeUninit<Chunk>>(),
        dst.cast::<MaybeUninit<Chunk>>(),
    );
    for i in 0..chunks::<T>() {
        // SAFETY: `src` and `dst` point to a `Words<T>`, aligned to a chunk
        // and at least `copied_bytes::<T>()` long, so chunk `i` is in bounds
        // and aligned; a `MaybeUninit` may hold padding bytes. The caller
        // vouches for `dst` being valid and written by nobody else.
        unsafe { ptr::write_volatile(dst_chunks.add(i), src_chunks.add(i).read()) };
    }
    if tail_word::<T>() {
        let at = chunks::<T>() * std::mem::size_of::<Chunk>();
        // SAFETY: the word at `at` is the last of `copied_bytes::<T>()`,
        // inside the `Words<T>`, and `at` is a multiple of a chunk's size,
        // so the word is aligned; otherwise as above.
        unsafe {
            let (s, d) = (
                src.byte_add(at).cast::<MaybeUninit<u64>>(),
                dst.byte_add(at).cast::<MaybeUninit<u64>>(),
            );
            ptr::write_volatile(d, s.read());
        }
    }
}

/// Copy the copied bytes of the `Words<T>` at `src` into `dst` with the
/// same sequence of accesses as [`store_chunks`], volatile loads here, so
/// that each load meets exactly one earlier store of the same width at the
/// same address (forwarded from the store buffer when the store was
/// recent).
///
/// # Safety
///
/// `src` is valid for reads of a `Words<T>` (a writer may be changing it:
/// the result is then garbage, which is why it lands in a `MaybeUninit`),
/// and `dst` valid for writes of one.
#[inline(always)]
unsafe fn load_chunks<T>(src: *const Words<T>, dst: *mut MaybeUninit<Words<T>>) {
    let (src_chunks, dst_chunks) = (
        src.cast::<MaybeUninit<Chunk>>(),
        dst.cast::<MaybeUninit<Chunk>>(),
    );
    for i in 0..chunks::<T>() {
        // SAFETY: as in `store_chunks`: in bounds, aligned, any bytes.
        unsafe {
            dst_chunks
                .add(i)
                .write(ptr::read_volatile(src_chunks.add(i)))
        };
    }
    if tail_word::<T>() {
        let at = chunks::<T>() * std::mem::size_of::<Chunk>();
        // SAFETY: as in `store_chunks`.
        unsafe {
            let (s, d) = (
                src.byte_add(at).cast::<MaybeUninit<u64>>(),
                dst.byte_add(at).cast::<MaybeUninit<u64>>(),
            );
            d.write(ptr::read_volatile(s));
        }
    }
}

/// A `T` that is stored as whole chunks (as [`SeqLock::write`] stores
/// them), for a value written in one
/// step of a cycle and read back in a later one (a subordinate's pending
/// command, written at `send` and copied to Global Memory at `flush`). Read
/// back soon after a plain store of a struct, loads the compiler widened
/// over several narrow field stores stall the CPU (see the module docs);
/// loads from a value stored as chunks are always forwarded.
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

    /// Replace the value, storing it chunk by chunk.
    #[inline]
    pub(crate) fn set(&mut self, value: T) {
        // SAFETY: `&mut self` makes the slot ours alone; the words written
        // are those of a valid `T`.
        unsafe { store_chunks(&raw mut self.words, value) };
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
        // The odd counter needs no ordering of its own: the release fence
        // after it keeps it before every data store below (a reader that
        // sees any of the new chunks, and then passes its acquire fence,
        // must see `seq` at `s + 1` or later, and retries). On x86_64 both
        // fences are compiler barriers only (TSO keeps stores in order); on
        // weaker CPUs the release fence is the one barrier a write pays.
        self.seq.store(s.wrapping_add(1), Ordering::Relaxed);
        fence(Ordering::Release);
        // SAFETY: `data` is valid for writes; the caller excludes other
        // writers; readers that overlap these stores discard what they copied.
        unsafe { store_chunks(self.data.get(), value) };
        // Release: the data stores above happen before this even counter,
        // so a reader whose first (acquire) load sees it also sees the
        // whole value.
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
        // SAFETY: `data` is a valid `Words<T>` for reads (the writer may be
        // storing into it; then the copy is garbage and thrown away below)
        // and `copy` one for writes. The copy is only assumed initialised
        // after the sequence check.
        unsafe { load_chunks(self.data.get().cast_const(), &raw mut copy) };
        // Acquire fence, then a relaxed load: the chunk loads above stay
        // before the second counter load. If any of them saw a store of a
        // later write, that write's odd counter (kept before its stores by
        // the writer's release fence) is visible to `s2`, so `s1 != s2`.
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
    use super::{chunks, tail_word, Chunk, SeqLock, Staged, Words};
    use std::mem::{align_of, size_of};
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

    /// The chunks and the tail word cover `T` rounded up to 8 bytes, and
    /// fit in a `Words<T>` (also checked at compile time).
    fn covered<T>() -> usize {
        let covered = chunks::<T>() * size_of::<Chunk>() + usize::from(tail_word::<T>()) * 8;
        assert!(covered >= size_of::<T>());
        assert!(covered < size_of::<T>() + 8);
        assert!(covered <= size_of::<Words<T>>());
        assert_eq!(align_of::<Words<T>>() % align_of::<Chunk>(), 0);
        covered
    }

    #[test]
    fn chunks_cover_the_value_padded_to_eight_bytes() {
        assert_eq!(covered::<()>(), 0);
        assert_eq!(covered::<u8>(), 8);
        assert_eq!(covered::<[u8; 8]>(), 8);
        assert_eq!(covered::<[u8; 9]>(), 16);
        assert_eq!(covered::<Odd>(), 8);
        assert_eq!(covered::<Mixed>(), 24);
        assert_eq!(covered::<u128>(), 16);
        assert_eq!(covered::<([u64; 8], u64)>(), 72);
        assert_eq!(covered::<([u64; 64], u64)>(), 520);
        assert!(align_of::<Words<u128>>() >= 16);
        if cfg!(target_arch = "x86_64") {
            // 16-byte chunks, and a word when a multiple of 8 is left.
            assert_eq!(size_of::<Chunk>(), 16);
            assert_eq!((chunks::<[u8; 9]>(), tail_word::<[u8; 9]>()), (1, false));
            assert_eq!((chunks::<Mixed>(), tail_word::<Mixed>()), (1, true));
            assert_eq!((chunks::<u8>(), tail_word::<u8>()), (0, true));
            assert_eq!(
                (chunks::<([u64; 8], u64)>(), tail_word::<([u64; 8], u64)>()),
                (4, true)
            );
        } else {
            assert_eq!(size_of::<Chunk>(), 8);
            assert!(!tail_word::<Mixed>());
        }
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

    /// A value the stress test writes as its `n`-th write; `whole` gives
    /// `n` back only if every part of the value agrees (a torn read mixes
    /// two writes).
    trait Pattern: Copy + Send + 'static {
        fn nth(n: u64) -> Self;
        fn whole(&self) -> Option<u64>;
    }

    /// 136 bytes: on x86_64 eight 16-byte chunks and a tail word (the flag).
    #[derive(Clone, Copy)]
    struct Wide {
        words: [u64; 16],
        flag: bool,
    }

    impl Pattern for Wide {
        fn nth(n: u64) -> Self {
            Self {
                words: [n; 16],
                flag: n % 2 == 1,
            }
        }
        fn whole(&self) -> Option<u64> {
            let w0 = self.words[0];
            (self.words.iter().all(|&w| w == w0) && self.flag == (w0 % 2 == 1)).then_some(w0)
        }
    }

    /// 64 bytes: whole chunks, no tail word.
    #[derive(Clone, Copy)]
    struct Exact([u64; 8]);

    impl Pattern for Exact {
        fn nth(n: u64) -> Self {
            Self([n; 8])
        }
        fn whole(&self) -> Option<u64> {
            self.0.iter().all(|&w| w == self.0[0]).then_some(self.0[0])
        }
    }

    /// 8 bytes with padding: no chunk, the tail word alone (x86_64).
    #[derive(Clone, Copy)]
    struct Small {
        n: u32,
        odd: bool,
    }

    impl Pattern for Small {
        fn nth(n: u64) -> Self {
            Self {
                n: n as u32,
                odd: n % 2 == 1,
            }
        }
        fn whole(&self) -> Option<u64> {
            (self.odd == (self.n % 2 == 1)).then_some(u64::from(self.n))
        }
    }

    /// 24 bytes with padding inside the chunk: a chunk and a tail word.
    #[derive(Clone, Copy)]
    struct Padded {
        a: u8,
        x: u64,
        b: u16,
    }

    impl Pattern for Padded {
        fn nth(n: u64) -> Self {
            Self {
                a: n as u8,
                x: n,
                b: n as u16,
            }
        }
        fn whole(&self) -> Option<u64> {
            (self.a == self.x as u8 && self.b == self.x as u16).then_some(self.x)
        }
    }

    /// One writer and three readers hammer a cell; every read must be one
    /// whole write, the one its generation names, and generations never go
    /// back. (The protocol under real concurrency, for each copy shape.)
    fn stress<T: Pattern>(writes: u64) {
        // Fewer iterations under Miri, which is orders of magnitude slower.
        let writes: u64 = if cfg!(miri) { 200 } else { writes };
        let lock = Arc::new(SeqLock::new(T::nth(0)));
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
                        let n = v.whole().expect("torn read");
                        // The value written by the n-th write is n (fewer
                        // than 2^32 writes: `Small` keeps 32 bits of it).
                        assert_eq!(n, g, "value and generation disagree");
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
            unsafe { lock.write(T::nth(i)) };
        }
        done.store(true, Ordering::Relaxed);
        for r in readers {
            let reads = r.join().expect("reader thread panicked");
            assert!(reads > 0);
        }
        assert_eq!(lock.read().1, writes);
    }

    #[test]
    fn stress_no_torn_reads() {
        stress::<Wide>(200_000);
    }

    #[test]
    fn stress_no_torn_reads_of_every_copy_shape() {
        stress::<Exact>(100_000);
        stress::<Small>(100_000);
        stress::<Padded>(100_000);
    }

    /// The reader's side of the protocol, step by step: an odd counter (a
    /// write in progress) is refused, an even one accepted with its
    /// generation.
    #[test]
    fn a_reader_refuses_a_write_in_progress() {
        let l = SeqLock::new(Padded::nth(5));
        // SAFETY: single writer in this test.
        unsafe { l.write(Padded::nth(6)) };
        // What a writer does before its stores.
        l.seq.store(3, Ordering::Relaxed);
        assert!(l.try_read().is_none());
        assert_eq!(l.generation(), 1);
        l.seq.store(4, Ordering::Relaxed);
        let (v, g) = l.try_read().expect("an even counter");
        assert_eq!((v.whole(), g), (Some(6), 2));
    }
}
