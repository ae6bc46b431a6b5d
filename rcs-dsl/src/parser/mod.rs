//! Stage 1 of the pipeline: text → [`ast::File`]. pest does the matching;
//! this module turns its pairs into the AST and its failures into `syntax`
//! diagnostics phrased in the user's words.
//!
//! Hostile input is bounded here: a size limit, a bracket-nesting limit
//! checked before pest runs (so no input can exhaust the stack), and an
//! expression-depth limit while folding operator chains.
//!
//! Pairs become AST nodes in [`builder`]; pest's failures become
//! diagnostics in [`syntax_error`].

use crate::ast::*;
use crate::diagnostic::{Code, Diagnostic};
use crate::source::{FileId, Span};
use pest::Parser as _;

mod builder;
mod foreign;
mod syntax_error;

use builder::Builder;
pub use builder::RESERVED;
use syntax_error::syntax_error;

#[derive(pest_derive::Parser)]
#[grammar = "grammar.pest"]
struct RcsParser;

/// pest's parse tree of a file [`parse_file`] accepted: the nesting the
/// lossless syntax tree of `rcsc fmt` ([`crate::fmt`]) is built from, so
/// that the formatter sees exactly the structure the parser does. `None`
/// when pest rejects the text (callers run [`parse_file`] first, which
/// also bounds the nesting before pest runs).
pub(crate) fn pest_tree(text: &str) -> Option<pest::iterators::Pair<'_, Rule>> {
    RcsParser::parse(Rule::file, text).ok()?.next()
}

/// Largest accepted source file.
pub const MAX_FILE_BYTES: usize = 16 * 1024 * 1024;
/// Deepest accepted nesting of `(`, `[` and `{`.
pub const MAX_NESTING: usize = 64;
/// Deepest accepted expression tree (operator chains count one level per operator).
pub const MAX_EXPR_DEPTH: usize = 256;

/// Parse one file. On failure, returns its `syntax` diagnostics.
pub fn parse_file(file: FileId, text: &str) -> Result<File, Vec<Diagnostic>> {
    if text.len() > MAX_FILE_BYTES {
        return Err(vec![Diagnostic::error(
            Code::Syntax,
            format!(
                "file is too large ({} bytes; the limit is {} bytes)",
                text.len(),
                MAX_FILE_BYTES
            ),
            Span::new(file, 0, 0),
            "this file",
        )
        .with_help("split the plan set into smaller files")]);
    }
    check_nesting(file, text)?;
    let pairs = match RcsParser::parse(Rule::file, text) {
        Ok(mut pairs) => pairs.next().expect("the file rule always yields one pair"),
        Err(e) => {
            // Tracking every token tried costs time, so only a failed parse
            // runs again with it, to say which punctuation was expected.
            pest::set_error_detail(true);
            let detailed = RcsParser::parse(Rule::file, text).err();
            pest::set_error_detail(false);
            return Err(vec![syntax_error(file, text, detailed.unwrap_or(e))]);
        }
    };
    let mut builder = Builder {
        file,
        diags: Vec::new(),
    };
    let mut out = File::default();
    for p in pairs.into_inner() {
        if p.as_rule() == Rule::item {
            if let Some(item) = builder.item(p) {
                out.items.push(item);
            }
        }
    }
    if builder.diags.is_empty() {
        Ok(out)
    } else {
        Err(builder.diags)
    }
}

/// Reject bracket nesting deeper than [`MAX_NESTING`] before pest sees the
/// text, skipping comments and strings the way the grammar does. An
/// unterminated block comment or string is reported here too, in plain
/// words, where pest could only point at an unexpected `/` or `"`.
fn check_nesting(file: FileId, text: &str) -> Result<(), Vec<Diagnostic>> {
    let bytes = text.as_bytes();
    let mut depth = 0usize;
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                while i < bytes.len() && bytes[i] != b'\n' && bytes[i] != b'\r' {
                    i += 1;
                }
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                let start = i;
                i += 2;
                while i < bytes.len() && !(bytes[i] == b'*' && bytes.get(i + 1) == Some(&b'/')) {
                    i += 1;
                }
                if i >= bytes.len() {
                    // pest would only say that `/` is unexpected here.
                    return Err(vec![Diagnostic::error(
                        Code::Syntax,
                        "unterminated block comment",
                        Span::new(file, start, start + 2),
                        "this comment is never closed",
                    )
                    .with_help("close it with `*/`; block comments do not nest")]);
                }
                i += 1;
            }
            b'"' => {
                let start = i;
                i += 1;
                while i < bytes.len() && !matches!(bytes[i], b'"' | b'\n' | b'\r') {
                    if bytes[i] == b'\\' {
                        i += 1;
                    }
                    i += 1;
                }
                if i >= bytes.len() || bytes[i] != b'"' {
                    return Err(vec![Diagnostic::error(
                        Code::Syntax,
                        "unterminated string",
                        Span::new(file, start, start + 1),
                        "this string has no closing `\"` on its line",
                    )
                    .with_help("close the title with `\"`; strings cannot span lines")]);
                }
            }
            b'(' | b'[' | b'{' => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Err(vec![Diagnostic::error(
                        Code::Syntax,
                        format!("brackets nested more than {MAX_NESTING} deep"),
                        Span::new(file, i, i + 1),
                        "nesting limit reached here",
                    )
                    .with_help("split the expression with a `var` or a hook")]);
                }
            }
            b')' | b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
        i += 1;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The condition of the first row of the first plan, fully parenthesised.
    fn condition(cond: &str) -> String {
        let text = format!(
            "controller A {{\n command GO\n plan GO {{\n *0 when {cond} -> Done\n }}\n}}\n"
        );
        let file = parse_file(FileId(0), &text).expect("parses");
        let Item::Controller(c) = &file.items[0] else {
            panic!("a controller")
        };
        let rows = c
            .entries
            .iter()
            .find_map(|e| match &e.kind {
                EntryKind::Plan(p) => Some(&p.rows),
                _ => None,
            })
            .expect("a plan");
        show(rows[0].cond.as_ref().expect("a condition"))
    }

    fn show(e: &Expr) -> String {
        match &e.kind {
            ExprKind::Path(None, n) => n.text.to_string(),
            ExprKind::CmdParam(n) => format!("cmd.{}", n.text),
            ExprKind::Path(Some(q), n) => format!("{}::{}", q.text, n.text),
            ExprKind::Call(f, args) => {
                let args: Vec<String> = args.iter().map(show).collect();
                format!("{}({})", f.text, args.join(", "))
            }
            ExprKind::Field(x, n) => format!("{}.{}", show(x), n.text),
            ExprKind::Index(x, i) => format!("{}[{}]", show(x), show(i)),
            ExprKind::Int(n) => n.to_string(),
            ExprKind::Unary(UnOp::Not, x) => format!("!{}", show(x)),
            ExprKind::Unary(UnOp::Neg, x) => format!("-{}", show(x)),
            ExprKind::Cast(x, ty) => format!("({} as {})", show(x), ty.text),
            ExprKind::Binary(op, operands) => {
                let [l, r] = &**operands;
                format!("({} {} {})", show(l), op.symbol(), show(r))
            }
            ExprKind::Paren(x) => show(x),
            other => format!("{other:?}"),
        }
    }

    /// Prefixes, casts and operators arrive from pest as one flat list
    /// (grammar.pest: `operand` is silent and casts share the operator
    /// loop); the builder must still bind casts tightest, then prefixes,
    /// then operators by precedence.
    #[test]
    fn prefixes_casts_and_operators_group_as_documented() {
        assert_eq!(condition("-x as u8 > 1"), "(-(x as u8) > 1)");
        assert_eq!(condition("!!a && - -b"), "(!!a && --b)");
        assert_eq!(
            condition("a as u8 as u16 + -b as u16 == c"),
            "((((a as u8) as u16) + -(b as u16)) == c)"
        );
        assert_eq!(
            condition("a + b * c as i64 - d"),
            "((a + (b * (c as i64))) - d)"
        );
        assert_eq!(condition("!(a || b) && c"), "(!(a || b) && c)");
        assert_eq!(condition("x - -y < 3 || z"), "(((x - -y) < 3) || z)");
        // A name's arguments and `::VARIANT` belong to it; fields and
        // indexes follow (`name_expr` and `field_access` are silent).
        assert_eq!(
            condition("f(a, b.c).d[i] as u8 > -g().h && m == Mode::Run"),
            "(((f(a, b.c).d[i] as u8) > -g().h) && (m == Mode::Run))"
        );
        assert_eq!(condition("cmd.n + x.status.y"), "(cmd.n + x.status.y)");
    }
}
