//! The optional trace sink of an executive: one JSON line per controller per
//! cycle (verb, state, status, error, fired row), for debugging and replay.
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

impl TraceSink {
    /// A sink writing to `out` (wrap files in a `BufWriter`).
    pub fn new(out: impl Write + Send + 'static) -> Self {
        Self {
            out: Box::new(out),
            records: 0,
            errors: 0,
        }
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

/// Parse a JSON-lines trace back into records (for replay and tests).
pub fn read_trace(text: &str) -> Result<Vec<TraceRecord>, serde_json::Error> {
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(serde_json::from_str)
        .collect()
}
