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
        message: message(e.to_string().lines().next().unwrap_or("")),
        location: e.location(),
    })
}

/// [`from_str`] for documents of names (scenarios): only `true` and
/// `false` are booleans, so `ON`, `OFF`, `YES`, `NO`, `Y`, `N` read as the
/// names they are (YAML 1.2's reading, not 1.1's).
pub fn from_str_names<T: DeserializeOwned>(text: &str) -> Result<T, YamlError> {
    let options = serde_saphyr::options! { with_snippet: false, strict_booleans: true };
    serde_saphyr::from_str_with_options(text, options).map_err(|e| YamlError {
        message: message(e.to_string().lines().next().unwrap_or("")),
        location: e.location(),
    })
}

/// The library's message without what callers say themselves (the place,
/// which they print as `file:line:`) or what only a programmer can act on
/// (the library option that would let duplicate keys through).
fn message(first_line: &str) -> String {
    let mut m = first_line.trim();
    if let Some(at) = m.rfind(" at line ") {
        let tail = &m[at + " at line ".len()..];
        let is_place = tail
            .split_once(", column ")
            .is_some_and(|(l, c)| l.parse::<u64>().is_ok() && c.parse::<u64>().is_ok());
        if is_place {
            m = &m[..at];
        }
    }
    let m = m.replace(", set DuplicateKeyPolicy in Options if acceptable", "");
    m.replace("duplicate mapping key: ", "a key is given twice: ")
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn error_of<T: DeserializeOwned + std::fmt::Debug>(text: &str) -> YamlError {
        from_str::<T>(text).expect_err(text)
    }

    #[test]
    fn a_duplicate_key_is_named_with_its_line_and_no_library_advice() {
        let e = error_of::<BTreeMap<String, u32>>("a: 1\nb: 2\na: 3\n");
        assert_eq!(e.message, "a key is given twice: a");
        assert_eq!(e.location.map(|l| l.line()), Some(3));
    }

    #[test]
    fn messages_leave_the_place_to_the_caller() {
        for text in ["a: 1\nb: [x]\n", "a: 1\nb: nine\n"] {
            let e = error_of::<BTreeMap<String, u32>>(text);
            assert!(!e.message.is_empty(), "{text}");
            assert!(!e.message.contains("at line"), "{text}: {}", e.message);
            assert_eq!(e.location.map(|l| l.line()), Some(2), "{text}");
        }
    }

    #[test]
    fn only_a_trailing_place_is_cut() {
        assert_eq!(message("bad at line 3, column 4"), "bad");
        assert_eq!(message("found at line end"), "found at line end");
        assert_eq!(message("  plain  "), "plain");
    }
}
