//! Rendering, human format: the source lines a snippet shows, as it shows
//! them. Only the lines the diagnostic's labels stand on (and one either
//! side, which codespan may show between two labels) are taken, so a
//! diagnostic costs the same in a file of one long line as in a file of
//! many short ones. Lines too long to show whole (a generated or minified
//! file, a 15 MB line) are cut around the spans the diagnostic points at,
//! with `…` where text was left out; control characters (ESC and the rest
//! of C0 and C1, but tab) are shown escaped, as `\u{1b}`, so that a plan's
//! text cannot drive the terminal. The shown text is what the snippet
//! shows; positions (`file:line:column`) stay those of the real file.

use super::escape_controls;
use crate::diagnostic::Diagnostic;
use crate::source::{FileId, SourceMap};
use codespan_reporting::files::{Error as FilesError, Files, Location};
use std::collections::{BTreeMap, BTreeSet};
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

/// The lines of a file a snippet shows.
struct Shown {
    text: String,
    /// The lines taken, (line index, where it starts in `text`), in order.
    lines: Vec<(usize, usize)>,
    /// How many lines the real file has.
    line_count: usize,
    pieces: Vec<Piece>,
}

/// The files of a diagnostic, each with the lines its labels need.
pub struct CutFiles<'a> {
    sources: &'a SourceMap,
    shown: BTreeMap<FileId, Shown>,
    names: BTreeMap<FileId, String>,
}

fn line_range(starts: &[usize], text: &str, line: usize) -> Range<usize> {
    let start = starts.get(line).copied().unwrap_or(text.len());
    let end = starts.get(line + 1).copied().unwrap_or(text.len());
    start..end
}

/// The index of the line holding byte `offset`.
fn line_of(starts: &[usize], offset: usize) -> usize {
    match starts.binary_search(&offset) {
        Ok(i) => i,
        Err(i) => i.saturating_sub(1),
    }
}

fn floor(text: &str, mut i: usize) -> usize {
    i = i.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

impl<'a> CutFiles<'a> {
    /// The files `d` points into, each with the lines its labels stand on
    /// (one either side), lines longer than [`MAX_SHOWN`] cut to a window
    /// around the labels on them (the first bytes, for a long line without
    /// labels), control characters escaped.
    pub fn new(d: &Diagnostic, sources: &'a SourceMap) -> CutFiles<'a> {
        let mut spans: BTreeMap<FileId, Vec<Range<usize>>> = BTreeMap::new();
        for l in &d.labels {
            spans.entry(l.span.file).or_default().push(l.span.range());
        }
        let names = spans
            .keys()
            .map(|&id| (id, escape_controls(&sources.get(id).path).into_owned()))
            .collect();
        let shown = spans
            .into_iter()
            .map(|(id, spans)| {
                (
                    id,
                    cut(&sources.get(id).text, sources.get(id).line_starts(), &spans),
                )
            })
            .collect();
        CutFiles {
            sources,
            shown,
            names,
        }
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

/// Whether `d` can be shown from the files as they are: every line its
/// labels need is short and free of control characters, and so are the
/// file names (the common case, which then costs no copy).
pub fn plain(d: &Diagnostic, sources: &SourceMap) -> bool {
    d.labels.iter().all(|l| {
        let f = sources.get(l.span.file);
        let starts = f.line_starts();
        let (a, b) = (
            line_of(starts, l.span.start as usize),
            line_of(starts, l.span.end as usize),
        );
        let last = starts.len().saturating_sub(1);
        let plain_text = |t: &str| {
            !t.chars()
                .any(|c| c.is_control() && !matches!(c, '\t' | '\n' | '\r'))
        };
        // A label over many lines: not worth checking here.
        b - a <= 8
            && plain_text(&f.path)
            && (a.saturating_sub(1)..=(b + 1).min(last)).all(|line| {
                let range = line_range(starts, &f.text, line);
                range.len() <= MAX_SHOWN && plain_text(&f.text[range])
            })
    })
}

/// The lines `spans` need: each span's lines and one either side, sorted.
fn needed_lines(starts: &[usize], spans: &[Range<usize>]) -> BTreeSet<usize> {
    let last = starts.len().saturating_sub(1);
    let mut lines = BTreeSet::new();
    for s in spans {
        let (a, b) = (line_of(starts, s.start), line_of(starts, s.end));
        lines.extend(a.saturating_sub(1)..=(b + 1).min(last));
    }
    lines
}

/// The shown text of one file: the lines `spans` need, long ones cut
/// around `spans`, control characters escaped.
fn cut(text: &str, starts: &[usize], spans: &[Range<usize>]) -> Shown {
    let mut out = Shown {
        text: String::new(),
        lines: Vec::new(),
        line_count: starts.len(),
        pieces: Vec::new(),
    };
    for line in needed_lines(starts, spans) {
        let range = line_range(starts, text, line);
        out.lines.push((line, out.text.len()));
        // The line's end (`\n`, `\r\n`, a lone `\r`) is kept as it is.
        let body = text[range.clone()].trim_end_matches(['\n', '\r']);
        let body_end = range.start + body.len();
        let keep = if range.len() <= MAX_SHOWN {
            range.start..body_end
        } else {
            // The labels on this line (the end of the file counts as on
            // its last line), and some context around them.
            let at_end = range.end == text.len();
            let on_line: Vec<&Range<usize>> = spans
                .iter()
                .filter(|s| {
                    s.start >= range.start
                        && (s.start < range.end || at_end && s.start == range.end)
                })
                .collect();
            let lo = on_line.iter().map(|s| s.start).min().unwrap_or(range.start);
            let hi = on_line.iter().map(|s| s.end).max().unwrap_or(range.start);
            let hi = hi.min(lo + MAX_SHOWN);
            floor(text, lo.saturating_sub(CONTEXT).max(range.start))
                ..floor(text, (hi + CONTEXT).min(body_end))
        };
        if keep.start > range.start {
            out.text.push_str(ELLIPSIS);
        }
        push_escaped(&mut out, text, keep.clone());
        if keep.end < body_end {
            out.text.push_str(ELLIPSIS);
        }
        out.pieces.push(Piece {
            orig: body_end..range.end,
            shown: out.text.len(),
        });
        out.text.push_str(&text[body_end..range.end]);
    }
    out
}

/// Append `text[range]` to the shown text, each control character but tab
/// escaped, recording the pieces of real text.
fn push_escaped(out: &mut Shown, text: &str, range: Range<usize>) {
    let mut run = range.start;
    for (i, c) in text[range.clone()].char_indices() {
        if c.is_control() && c != '\t' {
            let at = range.start + i;
            out.pieces.push(Piece {
                orig: run..at,
                shown: out.text.len(),
            });
            out.text.push_str(&text[run..at]);
            out.text.push_str(&c.escape_unicode().to_string());
            run = at + c.len_utf8();
        }
    }
    out.pieces.push(Piece {
        orig: run..range.end,
        shown: out.text.len(),
    });
    out.text.push_str(&text[run..range.end]);
}

impl<'a> Files<'a> for CutFiles<'a> {
    type FileId = FileId;
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, id: FileId) -> Result<&'a str, FilesError> {
        Ok(match self.names.get(&id) {
            Some(name) => name,
            None => &self.sources.get(id).path,
        })
    }

    fn source(&'a self, id: FileId) -> Result<&'a str, FilesError> {
        Ok(match self.shown.get(&id) {
            Some(s) => &s.text,
            None => &self.sources.get(id).text,
        })
    }

    fn line_index(&'a self, id: FileId, byte_index: usize) -> Result<usize, FilesError> {
        match self.shown.get(&id) {
            Some(s) => {
                let at = s.lines.partition_point(|&(_, start)| start <= byte_index);
                Ok(s.lines
                    .get(at.saturating_sub(1))
                    .map_or(0, |&(line, _)| line))
            }
            None => self.sources.line_index(id, byte_index),
        }
    }

    /// A line taken, as shown; a line not taken (codespan asks only for
    /// lines next to those it shows) is empty.
    fn line_range(&'a self, id: FileId, line_index: usize) -> Result<Range<usize>, FilesError> {
        let Some(s) = self.shown.get(&id) else {
            return self.sources.line_range(id, line_index);
        };
        if line_index >= s.line_count {
            return Err(FilesError::LineTooLarge {
                given: line_index,
                max: s.line_count.saturating_sub(1),
            });
        }
        let at = s.lines.partition_point(|&(line, _)| line < line_index);
        let next = |i: usize| s.lines.get(i).map_or(s.text.len(), |&(_, start)| start);
        Ok(match s.lines.get(at) {
            Some(&(line, start)) if line == line_index => start..next(at + 1),
            _ => next(at)..next(at),
        })
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
    fn the_end_of_a_long_last_line_has_the_column_of_the_short_format() {
        let mut sources = SourceMap::new();
        let text = format!("first\n{}", "a ".repeat(200));
        let id = sources.add("t.rcs", text.clone());
        let end = text.len();
        let d = Diagnostic::error(Code::Syntax, "here", Span::new(id, end, end), "end");
        let short = render(&d, &sources, Format::Short);
        assert!(short.starts_with("t.rcs:2:401:"), "{short}");
        let human = render(&d, &sources, Format::Human { color: false });
        assert!(human.contains("t.rcs:2:401"), "{human}");
    }

    #[test]
    fn control_characters_are_shown_escaped() {
        let mut sources = SourceMap::new();
        let text = "controller A \"x\u{1b}[31my\u{9b}\" {}\n";
        let id = sources.add("t\u{7}.rcs", text);
        let at = text.find('{').unwrap_or(0);
        let d = Diagnostic::error(
            Code::Syntax,
            "bad \u{1b}]0;t",
            Span::new(id, at, at + 1),
            "x\u{8}",
        );
        for format in [Format::Human { color: false }, Format::Short, Format::Json] {
            let shown = render(&d, &sources, format);
            assert!(
                !shown.chars().any(|c| c.is_control() && c != '\n'),
                "{shown:?}"
            );
        }
        let human = render(&d, &sources, Format::Human { color: false });
        assert!(human.contains("x\\u{1b}[31my\\u{9b}"), "{human}");
        assert!(human.contains("bad \\u{1b}]0;t"), "{human}");
        assert!(human.contains("t\\u{7}.rcs:1:"), "{human}");
        // The caret still sits under the `{`.
        let caret = human.lines().find(|l| l.contains('^')).unwrap_or_default();
        let line = human
            .lines()
            .find(|l| l.contains("controller A"))
            .unwrap_or_default();
        assert_eq!(caret.find('^'), line.rfind('{'), "{human}");
    }
}
