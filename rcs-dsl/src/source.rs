//! Source text and positions: the first thing loaded and the last thing
//! consulted (by the renderers) in the pipeline.
//!
//! Every span in the AST, the IR and the diagnostics is a byte range into one
//! [`SourceFile`] of a [`SourceMap`]. Lines and columns are computed only when
//! a diagnostic is rendered.

use serde::Serialize;

/// Index of a file in its [`SourceMap`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct FileId(pub u32);

/// A byte range `start..end` inside one file. Invariant: `start <= end <= len`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct Span {
    pub file: FileId,
    pub start: u32,
    pub end: u32,
}

impl Span {
    pub fn new(file: FileId, start: usize, end: usize) -> Span {
        Span {
            file,
            start: start as u32,
            end: end as u32,
        }
    }

    /// The smallest span covering both (same file assumed).
    pub fn to(self, other: Span) -> Span {
        Span {
            file: self.file,
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }

    pub fn range(self) -> std::ops::Range<usize> {
        self.start as usize..self.end as usize
    }
}

/// The byte-order mark some editors put at the start of a UTF-8 file.
pub const BOM: char = '\u{FEFF}';

/// One input file: its display path (relative to the plan set's root, with
/// `/` separators) and its text.
///
/// Positions come from two indexes built once with the file: where each
/// line starts, and (for a text that is not all ASCII) how many characters
/// come before every [`CHAR_BLOCK`]-byte block. A column is then found in
/// a bounded time however long its line is: 100,000 diagnostics on one
/// long line cost what they cost one per line.
#[derive(Clone, Debug)]
pub struct SourceFile {
    pub path: String,
    pub text: String,
    line_starts: Vec<usize>,
    /// Characters before byte `i * CHAR_BLOCK`, for each block; empty when
    /// the text is ASCII (a character is then a byte).
    chars_before_block: Vec<u32>,
}

/// The bytes of a block of the character index.
const CHAR_BLOCK: usize = 64;

/// Whether a byte starts a character (is not a UTF-8 continuation byte).
fn starts_char(b: &u8) -> bool {
    (*b as i8) >= -0x40
}

impl SourceFile {
    /// A file from its text. A leading byte-order mark is dropped (it is
    /// no character of the file, and would shift every column of line 1);
    /// lines end at `\n`, `\r\n` or a lone `\r`.
    pub fn new(path: impl Into<String>, text: impl Into<String>) -> SourceFile {
        let mut text = text.into();
        if text.starts_with(BOM) {
            text.drain(..BOM.len_utf8());
        }
        let bytes = text.as_bytes();
        let line_starts = std::iter::once(0)
            .chain(bytes.iter().enumerate().filter_map(|(i, b)| {
                let ends_line = *b == b'\n' || (*b == b'\r' && bytes.get(i + 1) != Some(&b'\n'));
                ends_line.then_some(i + 1)
            }))
            .collect();
        let chars_before_block = if text.is_ascii() {
            Vec::new()
        } else {
            let mut before = 0u32;
            text.as_bytes()
                .chunks(CHAR_BLOCK)
                .map(|block| {
                    let at = before;
                    before += block.iter().filter(|b| starts_char(b)).count() as u32;
                    at
                })
                .collect()
        };
        SourceFile {
            path: path.into(),
            text,
            line_starts,
            chars_before_block,
        }
    }

    /// How many characters start before byte `offset` (`offset <= len`).
    fn chars_before(&self, offset: usize) -> usize {
        if self.chars_before_block.is_empty() {
            return offset;
        }
        let block = offset / CHAR_BLOCK;
        let from = block * CHAR_BLOCK;
        let within = self.text.as_bytes()[from..offset]
            .iter()
            .filter(|b| starts_char(b))
            .count();
        self.chars_before_block
            .get(block)
            .map_or(0, |&n| n as usize)
            + within
    }

    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.text.len());
        let line = match self.line_starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let start = self.line_starts[line];
        let mut col_end = offset;
        while !self.text.is_char_boundary(col_end) {
            col_end -= 1;
        }
        let column = self.chars_before(col_end) - self.chars_before(start) + 1;
        (line + 1, column)
    }

    pub fn line_starts(&self) -> &[usize] {
        &self.line_starts
    }
}

/// All files of one plan set (plus its manifest), in a stable order.
#[derive(Clone, Debug, Default)]
pub struct SourceMap {
    files: Vec<SourceFile>,
}

impl SourceMap {
    pub fn new() -> SourceMap {
        SourceMap::default()
    }

    pub fn add(&mut self, path: impl Into<String>, text: impl Into<String>) -> FileId {
        self.files.push(SourceFile::new(path, text));
        FileId(self.files.len() as u32 - 1)
    }

    pub fn get(&self, id: FileId) -> &SourceFile {
        &self.files[id.0 as usize]
    }

    pub fn files(&self) -> impl Iterator<Item = (FileId, &SourceFile)> {
        self.files
            .iter()
            .enumerate()
            .map(|(i, f)| (FileId(i as u32), f))
    }

    pub fn len(&self) -> usize {
        self.files.len()
    }

    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// A key that orders spans by (file path, offset): the order the spec
    /// uses for "the later declaration".
    pub fn order_key(&self, span: Span) -> (&str, u32) {
        (self.get(span.file).path.as_str(), span.start)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_end_at_lf_crlf_and_a_lone_cr() {
        let f = SourceFile::new("t", "a\nbb\r\nccc\rdddd\r\re");
        assert_eq!(f.line_starts(), &[0, 2, 6, 10, 15, 16]);
        // `e` is on line 6, column 1; the `d`s on line 4.
        assert_eq!(f.line_col(16), (6, 1));
        assert_eq!(f.line_col(12), (4, 3));
    }

    #[test]
    fn columns_count_characters_on_long_and_short_lines() {
        // Every offset of a mixed text, against counting the characters.
        let line = "aé€😀b".repeat(40);
        let text = format!("{line}\nx\u{1b}ü\n{line}");
        let f = SourceFile::new("t", text.clone());
        for offset in 0..=text.len() {
            let mut end = offset;
            while !text.is_char_boundary(end) {
                end -= 1;
            }
            let start = text[..end].rfind('\n').map_or(0, |i| i + 1);
            let want = text[start..end].chars().count() + 1;
            assert_eq!(f.line_col(offset).1, want, "offset {offset}");
        }
        let ascii = SourceFile::new("t", "abc\ndef");
        assert_eq!(ascii.line_col(7), (2, 4));
    }

    #[test]
    fn a_byte_order_mark_is_not_a_column() {
        let f = SourceFile::new("t", "\u{FEFF}ab\ncd");
        assert_eq!(f.text, "ab\ncd");
        assert_eq!(f.line_col(1), (1, 2));
        assert_eq!(f.line_col(3), (2, 1));
    }
}
