//! Semantic tokens: every name the index resolved ([`super::symbols`]),
//! coloured by what it is (a verb, a hook, a state, a field …), with
//! `declaration` on the name where it is declared and `readonly` on
//! constants. Keywords, numbers and comments are the grammar's business
//! (editors/): these tokens add what only resolution knows.

use lsp_types::{
    SemanticToken, SemanticTokenModifier, SemanticTokenType, SemanticTokens, SemanticTokensLegend,
};
use rcs_dsl::source::FileId;

use super::documents::Analysis;
use super::position::LineIndex;
use super::symbols::Kind;

/// The token types, in the order the legend announces them.
const TYPES: [SemanticTokenType; 11] = [
    SemanticTokenType::NAMESPACE,
    SemanticTokenType::CLASS,
    SemanticTokenType::STRUCT,
    SemanticTokenType::PROPERTY,
    SemanticTokenType::ENUM,
    SemanticTokenType::ENUM_MEMBER,
    SemanticTokenType::VARIABLE,
    SemanticTokenType::METHOD,
    SemanticTokenType::PARAMETER,
    SemanticTokenType::FUNCTION,
    SemanticTokenType::MACRO,
];

const MODIFIERS: [SemanticTokenModifier; 2] = [
    SemanticTokenModifier::DECLARATION,
    SemanticTokenModifier::READONLY,
];

pub fn legend() -> SemanticTokensLegend {
    SemanticTokensLegend {
        token_types: TYPES.to_vec(),
        token_modifiers: MODIFIERS.to_vec(),
    }
}

/// The legend index of a kind's token type, and whether it is read-only.
fn token_type(kind: Kind) -> (SemanticTokenType, bool) {
    match kind {
        Kind::Controller | Kind::SubordinateSlot => (SemanticTokenType::NAMESPACE, false),
        Kind::ControllerType => (SemanticTokenType::CLASS, false),
        Kind::BufferType => (SemanticTokenType::STRUCT, false),
        Kind::Field | Kind::StatusField => (SemanticTokenType::PROPERTY, false),
        Kind::Enum => (SemanticTokenType::ENUM, false),
        Kind::Variant | Kind::Status | Kind::ErrorCode | Kind::State => {
            (SemanticTokenType::ENUM_MEMBER, false)
        }
        Kind::Var | Kind::Buffer => (SemanticTokenType::VARIABLE, false),
        Kind::Const => (SemanticTokenType::VARIABLE, true),
        Kind::Verb => (SemanticTokenType::METHOD, false),
        Kind::Param => (SemanticTokenType::PARAMETER, false),
        Kind::TypeParam => (SemanticTokenType::PARAMETER, true),
        Kind::Hook => (SemanticTokenType::FUNCTION, false),
        Kind::JobList | Kind::RowBlock => (SemanticTokenType::MACRO, false),
    }
}

/// The tokens of `file`, encoded relative to each other as LSP wants.
pub fn tokens(a: &Analysis, file: FileId) -> SemanticTokens {
    let text = a.text(file);
    let lines = LineIndex::new(text);
    let mut data = Vec::new();
    let (mut line, mut col) = (0, 0);
    let mut last_end = 0;
    for (span, symbol) in a.symbols().in_file(file) {
        let (start, end) = (span.start as usize, span.end as usize);
        // One token per place: a state named by a block placed in two
        // plans is one use in each; tokens may not overlap.
        if start < last_end || end > text.len() || start >= end {
            continue;
        }
        last_end = end;
        let from = lines.position(start);
        let to = lines.position(end);
        if to.line != from.line {
            continue;
        }
        let (ty, readonly) = token_type(symbol.kind);
        let Some(type_ix) = TYPES.iter().position(|t| *t == ty) else {
            continue;
        };
        let mut modifiers = 0;
        if symbol.def == span {
            modifiers |= 1;
        }
        if readonly {
            modifiers |= 2;
        }
        let delta_line = from.line - line;
        let delta_start = if delta_line == 0 {
            from.character - col
        } else {
            from.character
        };
        data.push(SemanticToken {
            delta_line,
            delta_start,
            length: to.character - from.character,
            token_type: u32::try_from(type_ix).unwrap_or(0),
            token_modifiers_bitset: modifiers,
        });
        (line, col) = (from.line, from.character);
    }
    SemanticTokens {
        result_id: None,
        data,
    }
}
