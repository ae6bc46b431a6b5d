//! The JSON-lines encoding of a trace (docs/trace-format.md): writing one
//! value a line, and reading a trace back into [`TraceRecord`]s. The
//! [sink](super::TraceSink) writes through [`write_line`]; the header
//! check is shared with the MCAP reader, whose metadata carries the same
//! format and version.

use std::io::{self, Write};

use serde::Serialize;

use super::{TraceHeader, TraceRecord, TRACE_FORMAT, TRACE_VERSION};

/// Write `value` as one JSON line.
pub(super) fn write_line(out: &mut dyn Write, value: &impl Serialize) -> io::Result<()> {
    serde_json::to_writer(&mut *out, value)
        .map_err(io::Error::from)
        .and_then(|()| out.write_all(b"\n"))
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

pub(super) fn check_header(h: &TraceHeader) -> Result<(), String> {
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
