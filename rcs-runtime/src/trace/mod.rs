//! The optional trace sink of an executive: one record per controller per
//! cycle (verb, state, status, error, fired row), for debugging and replay.
//! The format is documented, with its versions, in `docs/trace-format.md`.
//! A trace is written in one of two encodings:
//!
//! - **JSON lines** ([`jsonl`]): a header line
//!   (`{"format":"rcs-trace","version":1}`) then one [`TraceRecord`] a line;
//! - **MCAP** (feature `mcap`, `trace::mcap`): a recording that Foxglove,
//!   Lichtblick and PlotJuggler open as it is, one channel per controller
//!   (and per Global Memory buffer, when the writer has their values).
//!
//! [`read_trace`] reads JSON lines back (also the traces written before the
//! header existed, which are version 1 without it) and refuses a newer
//! version by name; [`read_trace_bytes`] reads either encoding, telling
//! them apart by MCAP's magic bytes.
//!
//! Tracing formats JSON and writes to an `io::Write`, so it **allocates and
//! does I/O on the cycle path**. It is off by default; attach it with
//! [`Executive::set_trace`](crate::Executive::set_trace) only when debugging.
//! An executive without a sink pays one `Option` test per controller.

mod jsonl;
#[cfg(feature = "mcap")]
pub mod mcap;
#[cfg(test)]
mod tests;

use std::io::{self, Write};

use serde::{Deserialize, Serialize};

use crate::handshake::{RowId, StateId, VerbId};

pub use jsonl::{read_trace, TraceError};

/// One controller's cycle as traced. Fields from the plan bookkeeping are
/// `None` for a controller without one (a simulator, a driver).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TraceRecord<S = String>
where
    S: AsRef<str>,
{
    /// The executive's name.
    pub executive: S,
    /// The executive's cycle count.
    pub cycle: u64,
    /// The controller's name.
    pub controller: S,
    /// Active verb id.
    pub verb: Option<VerbId>,
    /// Current state id after this cycle's decision.
    pub state: Option<StateId>,
    /// Status code.
    pub status: Option<u16>,
    /// Error code (0: none).
    pub error: Option<u16>,
    /// The row that fired this cycle, if any.
    pub fired: Option<RowId>,
    /// Whether a new command arrived this cycle.
    pub new_command: bool,
}

/// What a writer may know about a cycle beyond its [`TraceRecord`]: the
/// names of its ids (from the plans), the command's serial, the time. The
/// JSON-lines encoding has no place for it and drops it; MCAP writes each
/// part that is `Some`.
/// Serialized as the extra fields of an MCAP controller message, each
/// left out when `None`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct TraceDetail<'a> {
    /// The message's log time, in nanoseconds. `None`: the time of
    /// writing (nanoseconds since the Unix epoch).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_ns: Option<u64>,
    /// The verb's name (`GO`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verb_name: Option<&'a str>,
    /// The state's name (`S1`, `Waiting`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub state_name: Option<&'a str>,
    /// The fired row's name (`E3`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fired_name: Option<&'a str>,
    /// The status's name (`EXECUTING`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub status_name: Option<&'a str>,
    /// The serial of the command the status is about.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub serial: Option<u32>,
    /// How long the controller's cycle took, in nanoseconds, when measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cycle_ns: Option<u64>,
}

/// The schema name of the controller channels.
pub const CONTROLLER_SCHEMA_NAME: &str = "rcs.ControllerCycle";

/// The JSON Schema of a controller channel's messages, in an MCAP
/// recording and live (feature `foxglove`; the fields marked "live only"
/// come from the executive's monitor, which a recording does not read).
pub const CONTROLLER_SCHEMA: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "rcs.ControllerCycle",
  "description": "One cycle of one RCS controller (docs/trace-format.md)",
  "type": "object",
  "properties": {
    "executive": { "type": "string", "description": "the executive (CPU) that ran the cycle" },
    "cycle": { "type": "integer", "description": "the executive's cycle count, from 0" },
    "time_ns": { "type": "integer", "description": "the message's log time, in nanoseconds" },
    "controller": { "type": "string", "description": "the controller's name" },
    "verb": { "type": ["integer", "null"], "description": "the command's verb id" },
    "verb_name": { "type": "string", "description": "the command's verb" },
    "state": { "type": ["integer", "null"], "description": "the plan's state id after the cycle" },
    "state_name": { "type": "string", "description": "the plan's state after the cycle" },
    "status": { "type": ["integer", "null"], "description": "the status code after the cycle" },
    "status_name": { "type": "string", "description": "the status after the cycle" },
    "error": { "type": ["integer", "null"], "description": "the error code after the cycle (0: none)" },
    "fired": { "type": ["integer", "null"], "description": "the position of the row that fired" },
    "fired_name": { "type": "string", "description": "the row that fired (E3)" },
    "new_command": { "type": "boolean", "description": "whether a new command arrived" },
    "serial": { "type": "integer", "description": "the serial of the command the status is about" },
    "cycle_ns": { "type": "integer", "description": "how long the controller's cycle took" },
    "last_fired": { "type": "integer", "description": "live only: the position of the row that fired last, in any cycle" },
    "last_fired_name": { "type": "string", "description": "live only: the row that fired last" },
    "last_fired_cycle": { "type": "integer", "description": "live only: the executive's cycle in which it fired" },
    "exec_max_ns": { "type": "integer", "description": "live only: the controller's longest cycle so far" },
    "overruns": { "type": "integer", "description": "live only: its cycles that alone took longer than the period" },
    "panics": { "type": "integer", "description": "live only: panics caught in its cycle" }
  },
  "required": ["executive", "cycle", "time_ns", "controller", "verb", "state", "status", "error", "fired", "new_command"]
}"#;

/// A topic part from a name: characters other than letters, digits, `_`,
/// `-` and `.` become `_` (`scenario go` → `scenario_go`).
pub(crate) fn topic_part(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The topic of controller `controller` of executive `executive`, in a
/// recording and live: `/rcs/<executive>/<controller>`.
pub fn controller_topic(executive: &str, controller: &str) -> String {
    format!("/rcs/{}/{}", topic_part(executive), topic_part(controller))
}

/// The topic of Global Memory buffer `buffer` written on executive
/// `executive`, in a recording and live: `/rcs/<executive>/gm/<buffer>`.
pub fn buffer_topic(executive: &str, buffer: &str) -> String {
    format!("/rcs/{}/gm/{}", topic_part(executive), topic_part(buffer))
}

/// The trace format this runtime writes (the header's `version`).
pub const TRACE_VERSION: u32 = 1;

/// The name in the header's `format` field.
pub const TRACE_FORMAT: &str = "rcs-trace";

/// The first line of a trace: what it is and which version of the format.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TraceHeader {
    /// Always [`TRACE_FORMAT`].
    pub format: String,
    /// The format's version; a reader refuses versions newer than its own.
    pub version: u32,
    /// Who wrote the trace, when a tool did: `rcsc test --trace` puts
    /// `@generated by rcsc` here, in the first line (in MCAP: the header's
    /// `library` field), so that its next run may replace the file (rcsc
    /// replaces no file without it). Readers ignore it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generated: Option<String>,
}

impl TraceHeader {
    /// The header this runtime writes.
    pub fn current() -> Self {
        TraceHeader {
            format: TRACE_FORMAT.to_string(),
            version: TRACE_VERSION,
            generated: None,
        }
    }
}

/// The encoding a sink writes.
enum Encoding {
    Lines(Box<dyn Write + Send>),
    #[cfg(feature = "mcap")]
    Mcap(Box<mcap::McapTrace>),
}

/// Writes [`TraceRecord`]s to any writer, as JSON lines ([`TraceSink::new`])
/// or as MCAP (`TraceSink::mcap`, feature `mcap`). Write errors are
/// counted, not raised: a broken trace never stops the control cycle.
pub struct TraceSink {
    out: Encoding,
    records: u64,
    errors: u64,
}

impl std::fmt::Debug for TraceSink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TraceSink")
            .field("records", &self.records)
            .field("errors", &self.errors)
            .finish()
    }
}

impl TraceSink {
    /// A sink writing JSON lines to `out` (wrap files in a `BufWriter`).
    /// The header line is written at once.
    pub fn new(out: impl Write + Send + 'static) -> Self {
        Self::with_header(out, &TraceHeader::current())
    }

    /// A JSON-lines sink writing `header` first (a tool's, naming it in
    /// `generated`).
    pub fn with_header(out: impl Write + Send + 'static, header: &TraceHeader) -> Self {
        let mut out: Box<dyn Write + Send> = Box::new(out);
        let errors = u64::from(jsonl::write_line(&mut out, header).is_err());
        Self {
            out: Encoding::Lines(out),
            records: 0,
            errors,
        }
    }

    /// A sink writing to the file `path` (created or truncated, buffered):
    /// an MCAP recording when its name ends in `.mcap` (feature `mcap`;
    /// without it such a path is refused as `Unsupported`), else JSON lines.
    pub fn create(path: &std::path::Path) -> io::Result<Self> {
        let mcap = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
        if mcap && cfg!(not(feature = "mcap")) {
            return Err(io::Error::new(
                io::ErrorKind::Unsupported,
                "an .mcap trace needs rcs-runtime's feature `mcap`",
            ));
        }
        let file = io::BufWriter::new(std::fs::File::create(path)?);
        #[cfg(feature = "mcap")]
        if mcap {
            let sink = Self::mcap(file);
            return match sink.errors {
                0 => Ok(sink),
                _ => Err(io::Error::other("the MCAP recording could not be started")),
            };
        }
        Ok(Self::new(file))
    }

    /// A sink writing an MCAP recording to `out` (wrap files in a
    /// `BufWriter`); the recording is whole once [`TraceSink::finish`] ran
    /// or the sink was dropped.
    #[cfg(feature = "mcap")]
    pub fn mcap(out: impl mcap::SeekWrite + 'static) -> Self {
        Self::mcap_with_header(out, &TraceHeader::current())
    }

    /// An MCAP sink whose metadata and header carry `header` (a tool's,
    /// naming it in `generated`).
    #[cfg(feature = "mcap")]
    pub fn mcap_with_header(out: impl mcap::SeekWrite + 'static, header: &TraceHeader) -> Self {
        match mcap::McapTrace::start(Box::new(out), header) {
            Ok(m) => Self {
                out: Encoding::Mcap(Box::new(m)),
                records: 0,
                errors: 0,
            },
            // Nothing can be written: every record will count as lost.
            Err(_) => Self {
                out: Encoding::Lines(Box::new(FailedWriter)),
                records: 0,
                errors: 1,
            },
        }
    }

    /// Whether this sink writes MCAP (and so keeps buffer samples).
    pub fn is_mcap(&self) -> bool {
        match &self.out {
            Encoding::Lines(_) => false,
            #[cfg(feature = "mcap")]
            Encoding::Mcap(_) => true,
        }
    }

    /// Write one Global Memory buffer's value on its channel (MCAP only;
    /// JSON lines has no place for it and drops it).
    #[cfg(feature = "mcap")]
    pub fn write_buffer(&mut self, sample: &mcap::BufferSample<'_>) {
        if let Encoding::Mcap(m) = &mut self.out {
            if m.write_buffer(sample).is_err() {
                self.errors += 1;
            }
        }
    }

    /// Write one record (its log time in MCAP: the time of writing).
    pub fn write<S: AsRef<str> + Serialize>(&mut self, rec: &TraceRecord<S>) {
        self.write_with(rec, &TraceDetail::default());
    }

    /// Write one record with what the writer knows beyond it (names, time;
    /// used by MCAP, dropped by JSON lines).
    pub fn write_with<S: AsRef<str> + Serialize>(
        &mut self,
        rec: &TraceRecord<S>,
        detail: &TraceDetail<'_>,
    ) {
        let r = match &mut self.out {
            Encoding::Lines(out) => {
                let _ = detail;
                jsonl::write_line(out, rec)
            }
            #[cfg(feature = "mcap")]
            Encoding::Mcap(m) => m.write_record(rec, detail),
        };
        match r {
            Ok(()) => self.records += 1,
            Err(_) => self.errors += 1,
        }
    }

    /// Flush the underlying writer. An MCAP sink ends its current chunk
    /// (the recording is whole only once [`TraceSink::finish`] ran).
    pub fn flush(&mut self) -> io::Result<()> {
        match &mut self.out {
            Encoding::Lines(out) => out.flush(),
            #[cfg(feature = "mcap")]
            Encoding::Mcap(m) => m.flush(),
        }
    }

    /// End the trace: MCAP writes its summary and closing magic (dropping
    /// the sink does too, ignoring errors); JSON lines flushes. Records
    /// written after this are counted as errors.
    pub fn finish(&mut self) -> io::Result<()> {
        match &mut self.out {
            Encoding::Lines(out) => out.flush(),
            #[cfg(feature = "mcap")]
            Encoding::Mcap(m) => m.finish(),
        }
    }

    /// Records written.
    pub fn records(&self) -> u64 {
        self.records
    }

    /// Records lost to write errors.
    pub fn errors(&self) -> u64 {
        self.errors
    }
}

/// The writer of an MCAP sink that could not start: every write fails.
#[cfg(feature = "mcap")]
struct FailedWriter;

#[cfg(feature = "mcap")]
impl Write for FailedWriter {
    fn write(&mut self, _: &[u8]) -> io::Result<usize> {
        Err(io::Error::other("the MCAP recording could not be started"))
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// MCAP's magic bytes, the first eight of every MCAP file.
pub const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// Why a trace file cannot be read, with a short code and what to do.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TraceReadError {
    /// A JSON-lines trace with a bad line.
    #[error("{0}")]
    Lines(TraceError),
    /// Neither MCAP nor UTF-8 text.
    #[error(
        "not a trace: neither an MCAP recording nor UTF-8 text (first bad byte at offset {0})"
    )]
    NotText(usize),
    /// An MCAP recording that is damaged, cut short, or not an rcs trace.
    #[error("{0}")]
    Mcap(String),
    /// An MCAP recording, read by a build without the `mcap` feature.
    #[error(
        "an MCAP recording, and this build reads no MCAP (rcs-runtime's feature `mcap` is off)"
    )]
    McapOff,
}

impl TraceReadError {
    /// A short name for the kind of error, as a diagnostic's code.
    pub fn code(&self) -> &'static str {
        match self {
            TraceReadError::Lines(_) | TraceReadError::NotText(_) => "bad_trace",
            TraceReadError::Mcap(_) => "bad_mcap",
            TraceReadError::McapOff => "mcap_off",
        }
    }

    /// What the user can do about it.
    pub fn help(&self) -> &'static str {
        match self {
            TraceReadError::Lines(_) | TraceReadError::NotText(_) => {
                "a trace is what `rcsc test --trace` or an executive's trace sink writes; docs/trace-format.md describes it"
            }
            TraceReadError::Mcap(_) => {
                "the recording is damaged or was cut short (a writer stopped before it finished writes no summary); record it again, or repair it with `mcap recover` from the MCAP command-line tools"
            }
            TraceReadError::McapOff => "build rcsc with its default features (`mcap`)",
        }
    }
}

/// Read a trace of either encoding: MCAP when it starts with
/// [`MCAP_MAGIC`], else JSON lines (see [`read_trace`]).
pub fn read_trace_bytes(bytes: &[u8]) -> Result<Vec<TraceRecord>, TraceReadError> {
    if !bytes.is_empty() && MCAP_MAGIC.starts_with(bytes) {
        return Err(TraceReadError::Mcap(format!(
            "an MCAP recording cut short: only {} bytes",
            bytes.len()
        )));
    }
    if bytes.starts_with(MCAP_MAGIC) {
        #[cfg(feature = "mcap")]
        return mcap::read_mcap(bytes).map_err(TraceReadError::Mcap);
        #[cfg(not(feature = "mcap"))]
        return Err(TraceReadError::McapOff);
    }
    let text = std::str::from_utf8(bytes).map_err(|e| TraceReadError::NotText(e.valid_up_to()))?;
    read_trace(text).map_err(TraceReadError::Lines)
}
