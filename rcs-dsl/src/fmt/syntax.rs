//! The lossless syntax tree (CST) of a `.rcs` file: a rowan tree that
//! keeps every byte — whitespace, comments and punctuation included — so
//! that its text is the file's text. The formatter lays it out; the
//! language server can walk it for positions and tokens.
//!
//! The nesting comes from pest's parse tree ([`crate::parser::pest_tree`]),
//! never from a second grammar: the tree has exactly the structure the
//! parser gives the file. Each pest rule that matches a single token
//! (a name, a number, a keyword, an operator) becomes a token; every other
//! rule a node. The text pest matched silently between rules (whitespace,
//! comments, literal punctuation such as `{` or `,`) is split by
//! [`super::lexer`] into tokens of the innermost node around it. Trivia at
//! the start or end of a node is moved out to its parent, so that every
//! node but the root starts and ends with a token of the language.
//!
//! A file that does not parse still gets a tree, flat (one `Unparsed` root
//! over the lexed tokens), so the round trip holds for any text.

use crate::parser::{pest_tree, Rule};
use rowan::{GreenNode, GreenNodeBuilder};

macro_rules! kinds {
    ($($rule:ident => $kind:ident),* $(,)?) => {
        /// What a node or token of the tree is: the trivia and punctuation
        /// kinds, then one kind per (non-silent) rule of `grammar.pest`.
        #[allow(non_camel_case_types)]
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        #[repr(u16)]
        pub enum SyntaxKind {
            /// Spaces, tabs and line breaks.
            Whitespace,
            /// `// …` (not `///`), up to the end of its line.
            LineComment,
            /// `/* … */`.
            BlockComment,
            /// Punctuation the grammar writes literally (`{`, `,`, `:`, `->`
            /// of a hook, `::`, `#`, …), or any other character pest skipped.
            Punct,
            /// The root of a file that does not parse: its tokens, flat.
            Unparsed,
            $($kind,)*
        }

        fn kind_of_rule(rule: Rule) -> Option<SyntaxKind> {
            match rule {
                $(Rule::$rule => Some(SyntaxKind::$kind),)*
                _ => None,
            }
        }

        /// Every kind, indexed by its number (rowan stores kinds as `u16`).
        const ALL_KINDS: &[SyntaxKind] = &[
            SyntaxKind::Whitespace,
            SyntaxKind::LineComment,
            SyntaxKind::BlockComment,
            SyntaxKind::Punct,
            SyntaxKind::Unparsed,
            $(SyntaxKind::$kind,)*
        ];
    };
}

kinds! {
    file => File,
    ident => Ident,
    number => Number,
    int_lit => IntLit,
    string_lit => StringLit,
    kw_enum => KwEnum,
    kw_buffer => KwBuffer,
    kw_controller => KwController,
    kw_level => KwLevel,
    kw_subordinates => KwSubordinates,
    kw_reads => KwReads,
    kw_writes => KwWrites,
    kw_command => KwCommand,
    kw_status => KwStatus,
    kw_error => KwError,
    kw_var => KwVar,
    kw_hook => KwHook,
    kw_plan => KwPlan,
    kw_when => KwWhen,
    kw_accept => KwAccept,
    kw_otherwise => KwOtherwise,
    kw_report => KwReport,
    kw_same => KwSame,
    kw_as => KwAs,
    kw_const => KwConst,
    kw_pre => KwPre,
    kw_post => KwPost,
    kw_type => KwType,
    kw_rows => KwRows,
    kw_jobs => KwJobs,
    kw_use => KwUse,
    kw_except => KwExcept,
    item => Item,
    const_def => ConstDef,
    attribute => Attribute,
    lint_level => LintLevel,
    doc_comment => DocComment,
    enum_def => EnumDef,
    variant => Variant,
    buffer_def => BufferDef,
    field => Field,
    type_expr => TypeExpr,
    array_type => ArrayType,
    controller_def => ControllerDef,
    controller_type_def => ControllerTypeDef,
    instance_def => InstanceDef,
    binding => Binding,
    entry => Entry,
    rows_def => RowsDef,
    jobs_def => JobsDef,
    level_decl => LevelDecl,
    subordinates_decl => SubordinatesDecl,
    reads_decl => ReadsDecl,
    writes_decl => WritesDecl,
    command_decl => CommandDecl,
    accept_clause => AcceptClause,
    param => Param,
    status_decl => StatusDecl,
    status_field_decl => StatusFieldDecl,
    every_cycle_decl => EveryCycleDecl,
    error_decl => ErrorDecl,
    var_decl => VarDecl,
    hook_decl => HookDecl,
    plan_def => PlanDef,
    use_rows => UseRows,
    row => Row,
    row_label => RowLabel,
    arrow => Arrow,
    from_state => FromState,
    except_states => ExceptStates,
    dont_care => DontCare,
    target => Target,
    error_target => ErrorTarget,
    error_word => ErrorWord,
    jobs => Jobs,
    job => Job,
    send_arrow => SendArrow,
    named_arg => NamedArg,
    report_job => ReportJob,
    expr_job => ExprJob,
    assign_op => AssignOp,
    expr => Expr,
    postfix_expr => PostfixExpr,
    index => Index,
    path_tail => PathTail,
    call_args => CallArgs,
    paren => Paren,
    infix => Infix,
    op_unary => OpUnary,
}

impl SyntaxKind {
    /// Whitespace and comments (not doc comments: those are part of the
    /// language, attached to what follows).
    pub fn is_trivia(self) -> bool {
        matches!(
            self,
            SyntaxKind::Whitespace | SyntaxKind::LineComment | SyntaxKind::BlockComment
        )
    }

    /// Whether pest matches this rule as one token (an atomic rule with no
    /// parts of its own): it becomes a token of the tree, not a node.
    fn is_token_rule(self) -> bool {
        use SyntaxKind::*;
        matches!(
            self,
            Ident
                | Number
                | IntLit
                | StringLit
                | KwEnum
                | KwBuffer
                | KwController
                | KwLevel
                | KwSubordinates
                | KwReads
                | KwWrites
                | KwCommand
                | KwStatus
                | KwError
                | KwVar
                | KwHook
                | KwPlan
                | KwWhen
                | KwAccept
                | KwOtherwise
                | KwReport
                | KwSame
                | KwAs
                | KwConst
                | KwPre
                | KwPost
                | KwType
                | KwRows
                | KwJobs
                | KwUse
                | KwExcept
                | LintLevel
                | DocComment
                | RowLabel
                | Arrow
                | DontCare
                | ErrorWord
                | SendArrow
                | AssignOp
                | Infix
                | OpUnary
        )
    }
}

impl From<SyntaxKind> for rowan::SyntaxKind {
    fn from(kind: SyntaxKind) -> Self {
        rowan::SyntaxKind(kind as u16)
    }
}

/// The rowan language of `.rcs` files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum RcsLanguage {}

impl rowan::Language for RcsLanguage {
    type Kind = SyntaxKind;

    fn kind_from_raw(raw: rowan::SyntaxKind) -> SyntaxKind {
        // Only kinds made by `kind_to_raw` are ever stored.
        ALL_KINDS
            .get(usize::from(raw.0))
            .copied()
            .unwrap_or(SyntaxKind::Punct)
    }

    fn kind_to_raw(kind: SyntaxKind) -> rowan::SyntaxKind {
        kind.into()
    }
}

pub type SyntaxNode = rowan::SyntaxNode<RcsLanguage>;
pub type SyntaxToken = rowan::SyntaxToken<RcsLanguage>;
pub type SyntaxElement = rowan::SyntaxElement<RcsLanguage>;

/// A file's lossless tree.
#[derive(Clone, Debug)]
pub struct Cst {
    green: GreenNode,
    /// Whether pest parsed the file (the tree has its structure); when
    /// not, the root is one `Unparsed` node over the lexed tokens.
    pub parsed: bool,
}

impl Cst {
    pub fn root(&self) -> SyntaxNode {
        SyntaxNode::new_root(self.green.clone())
    }
}

/// One step of building the tree, before trivia is moved out of nodes.
enum Event {
    Start(SyntaxKind),
    Token(SyntaxKind, usize, usize),
    Finish,
}

/// The lossless tree of `text`. Never fails: a text pest rejects (or that
/// [`crate::parser::parse_file`] rejects for its size or nesting) gets a
/// flat tree.
pub fn parse(text: &str) -> Cst {
    let pair = crate::parser::parse_file(crate::source::FileId(0), text)
        .ok()
        .and_then(|_| pest_tree(text));
    let mut events = Vec::new();
    let parsed = match pair {
        Some(pair) => {
            let mut pos = 0;
            events.push(Event::Start(SyntaxKind::File));
            for child in pair.into_inner() {
                add_pair(child, text, &mut pos, &mut events);
            }
            gap(text, pos, text.len(), &mut events);
            events.push(Event::Finish);
            true
        }
        None => {
            events.push(Event::Start(SyntaxKind::Unparsed));
            gap(text, 0, text.len(), &mut events);
            events.push(Event::Finish);
            false
        }
    };
    let events = hoist_trivia(events);
    let mut builder = GreenNodeBuilder::new();
    for event in events {
        match event {
            Event::Start(kind) => builder.start_node(kind.into()),
            Event::Token(kind, start, end) => builder.token(kind.into(), &text[start..end]),
            Event::Finish => builder.finish_node(),
        }
    }
    Cst {
        green: builder.finish(),
        parsed,
    }
}

/// The events of one pest pair, after the gap from `pos` to its start.
fn add_pair(
    pair: pest::iterators::Pair<'_, Rule>,
    text: &str,
    pos: &mut usize,
    out: &mut Vec<Event>,
) {
    let span = pair.as_span();
    let (start, end) = (span.start(), span.end());
    let Some(kind) = kind_of_rule(pair.as_rule()) else {
        // EOI and other rules of no text: their text, if any, stays a gap.
        return;
    };
    if start == end {
        return;
    }
    gap(text, *pos, start, out);
    if kind.is_token_rule() {
        out.push(Event::Token(kind, start, end));
    } else {
        out.push(Event::Start(kind));
        let mut inner = start;
        for child in pair.into_inner() {
            add_pair(child, text, &mut inner, out);
        }
        gap(text, inner, end, out);
        out.push(Event::Finish);
    }
    *pos = end;
}

/// The tokens of text pest matched between rules.
fn gap(text: &str, start: usize, end: usize, out: &mut Vec<Event>) {
    if start < end {
        for (kind, s, e) in super::lexer::lex(&text[start..end]) {
            out.push(Event::Token(kind, start + s, start + e));
        }
    }
}

/// Move trivia at the start or end of a node out to its parent (pest
/// counts the whitespace it skipped before a missing optional part into
/// the rule), leaving the root's own.
fn hoist_trivia(mut events: Vec<Event>) -> Vec<Event> {
    let is_trivia = |e: &Event| matches!(e, Event::Token(k, ..) if k.is_trivia());
    // A `Finish` moves left past trivia; a `Start` right past trivia.
    let last = events.len().saturating_sub(1);
    let mut changed = true;
    while changed {
        changed = false;
        for i in 1..events.len() {
            if i < last && matches!(events[i], Event::Finish) && is_trivia(&events[i - 1]) {
                events.swap(i - 1, i);
                changed = true;
            }
        }
        for i in (1..events.len()).rev() {
            if i - 1 > 0 && matches!(events[i - 1], Event::Start(_)) && is_trivia(&events[i]) {
                events.swap(i - 1, i);
                changed = true;
            }
        }
    }
    events
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tree_keeps_every_byte() {
        for text in [
            "",
            "controller A { command GO plan GO { *0 when new_command -> Done } }\n",
            "// c\n/// d\ncontroller A {\n  command GO // x\n plan GO {\n E0: *0 when new_command -> Done { }\n }\n}\n  ",
            "controller {{{ ) ] /* unterminated",
            "\u{FEFF}enum E { A, B, }",
            "é ✓ \u{0} \r\n\r",
        ] {
            let cst = parse(text);
            assert_eq!(cst.root().to_string(), text);
        }
    }

    #[test]
    fn nodes_start_and_end_with_tokens_of_the_language() {
        let text = "controller A {\n    command GO   // why\n    plan GO {\n        *0 when new_command -> Done   \n    }\n}\n";
        let cst = parse(text);
        assert!(cst.parsed);
        for node in cst.root().descendants().skip(1) {
            let first = node.first_token().unwrap();
            let last = node.last_token().unwrap();
            assert!(!first.kind().is_trivia(), "{node:?} starts with {first:?}");
            assert!(!last.kind().is_trivia(), "{node:?} ends with {last:?}");
        }
    }
}
