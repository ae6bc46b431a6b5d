//! Global Memory: named, typed buffers with one writer and many readers
//! (§3.8.3, §3.8.5 of the methodology).
//!
//! Every controller, simulator, sensor driver and operator interface talks to
//! the others only through these buffers. A buffer holds a `Copy` value of a
//! fixed size; it starts as `T::default()` (the "all zeros" value of
//! generated buffer types). Each write stamps the buffer with its generation
//! (how many writes so far, 0 = never written) and the writer's cycle count.
//!
//! The one-writer rule is enforced by the API: [`GlobalMemory::writer`] hands
//! out one non-`Clone` [`Writer`] per buffer and refuses a second one.
//! [`Reader`]s are `Clone` and can be had any number of times. Readers and
//! writers may live on different threads (several executives share one
//! Global Memory); a read never blocks the writer and never returns a torn
//! value (the private `seqlock` module explains how).
//!
//! Looking buffers up by name happens at setup and takes a lock; reading and
//! writing through the handles afterwards is lock-free and allocation-free.

use std::any::{type_name, Any, TypeId};
use std::collections::BTreeMap;
use std::fmt;
use std::sync::{Arc, Mutex, MutexGuard};

use crate::error::SetupError;
use crate::handshake::{Command, CommandBuffer, StatusBuffer};
use crate::seqlock::SeqLock;

/// What a Global Memory buffer may hold: plain, fixed-size, thread-safe data
/// whose `Default` is the value before the first write.
pub trait BufferData: Copy + Default + Send + 'static {}
impl<T: Copy + Default + Send + 'static> BufferData for T {}

/// A value read from Global Memory with the stamps of the write that put it
/// there.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stamped<T> {
    /// The buffer's contents.
    pub value: T,
    /// How many times the buffer has been written (0: never).
    pub generation: u64,
    /// The writer's cycle count at that write (0 before the first write).
    pub writer_cycle: u64,
}

type Cell<T> = SeqLock<(T, u64)>;

struct Entry {
    type_id: TypeId,
    type_name: &'static str,
    cell: Arc<dyn Any + Send + Sync>,
    writer_taken: bool,
}

/// The shared store of named buffers. Cheap to clone: clones share the same
/// buffers.
#[derive(Clone, Default)]
pub struct GlobalMemory {
    entries: Arc<Mutex<BTreeMap<String, Entry>>>,
}

impl fmt::Debug for GlobalMemory {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("GlobalMemory")
            .field("buffers", &self.names())
            .finish()
    }
}

impl GlobalMemory {
    /// An empty Global Memory.
    pub fn new() -> Self {
        Self::default()
    }

    fn lock(&self) -> MutexGuard<'_, BTreeMap<String, Entry>> {
        // Setup only; a poisoned map is still a consistent map.
        self.entries.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Declare buffer `name` holding a `T`. Declaring it again with the same
    /// type is allowed and changes nothing; another type is an error.
    pub fn declare<T: BufferData>(&self, name: &str) -> Result<(), SetupError> {
        let mut map = self.lock();
        match map.get(name) {
            Some(e) => check_type::<T>(name, e),
            None => {
                let cell: Arc<Cell<T>> = Arc::new(SeqLock::new((T::default(), 0)));
                map.insert(
                    name.to_owned(),
                    Entry {
                        type_id: TypeId::of::<T>(),
                        type_name: type_name::<T>(),
                        cell,
                        writer_taken: false,
                    },
                );
                Ok(())
            }
        }
    }

    /// The writer of buffer `name`. Only one is ever handed out per buffer.
    pub fn writer<T: BufferData>(&self, name: &str) -> Result<Writer<T>, SetupError> {
        let mut map = self.lock();
        let entry = map
            .get_mut(name)
            .ok_or_else(|| SetupError::UnknownBuffer(name.to_owned()))?;
        let cell = downcast::<T>(name, entry)?;
        if entry.writer_taken {
            return Err(SetupError::WriterTaken(name.to_owned()));
        }
        entry.writer_taken = true;
        Ok(Writer {
            cell,
            name: name.into(),
        })
    }

    /// A reader of buffer `name`; any number may exist.
    pub fn reader<T: BufferData>(&self, name: &str) -> Result<Reader<T>, SetupError> {
        let map = self.lock();
        let entry = map
            .get(name)
            .ok_or_else(|| SetupError::UnknownBuffer(name.to_owned()))?;
        let cell = downcast::<T>(name, entry)?;
        Ok(Reader {
            cell,
            name: name.into(),
        })
    }

    /// The names of all declared buffers, sorted.
    pub fn names(&self) -> Vec<String> {
        self.lock().keys().cloned().collect()
    }

    /// Whether `name` has a writer yet (a buffer without one is an external
    /// input nobody feeds).
    pub fn has_writer(&self, name: &str) -> bool {
        self.lock().get(name).is_some_and(|e| e.writer_taken)
    }

    /// Declare controller `ctrl`'s command buffer (`CommandBuffer<C>`, named
    /// [`command_buffer_name`]) and status buffer (`StatusBuffer`, named
    /// [`status_buffer_name`]).
    pub fn declare_controller<C: Command>(&self, ctrl: &str) -> Result<(), SetupError> {
        self.declare::<CommandBuffer<C>>(&command_buffer_name(ctrl))?;
        self.declare::<StatusBuffer>(&status_buffer_name(ctrl))
    }

    /// The writer of `ctrl`'s command buffer (held by its supervisor, or by
    /// the operator for a root controller).
    pub fn command_writer<C: Command>(
        &self,
        ctrl: &str,
    ) -> Result<Writer<CommandBuffer<C>>, SetupError> {
        self.writer(&command_buffer_name(ctrl))
    }

    /// A reader of `ctrl`'s command buffer (the controller itself reads it).
    pub fn command_reader<C: Command>(
        &self,
        ctrl: &str,
    ) -> Result<Reader<CommandBuffer<C>>, SetupError> {
        self.reader(&command_buffer_name(ctrl))
    }

    /// The writer of `ctrl`'s status buffer (held by the controller itself).
    pub fn status_writer(&self, ctrl: &str) -> Result<Writer<StatusBuffer>, SetupError> {
        self.writer(&status_buffer_name(ctrl))
    }

    /// A reader of `ctrl`'s status buffer (its supervisor, the operator, a
    /// display…).
    pub fn status_reader(&self, ctrl: &str) -> Result<Reader<StatusBuffer>, SetupError> {
        self.reader(&status_buffer_name(ctrl))
    }
}

/// The Global Memory name of controller `ctrl`'s command buffer: `CTRL.command`.
pub fn command_buffer_name(ctrl: &str) -> String {
    format!("{ctrl}.command")
}

/// The Global Memory name of controller `ctrl`'s status buffer: `CTRL.status`.
pub fn status_buffer_name(ctrl: &str) -> String {
    format!("{ctrl}.status")
}

/// The Global Memory name of the buffer holding controller `ctrl`'s status
/// fields (`status NAME: TYPE`): `CTRL.status_fields`. Written in step 5
/// beside the status buffer; a supervisor reads it whatever serial the
/// status buffer echoes.
pub fn status_fields_buffer_name(ctrl: &str) -> String {
    format!("{ctrl}.status_fields")
}

fn check_type<T: 'static>(name: &str, e: &Entry) -> Result<(), SetupError> {
    if e.type_id == TypeId::of::<T>() {
        Ok(())
    } else {
        Err(SetupError::TypeMismatch {
            name: name.to_owned(),
            declared: e.type_name,
            requested: type_name::<T>(),
        })
    }
}

fn downcast<T: BufferData>(name: &str, e: &Entry) -> Result<Arc<Cell<T>>, SetupError> {
    check_type::<T>(name, e)?;
    Arc::clone(&e.cell)
        .downcast::<Cell<T>>()
        .map_err(|_| SetupError::TypeMismatch {
            name: name.to_owned(),
            declared: e.type_name,
            requested: type_name::<T>(),
        })
}

/// The single writer of one buffer. Not `Clone`; `write` takes `&mut self`,
/// so two writes to one buffer can never overlap.
pub struct Writer<T> {
    cell: Arc<Cell<T>>,
    name: Arc<str>,
}

impl<T: BufferData> Writer<T> {
    /// Publish `value`, stamped with the writer's `cycle` count. Returns the
    /// buffer's new generation. Lock-free, allocation-free, wait-free.
    #[inline]
    pub fn write(&mut self, value: T, cycle: u64) -> u64 {
        // SAFETY: this `Writer` is the only one for the cell (GlobalMemory
        // hands out one and it is not `Clone`), and `&mut self` excludes two
        // overlapping calls through it.
        unsafe { self.cell.write((value, cycle)) }
    }

    /// Read back the buffer (the writer's own last value and stamps).
    #[inline]
    pub fn read(&self) -> Stamped<T> {
        read_cell(&self.cell)
    }

    /// The buffer's name in Global Memory.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl<T> fmt::Debug for Writer<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Writer").field("name", &self.name).finish()
    }
}

/// A reader of one buffer. `Clone`, `Send` and `Sync`: share it freely.
pub struct Reader<T> {
    cell: Arc<Cell<T>>,
    name: Arc<str>,
}

impl<T> Clone for Reader<T> {
    fn clone(&self) -> Self {
        Self {
            cell: Arc::clone(&self.cell),
            name: Arc::clone(&self.name),
        }
    }
}

impl<T: BufferData> Reader<T> {
    /// A whole, consistent copy of the buffer with its stamps. Never blocks
    /// the writer; retries if it overlapped a write.
    #[inline]
    pub fn read(&self) -> Stamped<T> {
        read_cell(&self.cell)
    }

    /// The buffer's current generation (0: never written), without copying.
    #[inline]
    pub fn generation(&self) -> u64 {
        self.cell.generation()
    }

    /// The buffer's name in Global Memory.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl<T> fmt::Debug for Reader<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Reader").field("name", &self.name).finish()
    }
}

#[inline]
fn read_cell<T: BufferData>(cell: &Cell<T>) -> Stamped<T> {
    let ((value, writer_cycle), generation) = cell.read();
    Stamped {
        value,
        generation,
        writer_cycle,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, Default, PartialEq)]
    struct Ship {
        speed: f64,
        ahead: bool,
    }

    #[test]
    fn starts_at_default_generation_zero() {
        let gm = GlobalMemory::new();
        gm.declare::<Ship>("ship").unwrap();
        let r = gm.reader::<Ship>("ship").unwrap();
        assert_eq!(r.read(), Stamped::default());
        assert_eq!(r.generation(), 0);
    }

    #[test]
    fn write_stamps_generation_and_cycle() {
        let gm = GlobalMemory::new();
        gm.declare::<Ship>("ship").unwrap();
        let mut w = gm.writer::<Ship>("ship").unwrap();
        let r = gm.reader::<Ship>("ship").unwrap();
        let r2 = r.clone();
        let v = Ship {
            speed: 3.5,
            ahead: true,
        };
        assert_eq!(w.write(v, 41), 1);
        assert_eq!(w.write(v, 42), 2);
        let s = r2.read();
        assert_eq!((s.value, s.generation, s.writer_cycle), (v, 2, 42));
        assert_eq!(w.read(), s);
        assert_eq!(r.name(), "ship");
    }

    #[test]
    fn second_writer_is_a_setup_error() {
        let gm = GlobalMemory::new();
        gm.declare::<u32>("x").unwrap();
        let _w = gm.writer::<u32>("x").unwrap();
        assert_eq!(
            gm.writer::<u32>("x").unwrap_err(),
            SetupError::WriterTaken("x".into())
        );
        assert!(gm.has_writer("x"));
        // Readers are unlimited.
        assert!(gm.reader::<u32>("x").is_ok());
        assert!(gm.reader::<u32>("x").is_ok());
    }

    #[test]
    fn unknown_buffer_and_type_mismatch() {
        let gm = GlobalMemory::new();
        assert_eq!(
            gm.reader::<u32>("nope").unwrap_err(),
            SetupError::UnknownBuffer("nope".into())
        );
        assert!(matches!(
            gm.writer::<u32>("nope"),
            Err(SetupError::UnknownBuffer(_))
        ));
        gm.declare::<u32>("x").unwrap();
        gm.declare::<u32>("x").unwrap(); // same type: fine
        assert!(matches!(
            gm.declare::<u64>("x"),
            Err(SetupError::TypeMismatch { .. })
        ));
        let e = gm.reader::<f64>("x").unwrap_err();
        assert!(matches!(e, SetupError::TypeMismatch { .. }));
        assert!(e.to_string().contains("`x`"));
    }

    #[test]
    fn clones_share_buffers() {
        let gm = GlobalMemory::new();
        let gm2 = gm.clone();
        gm.declare::<u8>("a").unwrap();
        let mut w = gm2.writer::<u8>("a").unwrap();
        w.write(9, 1);
        assert_eq!(gm.reader::<u8>("a").unwrap().read().value, 9);
        assert_eq!(gm.names(), vec!["a".to_string()]);
    }

    #[test]
    fn readers_on_other_threads_see_whole_values() {
        #[derive(Clone, Copy, Default)]
        struct Pair {
            a: u64,
            b: u64,
        }
        let gm = GlobalMemory::new();
        gm.declare::<Pair>("p").unwrap();
        let mut w = gm.writer::<Pair>("p").unwrap();
        let r = gm.reader::<Pair>("p").unwrap();
        let n = if cfg!(miri) { 100 } else { 50_000 };
        let t = std::thread::spawn(move || {
            let mut last = 0;
            loop {
                let s = r.read();
                assert_eq!(s.value.a, s.value.b);
                assert_eq!(s.value.a, s.writer_cycle);
                assert!(s.generation >= last);
                last = s.generation;
                if s.value.a == n {
                    break;
                }
            }
        });
        for i in 1..=n {
            w.write(Pair { a: i, b: i }, i);
        }
        t.join().unwrap();
    }
}
