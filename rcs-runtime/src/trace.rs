//! The optional trace sink of an executive: one JSON line per controller per
//! cycle (verb, state, status, error, fired row), for debugging and replay.
//! The format is documented, with its versions, in `docs/trace-format.md`:
//! a header line (`{"format":"rcs-trace","version":1}`) then one
//! [`TraceRecord`] a line. [`read_trace`] reads it back (also the traces
//! written before the header existed, which are version 1 without it) and
//! refuses a newer version by name.
//!
//! Tracing formats JSON and writes to an `io::Write`, so it **allocates and
//! does I/O on the cycle path**. It is off by default; attach it with
//! [`Executive::set_trace`](crate::Executive::set_trace) only when debugging.

use std::io::{self, Write};

use serde::{Deserialize, Serialize};

use crate::handshake::{RowId, StateId, VerbId};

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

/// Writes [`TraceRecord`]s as JSON lines to any writer. Write errors are
/// counted, not raised: a broken trace never stops the control cycle.
pub struct TraceSink {
    out: Box<dyn Write + Send>,
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
}

impl TraceHeader {
    /// The header this runtime writes.
    pub fn current() -> Self {
        TraceHeader {
            format: TRACE_FORMAT.to_string(),
            version: TRACE_VERSION,
        }
    }
}

impl TraceSink {
    /// A sink writing to `out` (wrap files in a `BufWriter`). The header
    /// line is written at once.
    pub fn new(out: impl Write + Send + 'static) -> Self {
        let mut sink = Self {
            out: Box::new(out),
            records: 0,
            errors: 0,
        };
        let header = serde_json::to_writer(&mut sink.out, &TraceHeader::current())
            .map_err(io::Error::from)
            .and_then(|()| sink.out.write_all(b"\n"));
        if header.is_err() {
            sink.errors += 1;
        }
        sink
    }

    /// Write one record and a newline.
    pub fn write<S: AsRef<str> + Serialize>(&mut self, rec: &TraceRecord<S>) {
        let r = serde_json::to_writer(&mut self.out, rec)
            .map_err(io::Error::from)
            .and_then(|()| self.out.write_all(b"\n"));
        match r {
            Ok(()) => self.records += 1,
            Err(_) => self.errors += 1,
        }
    }

    /// Flush the underlying writer.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
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

/// Why a trace cannot be read: the 1-based line and what is wrong there.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: {message}")]
pub struct TraceError {
    /// 1-based line of the trace.
    pub line: usize,
    /// What is wrong, in words.
    pub message: String,
}

/// Parse a JSON-lines trace back into records (for replay and tests). The
/// header is optional (traces from before it are version 1); a header of
/// another format or of a newer version is refused, as is a line that is
/// not a record.
pub fn read_trace(text: &str) -> Result<Vec<TraceRecord>, TraceError> {
    let mut records = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        if line.trim().is_empty() {
            continue;
        }
        if records.is_empty() && line.contains("\"format\"") {
            if let Ok(h) = serde_json::from_str::<TraceHeader>(line) {
                check_header(&h).map_err(|message| TraceError {
                    line: line_no,
                    message,
                })?;
                continue;
            }
        }
        let rec = serde_json::from_str(line).map_err(|e| TraceError {
            line: line_no,
            message: format!("not a trace record: {e}"),
        })?;
        records.push(rec);
    }
    Ok(records)
}

fn check_header(h: &TraceHeader) -> Result<(), String> {
    if h.format != TRACE_FORMAT {
        return Err(format!(
            "a `{}` file, not an rcs trace (format `{TRACE_FORMAT}`)",
            h.format
        ));
    }
    if h.version == 0 || h.version > TRACE_VERSION {
        return Err(format!(
            "trace format version {} is not one this reader knows (it reads versions 1 to {TRACE_VERSION}); use the rcsc that wrote it or a newer one",
            h.version
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_then_records_and_old_traces_without_header() {
        let rec = r#"{"executive":"main","cycle":0,"controller":"PR","verb":2,"state":1,"status":1,"error":0,"fired":0,"new_command":true}"#;
        let with = format!("{{\"format\":\"rcs-trace\",\"version\":1}}\n{rec}\n");
        assert_eq!(read_trace(&with).unwrap().len(), 1);
        assert_eq!(read_trace(rec).unwrap()[0].fired, Some(0));
        let newer = format!("{{\"format\":\"rcs-trace\",\"version\":2}}\n{rec}\n");
        let e = read_trace(&newer).unwrap_err();
        assert_eq!(e.line, 1);
        assert!(e.message.contains("version 2"), "{e}");
        let other = "{\"format\":\"csv\",\"version\":1}\n";
        assert!(read_trace(other)
            .unwrap_err()
            .message
            .contains("not an rcs trace"));
        let bad = format!("{rec}\nnonsense\n");
        assert_eq!(read_trace(&bad).unwrap_err().line, 2);
    }

    #[test]
    fn a_sink_starts_with_the_header() {
        #[derive(Clone, Default)]
        struct Buf(std::sync::Arc<std::sync::Mutex<Vec<u8>>>);
        impl Write for Buf {
            fn write(&mut self, b: &[u8]) -> io::Result<usize> {
                self.0
                    .lock()
                    .map_err(|_| io::ErrorKind::Other)?
                    .extend_from_slice(b);
                Ok(b.len())
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        let buf = Buf::default();
        let sink = TraceSink::new(buf.clone());
        assert_eq!(sink.records(), 0);
        let text = String::from_utf8(buf.0.lock().unwrap().clone()).unwrap();
        assert_eq!(text, "{\"format\":\"rcs-trace\",\"version\":1}\n");
    }
}
