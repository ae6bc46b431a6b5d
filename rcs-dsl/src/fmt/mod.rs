//! `rcsc fmt`: the one canonical layout of `.rcs` files, on a lossless
//! syntax tree.
//!
//! ```text
//! text ──syntax::parse──▶ Cst (every byte) ──layout──▶ text ──check──▶ same tree?
//! ```
//!
//! The parser (pest, [`crate::parser`]) stays the source of truth: the
//! tree ([`syntax`]) has the nesting pest gives the file, with the
//! whitespace, comments and punctuation pest skips kept as tokens. The
//! layout ([`layout`], [`rows`]) changes only whitespace, the optional
//! separators (`;` between jobs, a trailing `,`) and line breaks; before
//! returning, [`format`] parses its result and compares the two trees
//! token by token, so a layout bug is an error, never a changed plan.
//!
//! Entries of a controller keep their order: LANGUAGE.md §2 says the
//! order is free, and plan sets group entries by meaning with comments
//! between the groups, which reordering would tear apart.
//!
//! The language server reuses [`format`] for formatting requests and the
//! tree of [`syntax::parse`] for positions and tokens.
//!
//! Beside the layout, [`renumber`] (`rcsc fmt --renumber`) rewrites row
//! labels to positions in a whole plan set and its scenarios, changing
//! only digits; [`meaning`] is the IR without places that it and the
//! formatter's tests compare.

pub mod config;
mod layout;
mod lexer;
pub mod meaning;
mod out;
pub mod renumber;
mod rows;
pub mod syntax;

pub use config::FmtOptions;
pub use renumber::{renumber, ChangedFile, Relabel, RenumberError, Renumbered, Undecided};
pub use syntax::{parse, Cst, RcsLanguage, SyntaxElement, SyntaxKind, SyntaxNode, SyntaxToken};

use crate::diagnostic::Diagnostic;

/// Why a file was not formatted.
#[derive(Debug)]
pub enum FmtError {
    /// The file does not parse: its `syntax` diagnostics (file id 0).
    Syntax(Vec<Diagnostic>),
    /// The layout would have changed the file's syntax tree: a bug of the
    /// formatter, reported instead of writing a changed plan.
    Changed(String),
}

impl std::fmt::Display for FmtError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FmtError::Syntax(diags) => {
                write!(f, "the file does not parse ({} errors)", diags.len())
            }
            FmtError::Changed(why) => write!(
                f,
                "the formatter would change the file's meaning ({why}); the file is left as it is \
                 (please report this as a bug)"
            ),
        }
    }
}

impl std::error::Error for FmtError {}

/// `source` in the canonical layout. `Err` when it does not parse, or
/// (a bug) when the laid-out text would not parse to the same tree.
pub fn format(source: &str, options: &FmtOptions) -> Result<String, FmtError> {
    crate::parser::parse_file(crate::source::FileId(0), source).map_err(FmtError::Syntax)?;
    let cst = syntax::parse(source);
    if !cst.parsed {
        return Err(FmtError::Changed(
            "pest rejected a file the parser accepted".into(),
        ));
    }
    let layout = layout::Layout {
        src: source,
        max_width: options.max_width,
    };
    let mut out = out::Out::new(0);
    layout.file(&cst.root(), &mut out);
    let formatted = out.text;
    let again = syntax::parse(&formatted);
    if !again.parsed {
        let why = match crate::parser::parse_file(crate::source::FileId(0), &formatted) {
            Err(diags) => diags.first().map(|d| d.message.clone()).unwrap_or_default(),
            Ok(_) => String::new(),
        };
        return Err(FmtError::Changed(format!(
            "the result does not parse: {why}"
        )));
    }
    let (before, after) = (signature(&cst.root()), signature(&again.root()));
    if before != after {
        let at = before
            .iter()
            .zip(&after)
            .position(|(a, b)| a != b)
            .unwrap_or(before.len().min(after.len()));
        return Err(FmtError::Changed(format!(
            "the tree differs at {:?} (was {:?})",
            after.get(at),
            before.get(at)
        )));
    }
    Ok(formatted)
}

/// The tree as the parser sees it: nodes and tokens of the language,
/// without trivia and the separators the layout may add or drop.
fn signature(root: &SyntaxNode) -> Vec<String> {
    let mut sig = Vec::new();
    for event in root.preorder_with_tokens() {
        match event {
            rowan::WalkEvent::Enter(rowan::NodeOrToken::Node(n)) => {
                sig.push(format!("({:?}", n.kind()))
            }
            rowan::WalkEvent::Leave(rowan::NodeOrToken::Node(_)) => sig.push(")".into()),
            rowan::WalkEvent::Enter(rowan::NodeOrToken::Token(t)) => {
                if t.kind().is_trivia() || is_optional_separator(&t) {
                    continue;
                }
                if t.kind() == SyntaxKind::DocComment {
                    sig.push(t.text().trim_end().to_string());
                } else {
                    sig.push(t.text().to_string());
                }
            }
            rowan::WalkEvent::Leave(rowan::NodeOrToken::Token(_)) => {}
        }
    }
    sig
}

/// A `;` between jobs, or a `,` right before a closing bracket.
fn is_optional_separator(t: &SyntaxToken) -> bool {
    if t.kind() != SyntaxKind::Punct {
        return false;
    }
    match t.text() {
        ";" => t.parent().is_some_and(|p| p.kind() == SyntaxKind::Jobs),
        "," => {
            let mut next = t.next_token();
            while let Some(n) = next.as_ref().filter(|n| n.kind().is_trivia()) {
                next = n.next_token();
            }
            next.is_some_and(|n| matches!(n.text(), "}" | ")" | "]"))
        }
        _ => false,
    }
}

#[cfg(test)]
mod tests;
