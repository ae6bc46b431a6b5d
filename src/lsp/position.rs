//! Byte offsets (what rcs-dsl's spans hold) to LSP positions and back.
//!
//! LSP counts a position's character in UTF-16 code units by default (the
//! client may offer others; this server announces UTF-16, which every
//! client understands), and a line ends at `\n` (a `\r` before it belongs to
//! the line's end, not its text).

use lsp_types::{Position, Range};

/// The start of every line of one text, for conversions both ways.
pub struct LineIndex<'a> {
    text: &'a str,
    starts: Vec<usize>,
}

impl<'a> LineIndex<'a> {
    pub fn new(text: &'a str) -> Self {
        let starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Self { text, starts }
    }

    /// The position of byte `offset` (clamped to the text, and back to a
    /// character boundary).
    pub fn position(&self, offset: usize) -> Position {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&s| s <= offset) - 1;
        let character: usize = self.text[self.starts[line]..offset]
            .chars()
            .map(char::len_utf16)
            .sum();
        Position::new(to_u32(line), to_u32(character))
    }

    pub fn range(&self, start: usize, end: usize) -> Range {
        Range::new(self.position(start), self.position(end))
    }

    /// The byte offset of `position` (a character past the line's end
    /// means its end; a line past the last means the end of the text).
    pub fn offset(&self, position: Position) -> usize {
        let Some(&start) = self.starts.get(position.line as usize) else {
            return self.text.len();
        };
        let end = self
            .starts
            .get(position.line as usize + 1)
            .map_or(self.text.len(), |&next| next - 1);
        let line = &self.text[start..end];
        let line = line.strip_suffix('\r').unwrap_or(line);
        let mut units = 0u32;
        for (i, c) in line.char_indices() {
            if units >= position.character {
                return start + i;
            }
            units += to_u32(c.len_utf16());
        }
        start + line.len()
    }
}

fn to_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_count_utf16_units_and_round_trip() {
        let text = "ab\n// é😀x\r\nlast";
        let index = LineIndex::new(text);
        let x = text.find('x').unwrap();
        // `// ` is 3 units, `é` 1, the emoji 2.
        assert_eq!(index.position(x), Position::new(1, 6));
        assert_eq!(index.offset(Position::new(1, 6)), x);
        assert_eq!(index.position(text.len()), Position::new(2, 4));
        // Past the end of a line: its end, before the `\r`.
        assert_eq!(index.offset(Position::new(1, 99)), text.find('\r').unwrap());
        assert_eq!(index.offset(Position::new(9, 0)), text.len());
        // Inside a multi-byte character: back to its start.
        let e = text.find('é').unwrap();
        assert_eq!(index.position(e + 1), index.position(e));
    }
}
