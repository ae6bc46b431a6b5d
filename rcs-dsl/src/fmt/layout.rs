//! The canonical layout of a parsed file: which constructs start a line,
//! how deep each is indented, where a block is one line or several. Rows
//! of plans and row blocks are laid out as tables by [`super::rows`].
//!
//! Comments are never moved between constructs: a comment on a line of its
//! own stays on its own line before what followed it; a comment after code
//! stays after that code, at its column when the code ends before it.
//! Blank lines are kept (at most one) between the entries of a block, and
//! exactly one separates the items of a file.

use super::out::{Out, INDENT};
use super::syntax::{SyntaxElement, SyntaxKind, SyntaxNode, SyntaxToken};
use SyntaxKind as K;

/// What the layout needs besides the tree.
pub(crate) struct Layout<'a> {
    /// The original text (for columns and line breaks of comments).
    pub(crate) src: &'a str,
    pub(crate) max_width: usize,
}

/// How the members of a block are separated.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sep {
    /// Nothing (entries, rows, jobs: a `;` between jobs is dropped).
    None,
    /// A comma after every member (variants, fields, bindings).
    Comma,
}

impl<'a> Layout<'a> {
    /// Whether the text before `offset` on its line is only indentation.
    pub(crate) fn starts_line(&self, offset: usize) -> bool {
        let before = &self.src[..offset];
        before
            .trim_end_matches([' ', '\t'])
            .chars()
            .next_back()
            .is_none_or(|c| c == '\n' || c == '\r')
    }

    /// Line breaks in the whitespace right before `offset`.
    pub(crate) fn breaks_before(&self, offset: usize) -> usize {
        let before = &self.src[..offset];
        let ws = before.len()
            - before
                .trim_end_matches([' ', '\t', '\n', '\r', '\x0b', '\x0c'])
                .len();
        let ws = &before[before.len() - ws..];
        ws.replace("\r\n", "\n").matches(['\n', '\r']).count()
    }

    /// The column (in characters) `offset` had in the original text.
    fn column(&self, offset: usize) -> usize {
        let before = &self.src[..offset];
        let line_start = before.rfind(['\n', '\r']).map_or(0, |i| i + 1);
        before[line_start..].chars().count()
    }

    fn offset(el: &SyntaxElement) -> usize {
        usize::from(el.text_range().start())
    }

    /// The whole file.
    pub(crate) fn file(&self, root: &SyntaxNode, out: &mut Out) {
        let mut prev_item = false;
        let mut prev_block = false;
        let mut first = true;
        for el in root.children_with_tokens() {
            match &el {
                rowan::NodeOrToken::Token(t) if t.kind() == K::Whitespace => {}
                rowan::NodeOrToken::Token(t) if t.text() == "\u{FEFF}" => {
                    out.text.push_str(t.text())
                }
                rowan::NodeOrToken::Token(t) if t.kind().is_trivia() => {
                    let own = self.starts_line(Self::offset(&el));
                    if own && !first && (prev_item || self.breaks_before(Self::offset(&el)) >= 2) {
                        out.blank_line();
                    }
                    self.comment(t, out);
                    prev_item = false;
                    first = false;
                }
                rowan::NodeOrToken::Token(t) => {
                    // Nothing else stands between items of a parsed file.
                    out.token(t.kind(), t.text());
                }
                rowan::NodeOrToken::Node(item) => {
                    // Laid out first: whether it takes several lines (its
                    // docs and attributes aside) decides the blank line.
                    let mut laid = Out::new(0);
                    self.member(item, &mut laid);
                    let block = laid
                        .text
                        .lines()
                        .filter(|l| {
                            let l = l.trim_start();
                            !(l.starts_with("//") || l.starts_with("#[") || l.starts_with("/*"))
                        })
                        .count()
                        > 1;
                    if !first {
                        // One blank line around an item of several lines;
                        // one-line items (constants) keep their grouping.
                        if (prev_item && (prev_block || block))
                            || self.breaks_before(Self::offset(&el)) >= 2
                        {
                            out.blank_line();
                        } else {
                            out.newline();
                        }
                    }
                    out.raw(&laid.text);
                    prev_item = true;
                    prev_block = block;
                    first = false;
                }
            }
        }
        out.newline();
        // No blank line at the end of the file; exactly one line break.
        let trimmed = out.text.trim_end_matches(['\n', ' ']).len();
        out.text.truncate(trimmed);
        if !out.text.is_empty() && out.text != "\u{FEFF}" {
            out.text.push('\n');
        }
    }

    /// A comment token where it stood: on a line of its own or after code.
    pub(crate) fn comment(&self, t: &SyntaxToken, out: &mut Out) {
        let offset = usize::from(t.text_range().start());
        let own = self.starts_line(offset);
        out.comment(t.kind(), t.text(), own, self.column(offset));
    }

    /// The members of a block (the elements between its braces), one per
    /// line at `out.indent`, with `member` laying out each member node.
    pub(crate) fn block(
        &self,
        elements: &[SyntaxElement],
        sep: Sep,
        out: &mut Out,
        member: &mut dyn FnMut(&SyntaxNode, &mut Out),
    ) {
        let mut first = true;
        for el in elements {
            match el {
                rowan::NodeOrToken::Token(t) if t.kind() == K::Whitespace => {}
                rowan::NodeOrToken::Token(t)
                    if matches!(t.text(), "," | ";") && t.kind() == K::Punct => {}
                rowan::NodeOrToken::Token(t) if t.kind().is_trivia() => {
                    let offset = Self::offset(el);
                    if self.starts_line(offset) {
                        if !first && self.breaks_before(offset) >= 2 {
                            out.blank_line();
                        } else {
                            out.newline();
                        }
                    }
                    self.comment(t, out);
                    first = false;
                }
                rowan::NodeOrToken::Token(t) => {
                    // A token directly in a block (none in a parsed file
                    // but the separators): keep it, on its own line.
                    out.newline();
                    out.token(t.kind(), t.text());
                    first = false;
                }
                rowan::NodeOrToken::Node(node) => {
                    if !first && self.breaks_before(Self::offset(el)) >= 2 {
                        out.blank_line();
                    } else {
                        out.newline();
                    }
                    member(node, out);
                    if sep == Sep::Comma {
                        if out.line_closed() {
                            // Only after a comment inside the member.
                            out.newline();
                        }
                        out.token(K::Punct, ",");
                    }
                    first = false;
                }
            }
        }
    }

    /// An item, entry, variant, field, parameter or row: its doc comments
    /// and attributes each on a line, then the construct.
    pub(crate) fn member(&self, node: &SyntaxNode, out: &mut Out) {
        let mut started = false;
        for el in node.children_with_tokens() {
            match &el {
                rowan::NodeOrToken::Token(t) if !started && t.kind() == K::DocComment => {
                    out.newline();
                    out.token(t.kind(), t.text());
                    out.newline();
                }
                rowan::NodeOrToken::Token(t) if !started && t.kind().is_trivia() => {
                    if t.kind() != K::Whitespace {
                        self.comment(t, out);
                        if self.starts_line(Self::offset(&el)) || t.kind() == K::LineComment {
                            out.newline();
                        }
                    }
                }
                rowan::NodeOrToken::Node(n) if !started && n.kind() == K::Attribute => {
                    out.newline();
                    self.flow_node(n, out);
                    out.newline();
                }
                rowan::NodeOrToken::Node(n)
                    if !started && matches!(node.kind(), K::Item | K::Entry) =>
                {
                    started = true;
                    self.construct(n, out);
                }
                _ => {
                    started = true;
                    self.flow_element(&el, out);
                }
            }
        }
    }

    /// One definition or declaration.
    fn construct(&self, node: &SyntaxNode, out: &mut Out) {
        match node.kind() {
            K::ControllerDef | K::ControllerTypeDef => {
                self.braced(node, out, |this, body, out| {
                    this.block(body, Sep::None, out, &mut |n, out| this.member(n, out))
                });
            }
            K::InstanceDef | K::EnumDef | K::BufferDef => {
                if !self.try_one_line(node, out) {
                    self.braced(node, out, |this, body, out| {
                        this.block(body, Sep::Comma, out, &mut |n, out| this.member(n, out))
                    });
                }
            }
            K::CommandDecl | K::HookDecl | K::JobsDef
                if node.children().any(|c| {
                    c.kind() == K::Param
                        && c.children_with_tokens().any(|t| t.kind() == K::DocComment)
                }) =>
            {
                self.params_one_per_line(node, out)
            }
            K::CommandDecl if !self.fits(node, out) => self.wrapped_accept(node, out),
            K::PlanDef | K::RowsDef => {
                self.braced(node, out, |this, body, out| this.rows(body, out));
            }
            _ => self.flow_node(node, out),
        }
    }

    /// A declaration whose parameters carry doc comments: the parameters
    /// one per line (with their docs) between `(` and `)`.
    fn params_one_per_line(&self, node: &SyntaxNode, out: &mut Out) {
        let elements: Vec<SyntaxElement> = node.children_with_tokens().collect();
        let (Some(open), Some(close)) = (
            elements.iter().position(|e| is_punct(e, "(")),
            elements.iter().position(|e| is_punct(e, ")")),
        ) else {
            self.flow_node(node, out);
            return;
        };
        for el in &elements[..=open] {
            self.flow_element(el, out);
        }
        out.indent += INDENT;
        self.block(
            &elements[open + 1..close],
            Sep::Comma,
            out,
            &mut |n, out| self.member(n, out),
        );
        out.indent -= INDENT;
        out.newline();
        for el in &elements[close..] {
            self.flow_element(el, out);
        }
    }

    /// Whether `node` fits on the current line (or holds a comment, which
    /// keeps its own line breaks).
    fn fits(&self, node: &SyntaxNode, out: &Out) -> bool {
        self.one_line(node).is_none_or(|line| {
            out.line_len().max(out.indent) + line.chars().count() <= self.max_width
        })
    }

    /// `command VERB(…) accept when COND` too long for the width: the
    /// condition broken before its loosest `&&` or `||` as a row's is.
    fn wrapped_accept(&self, node: &SyntaxNode, out: &mut Out) {
        let accept = node.children().find(|c| c.kind() == K::AcceptClause);
        let expr = accept
            .as_ref()
            .and_then(|a| a.children().find(|c| c.kind() == K::Expr));
        let (Some(accept), Some(segments)) = (accept.clone(), expr.and_then(|e| self.segments(&e)))
        else {
            self.flow_node(node, out);
            return;
        };
        for el in node.children_with_tokens() {
            if el.as_node() == Some(&accept) {
                break;
            }
            self.flow_element(&el, out);
        }
        let mut first = Out::new(0);
        for el in accept.children_with_tokens() {
            if el.kind() == K::Expr {
                break;
            }
            self.flow_element(&el, &mut first);
        }
        let head = format!(" {} {}", first.text, segments[0].1);
        out.raw(&head);
        self.continue_segments(&segments[1..], "", out);
    }

    /// `node` on one line, if it was written on one, has no comment and
    /// fits the width.
    fn try_one_line(&self, node: &SyntaxNode, out: &mut Out) -> bool {
        let text = node.text().to_string();
        if text.contains(['\n', '\r']) {
            return false;
        }
        match self.one_line(node) {
            Some(line)
                if out.line_len().max(out.indent) + line.chars().count() <= self.max_width =>
            {
                self.flow_node(node, out);
                true
            }
            _ => false,
        }
    }

    /// The text of `node` laid out on one line, or `None` when a comment
    /// (or a doc comment) inside it needs a line break.
    pub(crate) fn one_line(&self, node: &SyntaxNode) -> Option<String> {
        if node
            .descendants_with_tokens()
            .any(|e| matches!(e.kind(), K::LineComment | K::BlockComment | K::DocComment))
        {
            return None;
        }
        let mut scratch = Out::new(0);
        self.flow_node(node, &mut scratch);
        Some(scratch.text)
    }

    /// A construct with a `{ … }` body laid out as a block: the header on
    /// the line, the members one level deeper, `}` on a line of its own.
    fn braced(
        &self,
        node: &SyntaxNode,
        out: &mut Out,
        body: impl FnOnce(&Self, &[SyntaxElement], &mut Out),
    ) {
        let elements: Vec<SyntaxElement> = node.children_with_tokens().collect();
        let is_brace = |e: &SyntaxElement, b: &str| matches!(e, rowan::NodeOrToken::Token(t) if t.kind() == K::Punct && t.text() == b);
        let (Some(open), Some(close)) = (
            elements.iter().position(|e| is_brace(e, "{")),
            elements.iter().rposition(|e| is_brace(e, "}")),
        ) else {
            self.flow_node(node, out);
            return;
        };
        for el in &elements[..=open] {
            self.flow_element(el, out);
        }
        out.indent += INDENT;
        body(self, &elements[open + 1..close], out);
        out.indent -= INDENT;
        out.newline();
        for el in &elements[close..] {
            self.flow_element(el, out);
        }
    }

    /// Every token of `node` on the current line (a comment breaks it).
    /// A trailing comma before `}` is dropped (a block on one line).
    pub(crate) fn flow_node(&self, node: &SyntaxNode, out: &mut Out) {
        let elements: Vec<SyntaxElement> = node.children_with_tokens().collect();
        for (i, el) in elements.iter().enumerate() {
            if is_punct(el, ",")
                && elements[i + 1..]
                    .iter()
                    .find(|e| !e.kind().is_trivia())
                    .is_some_and(|e| is_punct(e, "}"))
            {
                continue;
            }
            self.flow_element(el, out);
        }
    }

    pub(crate) fn flow_element(&self, el: &SyntaxElement, out: &mut Out) {
        match el {
            rowan::NodeOrToken::Token(t) if t.kind() == K::Whitespace => {}
            rowan::NodeOrToken::Token(t) if t.kind().is_trivia() => self.comment(t, out),
            rowan::NodeOrToken::Token(t) => out.token(t.kind(), t.text()),
            rowan::NodeOrToken::Node(n) if n.kind() == K::Jobs => self.jobs(n, out, true),
            rowan::NodeOrToken::Node(n) => self.flow_node(n, out),
        }
    }

    /// A job list: `{ a; b }` on the line when it was written on one line
    /// and fits (and `inline` allows it), else one job per line.
    pub(crate) fn jobs(&self, node: &SyntaxNode, out: &mut Out, inline: bool) {
        if inline {
            if let Some(line) = self.jobs_one_line(node) {
                if out.line_len() + 1 + line.chars().count() <= self.max_width {
                    out.raw_spaced(&line);
                    return;
                }
            }
        }
        self.braced(node, out, |this, body, out| {
            this.block(body, Sep::None, out, &mut |n, out| this.flow_node(n, out))
        });
    }

    /// `{ a; b }` (or `{}`) when the job list was written on one line and
    /// holds no comment.
    pub(crate) fn jobs_one_line(&self, node: &SyntaxNode) -> Option<String> {
        if node.text().to_string().contains(['\n', '\r']) {
            return None;
        }
        let mut jobs = Vec::new();
        for child in node.children() {
            jobs.push(self.one_line(&child)?);
        }
        if node
            .children_with_tokens()
            .any(|e| e.kind().is_trivia() && e.kind() != K::Whitespace)
        {
            return None;
        }
        Some(if jobs.is_empty() {
            "{}".to_string()
        } else {
            format!("{{ {} }}", jobs.join("; "))
        })
    }
}

/// Whether `el` is the punctuation `text`.
pub(crate) fn is_punct(el: &SyntaxElement, text: &str) -> bool {
    matches!(el, rowan::NodeOrToken::Token(t) if t.kind() == K::Punct && t.text() == text)
}

impl Out {
    /// Laid-out text after a space (a job list after its row's target).
    pub(crate) fn raw_spaced(&mut self, text: &str) {
        if self.line_has_text() && !self.text.ends_with(' ') {
            self.text.push(' ');
        }
        self.raw(text);
    }
}
