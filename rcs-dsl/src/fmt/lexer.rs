//! The tokens of text the tree builder ([`super::syntax`]) finds between
//! pest's rules: whitespace, comments and the grammar's literal
//! punctuation. Also the whole lexer of a file pest rejects (a flat tree),
//! so it accepts any text and covers every byte.

use super::syntax::SyntaxKind;

/// `(kind, start, end)` for every token of `text`, in order, covering it.
pub(crate) fn lex(text: &str) -> Vec<(SyntaxKind, usize, usize)> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let start = i;
        let kind = match bytes[i] {
            b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c => {
                while i < bytes.len()
                    && matches!(bytes[i], b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
                {
                    i += 1;
                }
                SyntaxKind::Whitespace
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                while i < bytes.len() && bytes[i] != b'\n' && bytes[i] != b'\r' {
                    i += 1;
                }
                // `///` alone is a doc comment; the builder only asks for a
                // gap's tokens, where pest found a comment, so this is a
                // doc comment only in a flat tree.
                if is_doc(&text[start..i]) {
                    SyntaxKind::DocComment
                } else {
                    SyntaxKind::LineComment
                }
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i < bytes.len() && !(bytes[i] == b'*' && bytes.get(i + 1) == Some(&b'/')) {
                    i += 1;
                }
                i = (i + 2).min(bytes.len());
                SyntaxKind::BlockComment
            }
            _ => {
                let two = text.get(i..i + 2);
                if matches!(two, Some("->" | "::" | "<-")) {
                    i += 2;
                } else {
                    // One character (whole, however many bytes it takes).
                    i += text[i..].chars().next().map_or(1, char::len_utf8);
                }
                SyntaxKind::Punct
            }
        };
        out.push((kind, start, i));
    }
    out
}

/// `///` and not `////`.
fn is_doc(comment: &str) -> bool {
    comment.starts_with("///") && !comment.starts_with("////")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_byte_is_in_one_token() {
        let text = "  // a\n/* b */{->::<-é/* open";
        let tokens = lex(text);
        let mut pos = 0;
        for (_, s, e) in &tokens {
            assert_eq!(*s, pos);
            pos = *e;
        }
        assert_eq!(pos, text.len());
        assert_eq!(tokens[1].0, SyntaxKind::LineComment);
        assert_eq!(tokens[3].0, SyntaxKind::BlockComment);
    }
}
