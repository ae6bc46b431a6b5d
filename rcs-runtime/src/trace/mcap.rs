//! The MCAP encoding of a trace (feature `mcap`; docs/trace-format.md,
//! "MCAP"): a recording that Foxglove, Lichtblick and PlotJuggler open as
//! it is. It sits beside the JSON-lines encoding behind the same
//! [`TraceSink`](super::TraceSink), and [`read_mcap`] reads it back into
//! the same [`TraceRecord`]s, so `rcsc trace` sums either alike.
//!
//! Layout: an `rcs-trace` metadata record (format, version, the writer's
//! `generated` marker, which is also in the header's `library` field: the
//! first bytes of the file, where rcsc's writer looks for it); one channel
//! per controller, topic `/rcs/<executive>/<controller>`, whose JSON
//! messages are the [`TraceRecord`] plus the names and times of a
//! [`TraceDetail`], with the JSON Schema [`CONTROLLER_SCHEMA`]; and one
//! channel per Global Memory buffer whose values the writer has, topic
//! `/rcs/<executive>/gm/<buffer>` ([`BufferSample`]). Chunked, not
//! compressed (compression would compile C code into rcs-runtime).

use std::collections::BTreeMap;
use std::io::{self, Seek, Write};

use serde::Serialize;

use super::jsonl::check_header;
use super::{buffer_topic, controller_topic, TraceDetail, TraceHeader, TraceRecord, TRACE_FORMAT};
pub use super::{CONTROLLER_SCHEMA, CONTROLLER_SCHEMA_NAME};

/// A writer an MCAP sink can own: MCAP seeks back to finish its chunks.
pub trait SeekWrite: Write + Seek + Send {}
impl<T: Write + Seek + Send> SeekWrite for T {}

/// The name of the metadata record that says a recording is an rcs trace.
pub const METADATA_NAME: &str = "rcs-trace";
/// Channel metadata key naming what a channel carries (`controller` or
/// `buffer`).
pub const KIND_KEY: &str = "rcs.kind";

/// One Global Memory buffer's value after a cycle, for its channel.
#[derive(Debug, Clone, Copy)]
pub struct BufferSample<'a> {
    /// The executive whose cycle wrote it.
    pub executive: &'a str,
    /// The buffer's name.
    pub buffer: &'a str,
    /// The controller that writes it.
    pub writer: &'a str,
    /// The executive's cycle count.
    pub cycle: u64,
    /// The log time, in nanoseconds.
    pub time_ns: u64,
    /// The schema's name (the buffer type's, say `rcs.buffer.Speed`).
    pub schema_name: &'a str,
    /// The JSON Schema of `value`.
    pub schema: &'a str,
    /// The buffer's value.
    pub value: &'a serde_json::Value,
}

/// A controller's message: the record, then what the writer knows beyond
/// (its time always: the message's log time).
#[derive(Serialize)]
struct ControllerMessage<'a, S: AsRef<str> + Serialize> {
    #[serde(flatten)]
    record: &'a TraceRecord<S>,
    #[serde(flatten)]
    detail: TraceDetail<'a>,
}

#[derive(Serialize)]
struct BufferMessage<'a> {
    executive: &'a str,
    buffer: &'a str,
    writer: &'a str,
    cycle: u64,
    time_ns: u64,
    value: &'a serde_json::Value,
}

/// A channel of the recording: whose it is, its id, its next sequence.
struct Channel {
    executive: String,
    name: String,
    buffer: bool,
    id: u16,
    sequence: u32,
}

/// An MCAP recording being written.
pub(super) struct McapTrace {
    /// `None` once finished.
    writer: Option<::mcap::Writer<Box<dyn SeekWrite>>>,
    controller_schema: u16,
    channels: Vec<Channel>,
}

fn io_error(e: ::mcap::McapError) -> io::Error {
    match e {
        ::mcap::McapError::Io(e) => e,
        other => io::Error::other(other),
    }
}

fn finished() -> io::Error {
    io::Error::other("the MCAP recording is already finished")
}

/// Nanoseconds since the Unix epoch, now (a record written without a time).
fn now_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX))
        .unwrap_or(0)
}

impl McapTrace {
    /// Start a recording: MCAP header (its `library` naming the writer and
    /// carrying `header.generated`), the `rcs-trace` metadata, the
    /// controller schema.
    pub(super) fn start(out: Box<dyn SeekWrite>, header: &TraceHeader) -> io::Result<Self> {
        let library = match &header.generated {
            Some(g) => format!("{g}; rcs-runtime {}", env!("CARGO_PKG_VERSION")),
            None => format!("rcs-runtime {}", env!("CARGO_PKG_VERSION")),
        };
        let options = ::mcap::WriteOptions::new()
            .compression(None)
            .library(library)
            .profile("");
        let mut writer = options.create(out).map_err(io_error)?;
        let mut metadata = BTreeMap::new();
        metadata.insert("format".to_string(), header.format.clone());
        metadata.insert("version".to_string(), header.version.to_string());
        if let Some(g) = &header.generated {
            metadata.insert("generated".to_string(), g.clone());
        }
        writer
            .write_metadata(&::mcap::records::Metadata {
                name: METADATA_NAME.to_string(),
                metadata,
            })
            .map_err(io_error)?;
        let controller_schema = writer
            .add_schema(
                CONTROLLER_SCHEMA_NAME,
                "jsonschema",
                CONTROLLER_SCHEMA.as_bytes(),
            )
            .map_err(io_error)?;
        Ok(McapTrace {
            writer: Some(writer),
            controller_schema,
            channels: Vec::new(),
        })
    }

    /// The channel of `executive`'s `name` (a controller, or a buffer),
    /// added on first use; its index in `self.channels`.
    fn channel(
        &mut self,
        executive: &str,
        name: &str,
        buffer: Option<(&str, &str)>,
    ) -> io::Result<usize> {
        let is_buffer = buffer.is_some();
        if let Some(i) = self
            .channels
            .iter()
            .position(|c| c.buffer == is_buffer && c.name == name && c.executive == executive)
        {
            return Ok(i);
        }
        let writer = self.writer.as_mut().ok_or_else(finished)?;
        let (schema, topic, kind) = match buffer {
            None => (
                self.controller_schema,
                controller_topic(executive, name),
                "controller",
            ),
            Some((schema_name, schema)) => (
                writer
                    .add_schema(schema_name, "jsonschema", schema.as_bytes())
                    .map_err(io_error)?,
                buffer_topic(executive, name),
                "buffer",
            ),
        };
        let mut metadata = BTreeMap::new();
        metadata.insert(KIND_KEY.to_string(), kind.to_string());
        metadata.insert("rcs.executive".to_string(), executive.to_string());
        metadata.insert(format!("rcs.{kind}"), name.to_string());
        let id = writer
            .add_channel(schema, &topic, "json", &metadata)
            .map_err(io_error)?;
        self.channels.push(Channel {
            executive: executive.to_string(),
            name: name.to_string(),
            buffer: is_buffer,
            id,
            sequence: 0,
        });
        Ok(self.channels.len() - 1)
    }

    /// Write one message on channel `i`.
    fn message(&mut self, i: usize, time_ns: u64, data: &[u8]) -> io::Result<()> {
        let writer = self.writer.as_mut().ok_or_else(finished)?;
        let channel = &mut self.channels[i];
        let header = ::mcap::records::MessageHeader {
            channel_id: channel.id,
            sequence: channel.sequence,
            log_time: time_ns,
            publish_time: time_ns,
        };
        channel.sequence = channel.sequence.wrapping_add(1);
        writer
            .write_to_known_channel(&header, data)
            .map_err(io_error)
    }

    pub(super) fn write_record<S: AsRef<str> + Serialize>(
        &mut self,
        rec: &TraceRecord<S>,
        detail: &TraceDetail<'_>,
    ) -> io::Result<()> {
        let time_ns = detail.time_ns.unwrap_or_else(now_ns);
        let data = serde_json::to_vec(&ControllerMessage {
            record: rec,
            detail: TraceDetail {
                time_ns: Some(time_ns),
                ..*detail
            },
        })
        .map_err(io::Error::from)?;
        let i = self.channel(rec.executive.as_ref(), rec.controller.as_ref(), None)?;
        self.message(i, time_ns, &data)
    }

    pub(super) fn write_buffer(&mut self, s: &BufferSample<'_>) -> io::Result<()> {
        let data = serde_json::to_vec(&BufferMessage {
            executive: s.executive,
            buffer: s.buffer,
            writer: s.writer,
            cycle: s.cycle,
            time_ns: s.time_ns,
            value: s.value,
        })
        .map_err(io::Error::from)?;
        let i = self.channel(s.executive, s.buffer, Some((s.schema_name, s.schema)))?;
        self.message(i, s.time_ns, &data)
    }

    pub(super) fn flush(&mut self) -> io::Result<()> {
        match &mut self.writer {
            Some(w) => w.flush().map_err(io_error),
            None => Ok(()),
        }
    }

    /// Write the summary and closing magic, and flush the writer under it.
    pub(super) fn finish(&mut self) -> io::Result<()> {
        let Some(mut writer) = self.writer.take() else {
            return Ok(());
        };
        writer.finish().map_err(io_error)?;
        writer.into_inner().flush()
    }
}

/// What a reader says about an MCAP error.
fn describe(e: ::mcap::McapError) -> String {
    format!("not a readable MCAP recording: {e}")
}

/// Read an MCAP recording written by an rcs trace sink back into the
/// records of its controller channels, in the order written. `Err`: a
/// damaged or cut-short recording, or one that is no rcs trace (no
/// `rcs-trace` metadata, another format, a newer version), in words.
pub fn read_mcap(bytes: &[u8]) -> Result<Vec<TraceRecord>, String> {
    check_structure(bytes)?;
    let options = ::mcap::read::Options::ValidateChunkCrcs.into();
    let reader =
        ::mcap::read::ChunkFlattener::new_with_options(bytes, options).map_err(describe)?;
    let mut records = Vec::new();
    let mut controller_channels: BTreeMap<u16, String> = BTreeMap::new();
    let mut header = None;
    for record in reader {
        match record.map_err(describe)? {
            ::mcap::records::Record::Metadata(m) if m.name == METADATA_NAME => {
                let field = |k: &str| m.metadata.get(k).cloned().unwrap_or_default();
                let version = field("version");
                let h = TraceHeader {
                    format: field("format"),
                    version: version.parse().map_err(|_| {
                        format!(
                            "its `{METADATA_NAME}` metadata has no version number (`{version}`)"
                        )
                    })?,
                    generated: m.metadata.get("generated").cloned(),
                };
                check_header(&h)?;
                header = Some(h);
            }
            ::mcap::records::Record::Channel(c)
                if c.metadata.get(KIND_KEY).map(String::as_str) == Some("controller") =>
            {
                controller_channels.insert(c.id, c.topic);
            }
            ::mcap::records::Record::Message { header: m, data } => {
                if let Some(topic) = controller_channels.get(&m.channel_id) {
                    let rec = serde_json::from_slice(&data).map_err(|e| {
                        format!(
                            "message {} on `{topic}` is not a controller cycle: {e}",
                            m.sequence
                        )
                    })?;
                    records.push(rec);
                }
            }
            _ => {}
        }
    }
    if header.is_none() {
        return Err(format!(
            "an MCAP recording, but not an rcs trace (no `{METADATA_NAME}` metadata naming the format `{TRACE_FORMAT}`)"
        ));
    }
    Ok(records)
}

/// The opcode of a chunk record.
const OP_CHUNK: u8 = 0x06;

/// Check that every record, and every record inside an uncompressed chunk,
/// lies within its container, before the `mcap` crate reads the bytes:
/// its reader trusts an inner record's length (and overflows on one
/// longer than the chunk, a panic in a debug build).
fn check_structure(bytes: &[u8]) -> Result<(), String> {
    let magic = super::MCAP_MAGIC.len();
    let cut = |what: &str, at: usize| {
        format!("not a readable MCAP recording: {what} at byte {at} runs past its end (cut short or damaged)")
    };
    if bytes.len() < 2 * magic || !bytes.ends_with(super::MCAP_MAGIC) {
        return Err(
            "not a readable MCAP recording: it does not end with MCAP's magic bytes (cut short, or its writer stopped before finishing)"
                .to_string(),
        );
    }
    let end = bytes.len() - magic;
    let mut at = magic;
    while at < end {
        let (op, body) = record_at(bytes, at, end).ok_or_else(|| cut("a record", at))?;
        if op == OP_CHUNK {
            check_chunk(&bytes[body.clone()]).ok_or_else(|| cut("a record in the chunk", at))?;
        }
        at = body.end;
    }
    Ok(())
}

/// The opcode and body of the record at `at`, if it ends by `end`.
fn record_at(bytes: &[u8], at: usize, end: usize) -> Option<(u8, std::ops::Range<usize>)> {
    let op = *bytes.get(at)?;
    let len: [u8; 8] = bytes.get(at + 1..at + 9)?.try_into().ok()?;
    let len = usize::try_from(u64::from_le_bytes(len)).ok()?;
    let body_end = (at + 9).checked_add(len)?;
    (body_end <= end).then_some((op, at + 9..body_end))
}

/// Whether the records of an uncompressed chunk lie within it (a
/// compressed one is the decompressor's to check).
fn check_chunk(body: &[u8]) -> Option<()> {
    // start time, end time, uncompressed size, uncompressed CRC.
    let mut at = 8 + 8 + 8 + 4;
    let len: [u8; 4] = body.get(at..at + 4)?.try_into().ok()?;
    let compression_len = usize::try_from(u32::from_le_bytes(len)).ok()?;
    at = at.checked_add(4 + compression_len)?;
    let len: [u8; 8] = body.get(at..at + 8)?.try_into().ok()?;
    let records_len = usize::try_from(u64::from_le_bytes(len)).ok()?;
    at += 8;
    let records = body.get(at..at.checked_add(records_len)?)?;
    if compression_len != 0 {
        return Some(());
    }
    let mut inner = 0;
    while inner < records.len() {
        inner = record_at(records, inner, records.len())?.1.end;
    }
    Some(())
}

#[cfg(test)]
mod tests;
