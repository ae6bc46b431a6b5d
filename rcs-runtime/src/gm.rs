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
        self.declare_erased(name, TypeKey::of::<T>())
    }

    /// The writer of buffer `name`. Only one is ever handed out per buffer.
    pub fn writer<T: BufferData>(&self, name: &str) -> Result<Writer<T>, SetupError> {
        let (cell, name) = self.handle_erased(name, TypeKey::of::<T>(), true)?;
        Ok(Writer {
            cell: typed_cell::<T>(cell, &name)?,
            name,
        })
    }

    /// A reader of buffer `name`; any number may exist.
    pub fn reader<T: BufferData>(&self, name: &str) -> Result<Reader<T>, SetupError> {
        let (cell, name) = self.handle_erased(name, TypeKey::of::<T>(), false)?;
        Ok(Reader {
            cell: typed_cell::<T>(cell, &name)?,
            name,
        })
    }

    // The type-erased cores of the typed calls above: every generic method
    // of Global Memory is a thin wrapper over one of these, so a plan set
    // with a hundred command types instantiates a hundred small wrappers,
    // not a hundred copies of the map lookups and error paths (issue 30).

    fn declare_erased(&self, name: &str, key: TypeKey) -> Result<(), SetupError> {
        let mut map = self.lock();
        match map.get(name) {
            Some(e) => e.check(name, key),
            None => {
                map.insert(
                    name.to_owned(),
                    Entry {
                        type_id: key.id,
                        type_name: key.name,
                        cell: (key.new_cell)(),
                        writer_taken: false,
                    },
                );
                Ok(())
            }
        }
    }

    /// The cell of buffer `name`, checked to hold `key`'s type, and the
    /// name to keep in the handle; takes the one writer if `writer`.
    fn handle_erased(
        &self,
        name: &str,
        key: TypeKey,
        writer: bool,
    ) -> Result<(AnyCell, Arc<str>), SetupError> {
        let mut map = self.lock();
        let entry = map
            .get_mut(name)
            .ok_or_else(|| SetupError::UnknownBuffer(name.to_owned()))?;
        entry.check(name, key)?;
        if writer {
            if entry.writer_taken {
                return Err(SetupError::WriterTaken(name.to_owned()));
            }
            entry.writer_taken = true;
        }
        Ok((Arc::clone(&entry.cell), name.into()))
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
        self.declare_controller_erased(ctrl, TypeKey::of::<CommandBuffer<C>>())
    }

    pub(crate) fn declare_controller_erased(
        &self,
        ctrl: &str,
        command: TypeKey,
    ) -> Result<(), SetupError> {
        self.declare_erased(&command_buffer_name(ctrl), command)?;
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

    /// [`Setup`](crate::Setup)'s way to a handle: the cell of buffer `name`
    /// as [`GlobalMemory::writer`] or [`GlobalMemory::reader`] would give
    /// it, or, if that fails, the error recorded in `errors` and a cell of
    /// the right type that no Global Memory knows (a stand-in that never
    /// reaches a running system).
    pub(crate) fn handle_or_stand_in(
        &self,
        name: &str,
        key: TypeKey,
        writer: bool,
        errors: &mut Vec<SetupError>,
    ) -> (AnyCell, Arc<str>) {
        self.handle_erased(name, key, writer).unwrap_or_else(|e| {
            errors.push(e);
            ((key.new_cell)(), name.into())
        })
    }

    /// What a supervisor (or the operator) holds of controller `ctrl`: its
    /// buffers declared if needed, the writer of its command buffer (taken:
    /// this is its one supervisor) and a reader of its status.
    pub(crate) fn supervise<C: Command>(
        &self,
        ctrl: &str,
    ) -> Result<(Writer<CommandBuffer<C>>, Reader<StatusBuffer>), SetupError> {
        // The typed step last: no error path drops a typed handle.
        self.declare_controller::<C>(ctrl)?;
        let status = self.status_reader(ctrl)?;
        Ok((self.command_writer::<C>(ctrl)?, status))
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

/// A buffer's cell with its type erased, as Global Memory keeps it.
pub(crate) type AnyCell = Arc<dyn Any + Send + Sync>;

/// What the type-erased cores need of a buffer's type: its id and name to
/// check a handle against the declaration, and how to make its cell.
#[derive(Clone, Copy)]
pub(crate) struct TypeKey {
    id: TypeId,
    name: &'static str,
    new_cell: fn() -> AnyCell,
}

impl TypeKey {
    #[inline]
    pub(crate) fn of<T: BufferData>() -> Self {
        Self {
            id: TypeId::of::<T>(),
            name: type_name::<T>(),
            new_cell: new_cell::<T>,
        }
    }
}

fn new_cell<T: BufferData>() -> AnyCell {
    fresh_cell::<T>()
}

/// A new cell holding `T::default()`, never written. Out of line: one copy
/// per buffer type serves the declaration and every stand-in.
#[inline(never)]
fn fresh_cell<T: BufferData>() -> Arc<Cell<T>> {
    Arc::new(Cell::<T>::new((T::default(), 0)))
}

impl Entry {
    fn check(&self, name: &str, key: TypeKey) -> Result<(), SetupError> {
        if self.type_id == key.id {
            Ok(())
        } else {
            Err(mismatch(name, self.type_name, key.name))
        }
    }
}

#[cold]
fn mismatch(name: &str, declared: &'static str, requested: &'static str) -> SetupError {
    SetupError::TypeMismatch {
        name: name.to_owned(),
        declared,
        requested,
    }
}

/// The typed cell of an entry already checked to hold a `T`: the downcast
/// cannot fail then, but a failure is still an error, not a panic.
#[inline]
fn typed_cell<T: BufferData>(cell: AnyCell, name: &str) -> Result<Arc<Cell<T>>, SetupError> {
    cell.downcast::<Cell<T>>()
        .map_err(|_| mismatch(name, "another type", type_name::<T>()))
}

/// The typed cell of a cell [`GlobalMemory::handle_or_stand_in`] gave: it
/// holds a `T` (checked, or made for one), so the fresh stand-in here is
/// only there to need no panic.
pub(crate) fn cell_or_stand_in<T: BufferData>(cell: AnyCell) -> Arc<Cell<T>> {
    match cell.downcast::<Cell<T>>() {
        Ok(cell) => cell,
        Err(other) => stand_in(other),
    }
}

/// The cold end of [`cell_or_stand_in`]: drop the cell of another type
/// (never met: the cores check the type) and make a fresh one.
#[cold]
#[inline(never)]
fn stand_in<T: BufferData>(other: AnyCell) -> Arc<Cell<T>> {
    drop(other);
    fresh_cell()
}

/// The single writer of one buffer. Not `Clone`; `write` takes `&mut self`,
/// so two writes to one buffer can never overlap.
pub struct Writer<T> {
    cell: Arc<Cell<T>>,
    name: Arc<str>,
}

impl<T: BufferData> Writer<T> {
    /// The writer of a cell [`GlobalMemory::handle_or_stand_in`] gave.
    pub(crate) fn from_parts((cell, name): (AnyCell, Arc<str>)) -> Self {
        Self {
            cell: cell_or_stand_in(cell),
            name,
        }
    }

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

/// The single writer of one buffer with its type erased: the operator
/// keeps a root's command writer so (one non-generic operator core for
/// every command type) and writes through it with the type it was made
/// for.
pub(crate) struct ErasedWriter {
    writer: Box<dyn Any + Send>,
    name: Arc<str>,
}

impl ErasedWriter {
    /// `writer`, its type erased.
    pub(crate) fn new<T: BufferData>(writer: Writer<T>) -> Self {
        let name = Arc::clone(&writer.name);
        Self {
            writer: Box::new(writer),
            name,
        }
    }

    /// The writer of a cell [`GlobalMemory::handle_or_stand_in`] gave, as a
    /// `T` buffer's.
    pub(crate) fn of<T: BufferData>(parts: (AnyCell, Arc<str>)) -> Self {
        Self::new(Writer::<T>::from_parts(parts))
    }

    /// Publish `value` as [`Writer::write`] does, if this is the writer of
    /// a `T` buffer (`None`, nothing written, otherwise).
    #[inline]
    pub(crate) fn write<T: BufferData>(&mut self, value: T, cycle: u64) -> Option<u64> {
        let writer = self.writer.downcast_mut::<Writer<T>>()?;
        Some(writer.write(value, cycle))
    }
}

impl fmt::Debug for ErasedWriter {
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
    /// A reader of a cell [`GlobalMemory::handle_or_stand_in`] gave.
    pub(crate) fn from_parts((cell, name): (AnyCell, Arc<str>)) -> Self {
        Self {
            cell: cell_or_stand_in(cell),
            name,
        }
    }

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
