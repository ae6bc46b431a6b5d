//! Stage 1: pest pairs → AST nodes. The builder also reports the few
//! syntax errors the grammar leaves to it: attributes in the wrong place,
//! the expression-depth limit, numbers out of range. Items and controller
//! entries are built in [`items`], rows and jobs in [`rows`], expressions
//! in [`expr`].

mod expr;
mod items;
mod rows;

use super::{Rule, MAX_EXPR_DEPTH};
use crate::ast::*;
use crate::diagnostic::{Code, Diagnostic};
use crate::lint::{Level, Lint};
use crate::source::{FileId, Span};
use pest::iterators::Pair;

/// Builds AST nodes from pairs, collecting the few syntax errors the grammar
/// leaves to it (attributes in the wrong place, limits, bad numbers).
pub(super) struct Builder {
    pub(super) file: FileId,
    pub(super) diags: Vec<Diagnostic>,
}

impl Builder {
    pub(in crate::parser) fn span(&self, p: &Pair<Rule>) -> Span {
        let s = p.as_span();
        // A rule that ends in a repetition keeps the whitespace pest skipped
        // before trying it once more; a label should end at the last token.
        let trailing = s.as_str().len() - s.as_str().trim_end().len();
        Span::new(self.file, s.start(), s.end() - trailing)
    }

    /// The span of a pair that cannot end in whitespace (a token, or a
    /// rule that ends in one): [`Builder::span`] without the trimming.
    pub(in crate::parser) fn token_span(&self, p: &Pair<Rule>) -> Span {
        let s = p.as_span();
        Span::new(self.file, s.start(), s.end())
    }

    /// A user-chosen name; reserved words are refused here (see grammar.pest).
    pub(in crate::parser) fn name(&mut self, p: Pair<Rule>) -> Name {
        // An identifier is a token: no trailing whitespace to trim.
        let name = Name {
            text: p.as_str().into(),
            span: self.token_span(&p),
        };
        if RESERVED.contains(&name.text.as_str()) {
            let help = match name.text.as_str() {
                "cmd" => "read a command parameter as `cmd.NAME`".to_string(),
                _ => format!(
                    "`{}` is a keyword of the language; choose another name",
                    name.text
                ),
            };
            self.diags.push(
                Diagnostic::error(
                    Code::Syntax,
                    format!("`{}` is a reserved word", name.text),
                    name.span,
                    "reserved word used as a name",
                )
                .with_help(help),
            );
        }
        name
    }

    pub(in crate::parser) fn error(
        &mut self,
        span: Span,
        message: impl Into<String>,
        label: impl Into<String>,
    ) {
        self.diags
            .push(Diagnostic::error(Code::Syntax, message, span, label));
    }

    pub(in crate::parser) fn int(&mut self, p: Pair<Rule>) -> u64 {
        let span = self.span(&p);
        match parse_int(p.as_str()) {
            Ok(v) => v,
            Err(_) => {
                self.error(
                    span,
                    "integer literal is too large",
                    "does not fit in 64 bits",
                );
                0
            }
        }
    }

    pub(in crate::parser) fn doc(p: &Pair<Rule>) -> String {
        let s = p.as_str().trim_start_matches("///");
        s.strip_prefix(' ').unwrap_or(s).trim_end().to_string()
    }

    pub(in crate::parser) fn outer(&mut self, pairs: &mut Vec<Pair<Rule>>) -> Outer {
        let mut outer = Outer::default();
        for p in pairs.drain(..) {
            match p.as_rule() {
                Rule::doc_comment => outer.docs.push(Self::doc(&p)),
                Rule::attribute => {
                    let mut inner = p.into_inner();
                    let level = inner.next().expect("attribute has a level");
                    let level = Level::from_name(level.as_str()).expect("grammar limits levels");
                    for name in inner {
                        let span = self.span(&name);
                        match Lint::from_name(name.as_str()) {
                            Some(lint) => outer.lints.push(((lint, level), span)),
                            None => self.diags.push(
                                Diagnostic::error(
                                    Code::UnknownName,
                                    format!("unknown lint `{}`", name.as_str()),
                                    span,
                                    "not a lint",
                                )
                                .with_help(format!(
                                    "the lints are: {}",
                                    Lint::ALL.map(Lint::name).join(", ")
                                ))
                                .suggest(name.as_str(), Lint::ALL.map(Lint::name)),
                            ),
                        }
                    }
                }
                _ => unreachable!("outer holds only docs and attributes"),
            }
        }
        outer
    }

    /// Split leading docs/attributes from the rest of a pair's children.
    pub(in crate::parser) fn split_outer<'i>(
        &mut self,
        p: Pair<'i, Rule>,
    ) -> (Outer, Vec<Pair<'i, Rule>>) {
        let mut lead = Vec::new();
        let mut rest = Vec::new();
        for c in p.into_inner() {
            if rest.is_empty() && matches!(c.as_rule(), Rule::doc_comment | Rule::attribute) {
                lead.push(c);
            } else {
                rest.push(c);
            }
        }
        (self.outer(&mut lead), rest)
    }

    pub(in crate::parser) fn no_attributes(&mut self, outer: &Outer, what: &str) {
        for (_, span) in &outer.lints {
            self.error(
                *span,
                format!("lint attributes cannot stand before {what}"),
                "attribute not allowed here",
            );
            self.diags.last_mut().expect("just pushed").help =
                Some("put it before the controller or the plan".to_string());
        }
    }
}

/// Words of the language that cannot name anything (LANGUAGE.md §1).
pub const RESERVED: [&str; 26] = [
    "enum",
    "buffer",
    "controller",
    "level",
    "subordinates",
    "reads",
    "writes",
    "command",
    "status",
    "error",
    "var",
    "hook",
    "plan",
    "when",
    "otherwise",
    "report",
    "true",
    "false",
    "same",
    "as",
    "new_command",
    "cmd",
    "state_cycles",
    "plan_cycles",
    "state_time",
    "plan_time",
];

fn bin_op(s: &str) -> BinOp {
    match s {
        "||" => BinOp::Or,
        "&&" => BinOp::And,
        "==" => BinOp::Eq,
        "!=" => BinOp::Ne,
        "<" => BinOp::Lt,
        "<=" => BinOp::Le,
        ">" => BinOp::Gt,
        ">=" => BinOp::Ge,
        "+" => BinOp::Add,
        "-" => BinOp::Sub,
        "*" => BinOp::Mul,
        "/" => BinOp::Div,
        "&" => BinOp::BitAnd,
        "|" => BinOp::BitOr,
        "^" => BinOp::BitXor,
        "<<" => BinOp::Shl,
        ">>" => BinOp::Shr,
        _ => BinOp::Rem,
    }
}

/// An integer literal: decimal, `0x` hex or `0b` binary, `_` allowed.
pub(in crate::parser) fn parse_int(s: &str) -> Result<u64, ()> {
    let (digits, radix) = match s.get(..2) {
        Some("0x") => (&s[2..], 16),
        Some("0b") => (&s[2..], 2),
        _ => (s, 10),
    };
    let digits = without_underscores(digits);
    if digits.is_empty() {
        return Err(());
    }
    u64::from_str_radix(&digits, radix).map_err(|_| ())
}

/// A number's digits without its `_` separators (borrowed when it has
/// none, as most do: no allocation per literal).
fn without_underscores(s: &str) -> std::borrow::Cow<'_, str> {
    if s.contains('_') {
        std::borrow::Cow::Owned(s.replace('_', ""))
    } else {
        std::borrow::Cow::Borrowed(s)
    }
}

fn unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(other) => out.push(other),
                None => {}
            }
        } else {
            out.push(c);
        }
    }
    out
}
