//! The formatter's output: text written token by token, with the spacing
//! between two tokens decided here, once, from their kinds (the layout in
//! [`super::layout`] decides only line breaks and indentation).

use super::syntax::SyntaxKind;

/// Spaces per indentation level.
pub(crate) const INDENT: usize = 4;

pub(crate) struct Out {
    pub(crate) text: String,
    /// The indentation of the block being written, in spaces.
    pub(crate) indent: usize,
    /// The last token written on the current line (`None` at a line start).
    prev: Option<(SyntaxKind, String)>,
    /// A line comment or doc comment ended the line: the next token must
    /// start a new one (a continuation line inside a construct).
    need_newline: bool,
    /// The continuation indent of the current line (0: a line of its block).
    line_continuation: usize,
}

impl Out {
    pub(crate) fn new(indent: usize) -> Out {
        Out {
            text: String::new(),
            indent,
            prev: None,
            need_newline: false,
            line_continuation: 0,
        }
    }

    /// Characters on the current line so far.
    pub(crate) fn line_len(&self) -> usize {
        let line = match self.text.rfind('\n') {
            Some(i) => &self.text[i + 1..],
            None => &self.text[..],
        };
        line.chars().count()
    }

    fn at_line_start(&self) -> bool {
        self.text.is_empty() || self.text.ends_with('\n')
    }

    /// End the current line (unless already at a line start).
    pub(crate) fn newline(&mut self) {
        if !self.at_line_start() {
            let trimmed = self.text.trim_end_matches([' ', '\t']).len();
            self.text.truncate(trimmed);
            self.text.push('\n');
        }
        self.prev = None;
        self.need_newline = false;
    }

    /// End the current line and leave one empty line (not at the start of
    /// the output).
    pub(crate) fn blank_line(&mut self) {
        self.newline();
        if !self.text.is_empty() && !self.text.ends_with("\n\n") {
            self.text.push('\n');
        }
    }

    fn indent_line(&mut self, continuation: usize) {
        for _ in 0..self.indent + continuation {
            self.text.push(' ');
        }
        self.line_continuation = continuation;
    }

    /// Whether anything but a line break was written since the last one.
    pub(crate) fn line_has_text(&self) -> bool {
        !self.at_line_start()
    }

    fn start_token(&mut self, kind: SyntaxKind, text: &str, continuation: usize) {
        if self.need_newline {
            self.newline();
        }
        if self.at_line_start() {
            self.indent_line(continuation);
        } else if let Some((pk, pt)) = &self.prev {
            if space_between(*pk, pt, kind, text) {
                self.text.push(' ');
            }
        } else {
            self.text.push(' ');
        }
    }

    /// Write a token of the language, spaced from the one before it; a
    /// token forced onto a new line by a comment is indented one level
    /// deeper than its block.
    pub(crate) fn token(&mut self, kind: SyntaxKind, text: &str) {
        let continuation = if self.need_newline { INDENT } else { 0 };
        self.start_token(kind, text, continuation);
        self.text.push_str(text);
        self.prev = Some((kind, text.to_string()));
        if kind == SyntaxKind::DocComment {
            self.need_newline = true;
        }
    }

    /// Write text already laid out (a row of a table), as one token.
    pub(crate) fn raw(&mut self, text: &str) {
        if self.at_line_start() {
            for _ in 0..self.indent {
                self.text.push(' ');
            }
        }
        self.text.push_str(text);
        self.prev = Some((SyntaxKind::Punct, "\u{0}".to_string()));
    }

    /// A comment. `own_line`: it stood on a line of its own. `column`: where
    /// it started on its line, kept for a comment after code when the code
    /// ends before it (so aligned comments stay aligned).
    pub(crate) fn comment(&mut self, kind: SyntaxKind, text: &str, own_line: bool, column: usize) {
        let text = text.trim_end();
        if own_line {
            // Inside a construct (code before it on the line) a comment
            // line is a continuation; after another comment, its sibling.
            let continuation = if self.need_newline {
                self.line_continuation
            } else if self.line_has_text() {
                INDENT
            } else {
                0
            };
            self.newline();
            self.indent_line(continuation);
        } else if self.at_line_start() {
            for _ in 0..self.indent {
                self.text.push(' ');
            }
        } else {
            let len = self.line_len();
            let pad = if column > len { column - len } else { 1 };
            for _ in 0..pad {
                self.text.push(' ');
            }
        }
        self.text.push_str(text);
        self.prev = Some((kind, text.to_string()));
        if kind == SyntaxKind::LineComment {
            self.need_newline = true;
        }
    }

    /// Whether the last thing written ends its line by itself (a line or
    /// doc comment).
    pub(crate) fn line_closed(&self) -> bool {
        self.need_newline
    }
}

/// Whether one space separates `prev` and `next` on a line. No space is
/// only ever chosen next to punctuation, so two names or numbers never
/// run together; the formatter checks its result re-parses to the same
/// tree in any case ([`super::format`]).
fn space_between(pk: SyntaxKind, pt: &str, nk: SyntaxKind, nt: &str) -> bool {
    use SyntaxKind::*;
    if pk == LineComment || pk == DocComment {
        return true;
    }
    if matches!(nt, ")" | "]" | "," | ";" | "." | "::" | ":") {
        return false;
    }
    if matches!(pt, "(" | "[" | "." | "::" | "#") || pk == OpUnary {
        return false;
    }
    match nt {
        "(" => !matches!(pk, Ident | ErrorWord | LintLevel),
        "[" => !(pk == Ident || pt == ")" || pt == "]"),
        "}" => pt != "{",
        _ => {
            let _ = nk;
            true
        }
    }
}
