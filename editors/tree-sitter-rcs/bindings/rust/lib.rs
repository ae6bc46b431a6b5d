//! The tree-sitter grammar of the RCS plan language (`.rcs`), for editors
//! (Neovim, Helix, Zed) and any Rust tool that wants a concrete syntax
//! tree with error recovery. It sits beside rcsc, not inside it: the
//! compiler parses with pest (`rcs-dsl/src/grammar.pest`, the source of
//! truth); this grammar follows it, and `tests/corpus.rs` holds it to every
//! `.rcs` file in the repository that the compiler parses.
//!
//! ```
//! let mut parser = tree_sitter::Parser::new();
//! parser
//!     .set_language(&tree_sitter_rcs::LANGUAGE.into())
//!     .expect("the grammar's ABI is one the library reads");
//! let tree = parser.parse("enum Dir { Ahead, Stopped }", None).unwrap();
//! assert!(!tree.root_node().has_error());
//! ```

use tree_sitter_language::LanguageFn;

extern "C" {
    fn tree_sitter_rcs() -> *const ();
}

/// The grammar, for `tree_sitter::Parser::set_language(&LANGUAGE.into())`.
// SAFETY: `tree_sitter_rcs` is the generated parser's entry point
// (src/parser.c, compiled by build.rs): it takes nothing and returns a
// pointer to a static `TSLanguage`. This is the one way a C parser reaches
// Rust; every tree-sitter grammar crate does the same.
pub const LANGUAGE: LanguageFn = unsafe { LanguageFn::from_raw(tree_sitter_rcs) };

/// The node types (`src/node-types.json`), as tree-sitter generated them.
pub const NODE_TYPES: &str = include_str!("../../src/node-types.json");

/// The highlight queries (`queries/highlights.scm`).
pub const HIGHLIGHTS_QUERY: &str = include_str!("../../queries/highlights.scm");
