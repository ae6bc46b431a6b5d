//! Rendering, human format: source lines too long to show whole (a
//! generated or minified file, a 15 MB line) are cut around the spans the
//! diagnostic points at, with `…` where text was left out. The cut text is
//! what the snippet shows; positions (`file:line:column`) stay those of the
//! real file.

use crate::diagnostic::Diagnostic;
use crate::source::{FileId, SourceMap};
use codespan_reporting::files::{Error as FilesError, Files, Location};
use std::collections::BTreeMap;
use std::ops::Range;

/// Lines longer than this many bytes are cut.
pub const MAX_SHOWN: usize = 240;
/// Bytes of context kept on each side of the spans of a cut line.
const CONTEXT: usize = 60;
const ELLIPSIS: &str = "…";

/// One piece of a shown line: bytes `orig` of the real file, at `shown` in
/// the shown text.
#[derive(Clone, Debug)]
struct Piece {
    orig: Range<usize>,
    shown: usize,
}

/// A file as the snippet shows it.
struct Shown {
    text: String,
    line_starts: Vec<usize>,
    pieces: Vec<Piece>,
}

/// The files of a diagnostic, with long lines cut.
pub struct CutFiles<'a> {
    sources: &'a SourceMap,
    shown: BTreeMap<FileId, Shown>,
}

/// Whether `d` points into a line longer than [`MAX_SHOWN`].
pub fn needed(d: &Diagnostic, sources: &SourceMap) -> bool {
    d.labels.iter().any(|l| {
        let f = sources.get(l.span.file);
        let (line, _) = f.line_col(l.span.start as usize);
        line_range(f.line_starts(), &f.text, line - 1).len() > MAX_SHOWN
    })
}

fn line_range(starts: &[usize], text: &str, line: usize) -> Range<usize> {
    let start = starts.get(line).copied().unwrap_or(text.len());
    let end = starts.get(line + 1).copied().unwrap_or(text.len());
    start..end
}

fn floor(text: &str, mut i: usize) -> usize {
    i = i.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

impl<'a> CutFiles<'a> {
    /// The files `d` points into, each line longer than [`MAX_SHOWN`] cut
    /// to a window around the labels on it (the first bytes, for a long
    /// line without labels).
    pub fn new(d: &Diagnostic, sources: &'a SourceMap) -> CutFiles<'a> {
        let mut spans: BTreeMap<FileId, Vec<Range<usize>>> = BTreeMap::new();
        for l in &d.labels {
            spans.entry(l.span.file).or_default().push(l.span.range());
        }
        let shown = spans
            .into_iter()
            .map(|(id, spans)| {
                (
                    id,
                    cut(&sources.get(id).text, sources.get(id).line_starts(), &spans),
                )
            })
            .collect();
        CutFiles { sources, shown }
    }

    /// Where byte `orig` of file `id` is in the shown text.
    pub fn shown_offset(&self, id: FileId, orig: usize) -> usize {
        let Some(s) = self.shown.get(&id) else {
            return orig;
        };
        match s
            .pieces
            .iter()
            .find(|p| p.orig.start <= orig && orig <= p.orig.end)
        {
            Some(p) => p.shown + (orig - p.orig.start),
            None => s
                .pieces
                .iter()
                .rev()
                .find(|p| p.orig.end <= orig)
                .map_or(0, |p| p.shown + p.orig.len()),
        }
    }

    /// Which byte of the real file byte `shown` of the shown text stands for.
    fn orig_offset(&self, id: FileId, shown: usize) -> usize {
        let Some(s) = self.shown.get(&id) else {
            return shown;
        };
        match s.pieces.iter().rev().find(|p| p.shown <= shown) {
            Some(p) => p.orig.start + (shown - p.shown).min(p.orig.len()),
            None => 0,
        }
    }
}

/// The shown text of one file: every line, long ones cut around `spans`.
fn cut(text: &str, starts: &[usize], spans: &[Range<usize>]) -> Shown {
    let mut out = Shown {
        text: String::with_capacity(text.len().min(1 << 16)),
        line_starts: Vec::with_capacity(starts.len()),
        pieces: Vec::new(),
    };
    for line in 0..starts.len() {
        let range = line_range(starts, text, line);
        out.line_starts.push(out.text.len());
        let keep = if range.len() <= MAX_SHOWN {
            range.clone()
        } else {
            // The labels on this line, and some context around them.
            let on_line: Vec<&Range<usize>> = spans
                .iter()
                .filter(|s| s.start >= range.start && s.start < range.end)
                .collect();
            let lo = on_line.iter().map(|s| s.start).min().unwrap_or(range.start);
            let hi = on_line.iter().map(|s| s.end).max().unwrap_or(range.start);
            let hi = hi.min(lo + MAX_SHOWN);
            floor(text, lo.saturating_sub(CONTEXT).max(range.start))
                ..floor(text, (hi + CONTEXT).min(range.end))
        };
        if keep.start > range.start {
            out.text.push_str(ELLIPSIS);
        }
        out.pieces.push(Piece {
            orig: keep.clone(),
            shown: out.text.len(),
        });
        out.text.push_str(&text[keep.clone()]);
        if keep.end < range.end {
            out.text.push_str(ELLIPSIS);
            // Keep the line's end, so the next line starts on its own.
            let tail = &text[keep.end..range.end];
            let end = tail.trim_end_matches(['\n', '\r']);
            out.text.push_str(&tail[end.len()..]);
        }
    }
    out
}

impl<'a> Files<'a> for CutFiles<'a> {
    type FileId = FileId;
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, id: FileId) -> Result<&'a str, FilesError> {
        Ok(&self.sources.get(id).path)
    }

    fn source(&'a self, id: FileId) -> Result<&'a str, FilesError> {
        Ok(match self.shown.get(&id) {
            Some(s) => &s.text,
            None => &self.sources.get(id).text,
        })
    }

    fn line_index(&'a self, id: FileId, byte_index: usize) -> Result<usize, FilesError> {
        match self.shown.get(&id) {
            Some(s) => Ok(match s.line_starts.binary_search(&byte_index) {
                Ok(i) => i,
                Err(i) => i.saturating_sub(1),
            }),
            None => self.sources.line_index(id, byte_index),
        }
    }

    fn line_range(&'a self, id: FileId, line_index: usize) -> Result<Range<usize>, FilesError> {
        match self.shown.get(&id) {
            Some(s) => {
                let start = *s
                    .line_starts
                    .get(line_index)
                    .ok_or(FilesError::LineTooLarge {
                        given: line_index,
                        max: s.line_starts.len().saturating_sub(1),
                    })?;
                let end = s
                    .line_starts
                    .get(line_index + 1)
                    .copied()
                    .unwrap_or(s.text.len());
                Ok(start..end)
            }
            None => self.sources.line_range(id, line_index),
        }
    }

    /// The real file's line and column, whatever was cut.
    fn location(&'a self, id: FileId, byte_index: usize) -> Result<Location, FilesError> {
        let (line_number, column_number) = self
            .sources
            .get(id)
            .line_col(self.orig_offset(id, byte_index));
        Ok(Location {
            line_number,
            column_number,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnostic::{Code, Diagnostic};
    use crate::render::{render, Format};
    use crate::source::Span;

    #[test]
    fn a_long_line_is_cut_around_the_span_and_keeps_its_position() {
        let mut sources = SourceMap::new();
        let line = format!("{}NEEDLE{}", "a ".repeat(5_000), "b ".repeat(5_000));
        let text = format!("first\n{line}\nlast\n");
        let id = sources.add("t.rcs", text.clone());
        let at = text.find("NEEDLE").unwrap_or(0);
        let d = Diagnostic::error(Code::Syntax, "here", Span::new(id, at, at + 6), "this");
        let shown = render(&d, &sources, Format::Human { color: false });
        assert!(shown.contains("t.rcs:2:10001"), "{shown}");
        let snippet = shown
            .lines()
            .find(|l| l.contains("NEEDLE"))
            .unwrap_or_default();
        assert!(
            snippet.len() < 2 * MAX_SHOWN,
            "{} bytes: {snippet}",
            snippet.len()
        );
        assert!(
            snippet.contains("…a a") && snippet.ends_with('…'),
            "{snippet}"
        );
        // The caret sits under the needle (columns in characters).
        let caret = shown
            .lines()
            .find(|l| l.contains("^^^^^^"))
            .unwrap_or_default();
        let column = |l: &str, b: Option<usize>| b.map(|b| l[..b].chars().count());
        assert_eq!(
            column(caret, caret.find('^')),
            column(snippet, snippet.find("NEEDLE")),
            "{shown}"
        );
    }

    #[test]
    fn short_lines_are_shown_whole() {
        let mut sources = SourceMap::new();
        let id = sources.add("t.rcs", "controller A {}\n");
        let d = Diagnostic::error(Code::Syntax, "here", Span::new(id, 11, 12), "this");
        assert!(!needed(&d, &sources));
    }
}
