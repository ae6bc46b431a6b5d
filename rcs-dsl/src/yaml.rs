//! The one module that talks to the YAML library (serde-saphyr). The
//! manifest, scenarios and `rcsc ir --format yaml` all go through it, so a
//! change of library touches this file only.

use crate::source::{FileId, SourceFile, Span};
use serde::de::DeserializeOwned;

pub use serde_saphyr::{Location, Spanned};

/// A YAML document that does not fit its schema: the library's message
/// (first line) and where it points, if it knows.
#[derive(Debug)]
pub struct YamlError {
    pub message: String,
    pub location: Option<Location>,
}

/// Deserialize a whole document, strictly (the types decide about unknown keys).
pub fn from_str<T: DeserializeOwned>(text: &str) -> Result<T, YamlError> {
    let options = serde_saphyr::options! { with_snippet: false };
    serde_saphyr::from_str_with_options(text, options).map_err(|e| YamlError {
        message: e
            .to_string()
            .lines()
            .next()
            .unwrap_or("")
            .trim()
            .to_string(),
        location: e.location(),
    })
}

/// Any serialisable value as YAML.
pub fn to_string<T: serde::Serialize>(value: &T) -> Result<String, serde_saphyr::SerializeError> {
    serde_saphyr::to_string(value)
}

/// Whether a document holds nothing but blank lines and comments.
pub fn is_empty(text: &str) -> bool {
    text.lines()
        .all(|l| l.trim().is_empty() || l.trim_start().starts_with('#'))
}

/// The byte span a location points at in `file`; an empty location is
/// widened to the rest of its token on the line.
pub fn span(id: FileId, file: &SourceFile, loc: &Location) -> Span {
    let s = loc.span();
    let start = match s.byte_offset() {
        Some(b) => (b as usize).min(file.text.len()),
        None => offset_of(file, loc.line(), loc.column()),
    };
    let end = (start + s.byte_len().unwrap_or(0) as usize).min(file.text.len());
    if start < end {
        return Span::new(id, start, end);
    }
    let rest = &file.text[start..];
    let len = rest.find(['\n', '\r', ',', ']', '}']).unwrap_or(rest.len());
    Span::new(id, start, start + rest[..len].trim_end().len())
}

fn offset_of(file: &SourceFile, line: u64, column: u64) -> usize {
    let starts = file.line_starts();
    let Some(&start) = starts.get((line as usize).saturating_sub(1)) else {
        return file.text.len();
    };
    let rest = &file.text[start..];
    start
        + rest
            .char_indices()
            .nth((column as usize).saturating_sub(1))
            .map(|(i, _)| i)
            .unwrap_or(rest.len())
}
