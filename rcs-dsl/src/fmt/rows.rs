//! The rows of a plan (or of a `rows` block) as a table: label, from-state,
//! condition, target and jobs in columns, so the precedence order reads
//! down and each edge across (LANGUAGE.md §3 writes plans this way).
//!
//! A row with a comment inside it keeps its own layout (the comment stays
//! where it was). A row too long for the width even unaligned leaves the
//! table; if still too long, its condition is broken before each of its
//! loosest `&&` or `||`, one operand per line, and its jobs go one per line.

use super::layout::{Layout, Sep};
use super::out::{Out, INDENT};
use super::syntax::{SyntaxElement, SyntaxKind, SyntaxNode};
use SyntaxKind as K;

/// A row without comments inside, in parts.
struct Parts {
    label: String,
    from: String,
    cond: String,
    /// The node of the condition's expression (for wrapping).
    expr: Option<SyntaxNode>,
    target: String,
    jobs: Jobs,
}

enum Jobs {
    None,
    Inline(String, SyntaxNode),
    Block(SyntaxNode),
}

/// Column widths of a table (0: the column is empty in every row).
#[derive(Clone, Copy, Default)]
struct Widths {
    label: usize,
    from: usize,
    cond: usize,
    target: usize,
}

fn width(s: &str) -> usize {
    s.chars().count()
}

impl Parts {
    fn own_widths(&self) -> Widths {
        Widths {
            label: width(&self.label),
            from: width(&self.from),
            cond: width(&self.cond),
            target: width(&self.target),
        }
    }

    /// The row's line up to its job list (or `{` of a job block), padded
    /// to `w`.
    fn line(&self, w: Widths) -> String {
        let mut cols: Vec<String> = Vec::new();
        if w.label > 0 {
            cols.push(format!("{:<1$}", self.label, w.label));
        }
        if w.from > 0 {
            cols.push(format!("{:<1$}", self.from, w.from));
        }
        cols.push(format!("{:<1$}", self.cond, w.cond));
        match &self.jobs {
            Jobs::Inline(jobs, _) => {
                cols.push(format!("{:<1$}", self.target, w.target));
                cols.push(jobs.clone());
            }
            Jobs::Block(_) => {
                cols.push(self.target.clone());
                cols.push("{".to_string());
            }
            Jobs::None => cols.push(self.target.clone()),
        }
        cols.join(" ").trim_end().to_string()
    }
}

impl Layout<'_> {
    /// The rows and `use` lines of a plan or row block (the elements
    /// between its braces), at `out.indent`.
    pub(crate) fn rows(&self, body: &[SyntaxElement], out: &mut Out) {
        let indent = out.indent;
        let rows: Vec<SyntaxNode> = body
            .iter()
            .filter_map(|e| e.as_node().filter(|n| n.kind() == K::Row).cloned())
            .collect();
        let mut parts: Vec<Option<Parts>> = rows.iter().map(|r| self.parts(r, indent)).collect();
        // The table: rows that fit the width when aligned with the others.
        let mut in_table: Vec<bool> = parts.iter().map(Option::is_some).collect();
        let widths = loop {
            let mut w = Widths::default();
            for p in parts
                .iter()
                .zip(&in_table)
                .filter_map(|(p, t)| p.as_ref().filter(|_| *t))
            {
                let own = p.own_widths();
                w.label = w.label.max(own.label);
                w.from = w.from.max(own.from);
                w.cond = w.cond.max(own.cond);
                if matches!(p.jobs, Jobs::Inline(..)) {
                    w.target = w.target.max(own.target);
                }
            }
            let too_long = parts
                .iter()
                .zip(&in_table)
                .filter_map(|(p, t)| p.as_ref().filter(|_| *t))
                .any(|p| indent + width(&p.line(w)) > self.max_width);
            if !too_long {
                break w;
            }
            // The row with the widest condition (the last of equals) leaves
            // the table: the others' columns narrow.
            let widest = parts
                .iter()
                .enumerate()
                .filter_map(|(i, p)| {
                    p.as_ref()
                        .filter(|_| in_table[i])
                        .map(|p| (width(&p.cond), i))
                })
                .max()
                .map(|(_, i)| i);
            match widest {
                Some(i) => in_table[i] = false,
                None => break w,
            }
        };
        let mut next_row = 0;
        self.block(body, Sep::None, out, &mut |node, out| {
            if node.kind() != K::Row {
                self.flow_node(node, out);
                return;
            }
            let i = next_row;
            next_row += 1;
            match parts.get_mut(i).and_then(Option::take) {
                Some(p) => {
                    self.docs(node, out);
                    let w = if in_table[i] { widths } else { p.own_widths() };
                    self.row(&p, w, out);
                }
                None => self.member(node, out),
            }
        });
    }

    fn docs(&self, row: &SyntaxNode, out: &mut Out) {
        for t in row.children_with_tokens().filter_map(|e| e.into_token()) {
            if t.kind() == K::DocComment {
                out.newline();
                out.token(t.kind(), t.text());
                out.newline();
            }
        }
    }

    fn row(&self, p: &Parts, w: Widths, out: &mut Out) {
        let line = p.line(w);
        let block = match &p.jobs {
            Jobs::Block(jobs) => Some(jobs),
            _ if out.indent + width(&line) <= self.max_width => None,
            Jobs::Inline(_, jobs) => Some(jobs),
            Jobs::None => None,
        };
        if out.indent + width(&line) <= self.max_width {
            out.raw(&line);
        } else {
            self.wrapped(p, out);
        }
        if let Some(jobs) = block {
            // `line` ends in the `{` the job block opens; the block writes it.
            let trimmed = out.text.trim_end_matches('{').trim_end().len();
            out.text.truncate(trimmed);
            self.jobs(jobs, out, false);
        }
    }

    /// A row too long for the width: its condition one operand per line.
    fn wrapped(&self, p: &Parts, out: &mut Out) {
        let segments = p.expr.as_ref().and_then(|e| self.segments(e));
        let Some(segments) = segments else {
            out.raw(&p.line(p.own_widths()));
            return;
        };
        let mut head: Vec<&str> = Vec::new();
        for s in [&p.label, &p.from] {
            if !s.is_empty() {
                head.push(s);
            }
        }
        let tail = match &p.jobs {
            Jobs::None => p.target.clone(),
            Jobs::Inline(..) | Jobs::Block(_) => format!("{} {{", p.target),
        };
        // As many operands on a line as fit; the next line starts with the
        // operator, two levels deeper than the row.
        let first = format!("{} when {}", head.join(" "), segments[0].1);
        let mut line = first.trim_start().to_string();
        let mut line_indent = out.indent;
        let mut lines = Vec::new();
        for (op, text) in &segments[1..] {
            let piece = format!("{op} {text}");
            if line_indent + width(&line) + 1 + width(&piece) <= self.max_width {
                line = format!("{line} {piece}");
            } else {
                lines.push((line_indent, std::mem::replace(&mut line, piece)));
                line_indent = out.indent + 2 * INDENT;
            }
        }
        if line_indent + width(&line) + 1 + width(&tail) <= self.max_width || lines.is_empty() {
            line = format!("{line} {tail}");
            lines.push((line_indent, line));
        } else {
            lines.push((line_indent, line));
            lines.push((out.indent + 2 * INDENT, tail));
        }
        let block_indent = out.indent;
        for (i, (indent, text)) in lines.iter().enumerate() {
            if i > 0 {
                out.newline();
            }
            out.indent = *indent;
            out.raw(text);
        }
        out.indent = block_indent;
    }

    /// After a line holding a condition's first operand: the other
    /// operands, as many on a line as fit, each further line starting with
    /// the operator two levels deeper; then `tail` (if any) on the last
    /// line, or on one of its own when it does not fit.
    pub(crate) fn continue_segments(
        &self,
        segments: &[(String, String)],
        tail: &str,
        out: &mut Out,
    ) {
        let block_indent = out.indent;
        let deeper = block_indent + 2 * INDENT;
        for (op, text) in segments {
            let piece = format!("{op} {text}");
            if out.line_len() + 1 + width(&piece) <= self.max_width {
                out.text.push(' ');
                out.text.push_str(&piece);
            } else {
                out.newline();
                out.indent = deeper;
                out.raw(&piece);
                out.indent = block_indent;
            }
        }
        if !tail.is_empty() {
            if out.line_len() + 1 + width(tail) <= self.max_width {
                out.text.push(' ');
                out.text.push_str(tail);
            } else {
                out.newline();
                out.indent = deeper;
                out.raw(tail);
                out.indent = block_indent;
            }
        }
    }

    /// The condition split before each of its loosest boolean operators,
    /// `None` when it has none at its top level.
    pub(crate) fn segments(&self, expr: &SyntaxNode) -> Option<Vec<(String, String)>> {
        let elements: Vec<SyntaxElement> = expr
            .children_with_tokens()
            .filter(|e| e.kind() != K::Whitespace)
            .collect();
        let loosest = ["||", "&&"].into_iter().find(|op| {
            elements
                .iter()
                .any(|e| e.kind() == K::Infix && e.as_token().is_some_and(|t| t.text() == *op))
        })?;
        let mut segments = vec![(String::new(), Out::new(0))];
        for el in &elements {
            match el {
                rowan::NodeOrToken::Token(t) if t.kind() == K::Infix && t.text() == loosest => {
                    segments.push((loosest.to_string(), Out::new(0)));
                }
                _ => {
                    let last = segments.last_mut().expect("one segment at least");
                    self.flow_element(el, &mut last.1);
                }
            }
        }
        Some(
            segments
                .into_iter()
                .map(|(op, out)| (op, out.text))
                .collect(),
        )
    }

    /// A row's parts, `None` when a comment inside it keeps its layout.
    fn parts(&self, row: &SyntaxNode, indent: usize) -> Option<Parts> {
        let mut p = Parts {
            label: String::new(),
            from: String::new(),
            cond: String::new(),
            expr: None,
            target: String::new(),
            jobs: Jobs::None,
        };
        let mut jobs_node = None;
        for el in row.children_with_tokens() {
            match &el {
                rowan::NodeOrToken::Token(t) => match t.kind() {
                    K::Whitespace | K::DocComment => {}
                    K::LineComment | K::BlockComment => return None,
                    K::RowLabel => p.label = t.text().to_string(),
                    K::Punct if t.text() == ":" => p.label.push(':'),
                    K::KwWhen => p.cond = "when".to_string(),
                    K::KwOtherwise => p.cond = "otherwise".to_string(),
                    K::Arrow => p.target = "->".to_string(),
                    _ => return None,
                },
                rowan::NodeOrToken::Node(n) => match n.kind() {
                    K::FromState => p.from = self.one_line(n)?,
                    K::Expr => {
                        p.cond = format!("{} {}", p.cond, self.one_line(n)?);
                        p.expr = Some(n.clone());
                    }
                    K::Target => p.target = format!("{} {}", p.target, self.one_line(n)?),
                    K::Jobs => jobs_node = Some(n.clone()),
                    _ => return None,
                },
            }
        }
        if let Some(jobs) = jobs_node {
            if jobs
                .descendants_with_tokens()
                .any(|e| matches!(e.kind(), K::LineComment | K::BlockComment | K::DocComment))
            {
                // Its comments are laid out by the job block.
                p.jobs = Jobs::Block(jobs);
                return Some(p);
            }
            p.jobs = match self.jobs_one_line(&jobs) {
                Some(line) => {
                    let candidate = Parts {
                        jobs: Jobs::Inline(line.clone(), jobs.clone()),
                        ..clone_head(&p)
                    };
                    if indent + width(&candidate.line(candidate.own_widths())) <= self.max_width {
                        Jobs::Inline(line, jobs)
                    } else {
                        Jobs::Block(jobs)
                    }
                }
                None => Jobs::Block(jobs),
            };
        }
        Some(p)
    }
}

fn clone_head(p: &Parts) -> Parts {
    Parts {
        label: p.label.clone(),
        from: p.from.clone(),
        cond: p.cond.clone(),
        expr: p.expr.clone(),
        target: p.target.clone(),
        jobs: Jobs::None,
    }
}
