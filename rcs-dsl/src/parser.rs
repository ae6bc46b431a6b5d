//! Stage 1 of the pipeline: text → [`ast::File`]. pest does the matching;
//! this module turns its pairs into the AST and its failures into `syntax`
//! diagnostics phrased in the user's words.
//!
//! Hostile input is bounded here: a size limit, a bracket-nesting limit
//! checked before pest runs (so no input can exhaust the stack), and an
//! expression-depth limit while folding operator chains.

use crate::ast::*;
use crate::diagnostic::{Code, Diagnostic};
use crate::lint::{Level, Lint};
use crate::source::{FileId, Span};
use pest::iterators::Pair;
use pest::Parser as _;

#[derive(pest_derive::Parser)]
#[grammar = "grammar.pest"]
struct RcsParser;

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
                while i < bytes.len() && bytes[i] != b'\n' {
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
                while i < bytes.len() && bytes[i] != b'"' && bytes[i] != b'\n' {
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

/// Turn a pest failure into one diagnostic: where, what was expected, what was found.
fn syntax_error(file: FileId, text: &str, e: pest::error::Error<Rule>) -> Diagnostic {
    use pest::error::{ErrorVariant, InputLocation};
    let mut pos = match e.location {
        InputLocation::Pos(p) => p,
        InputLocation::Span((s, _)) => s,
    };
    let mut expected: Vec<String> = Vec::new();
    let mut add = |s: String| {
        if !expected.contains(&s) {
            expected.push(s);
        }
    };
    match &e.variant {
        ErrorVariant::ParsingError { positives, .. } => {
            for r in positives {
                if let Some(w) = rule_words(*r) {
                    add(w.to_string());
                }
            }
        }
        ErrorVariant::CustomError { message } => {
            // pest's own limits ("call limit reached", "stack limit reached").
            return Diagnostic::error(
                Code::Syntax,
                format!("input too complex to parse: {message}"),
                Span::new(file, pos, pos),
                "parsing stopped here",
            );
        }
    }
    if let Some(attempts) = e.parse_attempts() {
        // The token type is not exported; its Display is the literal text.
        let tokens: Vec<String> = attempts
            .expected_tokens()
            .iter()
            .filter_map(|t| token_words(&t.to_string()))
            .collect();
        if attempts.max_position > pos && !tokens.is_empty() {
            // Punctuation was tried further on (`Error(CODE` missing its `)`):
            // that is where the text went wrong, and the rules that failed
            // earlier only describe what an optional part could have been.
            // Point just after the last token, not at the next line.
            let before = &text[..attempts.max_position.min(text.len())];
            pos = pos.max(before.trim_end().len());
            expected.clear();
        }
        for w in tokens {
            if !expected.contains(&w) {
                expected.push(w);
            }
        }
    }
    // `(` and `[` can start an expression; saying both is noise.
    if expected.iter().any(|w| w == "an expression") {
        expected.retain(|w| w != "`(`" && w != "`[`");
    }
    // `#` starts an attribute, which is part of an item or entry.
    if expected
        .iter()
        .any(|w| w.starts_with("an item") || w.starts_with("a controller entry"))
    {
        expected.retain(|w| w != "`#`" && w != "an attribute `#[…]`");
    }
    // After an operand, `as`, `.` and `[` continue it like an operator does.
    if expected.iter().any(|w| w == "an operator") {
        expected.retain(|w| w != "`as`" && w != "`.`" && w != "`[`" && w != "an operator");
        expected.push("an operator".to_string());
    }
    // "end of file" reads best last.
    if let Some(i) = expected.iter().position(|w| w == "end of file") {
        let eof = expected.remove(i);
        expected.push(eof);
    }
    let found = describe_found(text, pos);
    let end = found_end(text, pos);
    let message = if expected.is_empty() {
        format!("unexpected {found}")
    } else {
        format!("expected {}, found {found}", one_of(&expected))
    };
    // `h ()`, `ship .speed`, `a [0]`: postfix parts must touch their name.
    let before = text[..pos.min(text.len())].trim_end_matches([' ', '\t']);
    let spaced_postfix = before.len() < pos
        && matches!(text[pos..].chars().next(), Some('(' | '[' | '.' | ':'))
        && before
            .ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_' || c == ')' || c == ']');
    let diagnostic = Diagnostic::error(
        Code::Syntax,
        message,
        Span::new(file, pos, end),
        if expected.is_empty() {
            "unexpected here".to_string()
        } else {
            format!("expected {}", one_of(&expected))
        },
    );
    if spaced_postfix {
        diagnostic.with_help("write calls, fields, indices and `Enum::Variant` without spaces: `h()`, `ship.speed`, `a[0]`")
    } else {
        diagnostic
    }
}

fn one_of(words: &[String]) -> String {
    match words {
        [] => String::new(),
        [a] => a.clone(),
        [a, b] => format!("{a} or {b}"),
        [rest @ .., last] => format!("{}, or {last}", rest.join(", ")),
    }
}

/// What a named rule means to a user, or `None` for rules that never help.
fn rule_words(rule: Rule) -> Option<&'static str> {
    Some(match rule {
        Rule::EOI => "end of file",
        Rule::item => "an item (`enum`, `buffer` or `controller`)",
        Rule::doc_comment => return None,
        Rule::attribute => "an attribute `#[…]`",
        Rule::ident => "a name",
        Rule::int_lit => "an integer",
        Rule::number => "a number",
        Rule::string_lit => "a title string",
        Rule::type_expr | Rule::array_type => "a type",
        Rule::variant => "a variant name",
        Rule::field => "a field",
        Rule::entry => "a controller entry (`command`, `plan`, `reads`, …)",
        Rule::param | Rule::named_arg => "a parameter",
        Rule::row => "a row",
        Rule::row_label => "a row label `EN`",
        Rule::from_state => "a state or `*`",
        Rule::dont_care => "`*`",
        Rule::target => "a target (a state, `same`, `Done` or `Error(…)`)",
        Rule::error_target | Rule::error_word => "`Error`",
        Rule::jobs => "a job list `{ … }`",
        Rule::job | Rule::report_job | Rule::expr_job => "a job",
        Rule::assign_op => "`=`, `+=` or `-=`",
        Rule::send_arrow => "`<-`",
        Rule::arrow => "`->`",
        Rule::expr | Rule::operand | Rule::postfix_expr | Rule::paren | Rule::name_expr => {
            "an expression"
        }
        Rule::call_args => "`(`",
        Rule::infix => "an operator",
        Rule::op_unary => "an expression",
        Rule::field_access => "`.`",
        Rule::index => "`[`",
        Rule::lint_level => "`allow`, `warn` or `deny`",
        Rule::kw_when => "`when`",
        Rule::kw_otherwise => "`otherwise`",
        Rule::kw_as => "`as`",
        Rule::kw_same => "`same`",
        Rule::kw_report => "`report`",
        _ => return None,
    })
}

/// Literal tokens pest tried at the failure point, as the user writes them.
fn token_words(token: &str) -> Option<String> {
    match token {
        "{" | "}" | "(" | ")" | "[" | "]" | ":" | ";" | "," | "->" | "=" | "::" | "." | "#" => {
            Some(format!("`{token}`"))
        }
        _ => None,
    }
}

fn describe_found(text: &str, pos: usize) -> String {
    let rest = &text[pos.min(text.len())..];
    match rest.chars().next() {
        None => "end of file".to_string(),
        Some(c) if c.is_ascii_alphanumeric() || c == '_' => {
            let word: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .take(40)
                .collect();
            format!("`{word}`")
        }
        Some('\n') | Some('\r') => "end of line".to_string(),
        Some(c) if c.is_control() => format!("character U+{:04X}", c as u32),
        Some(c) => format!("`{c}`"),
    }
}

fn found_end(text: &str, pos: usize) -> usize {
    let rest = &text[pos.min(text.len())..];
    match rest.chars().next() {
        None | Some('\n') | Some('\r') => pos,
        Some(c) if c.is_ascii_alphanumeric() || c == '_' => {
            pos + rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .count()
        }
        Some(c) => pos + c.len_utf8(),
    }
}

/// Builds AST nodes from pairs, collecting the few syntax errors the grammar
/// leaves to it (attributes in the wrong place, limits, bad numbers).
struct Builder {
    file: FileId,
    diags: Vec<Diagnostic>,
}

impl Builder {
    fn span(&self, p: &Pair<Rule>) -> Span {
        let s = p.as_span();
        // A rule that ends in a repetition keeps the whitespace pest skipped
        // before trying it once more; a label should end at the last token.
        let trailing = s.as_str().len() - s.as_str().trim_end().len();
        Span::new(self.file, s.start(), s.end() - trailing)
    }

    /// A user-chosen name; reserved words are refused here (see grammar.pest).
    fn name(&mut self, p: Pair<Rule>) -> Name {
        let name = Name {
            text: p.as_str().into(),
            span: self.span(&p),
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

    fn error(&mut self, span: Span, message: impl Into<String>, label: impl Into<String>) {
        self.diags
            .push(Diagnostic::error(Code::Syntax, message, span, label));
    }

    fn int(&mut self, p: Pair<Rule>) -> u64 {
        let span = self.span(&p);
        match p.as_str().replace('_', "").parse::<u64>() {
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

    fn doc(p: &Pair<Rule>) -> String {
        let s = p.as_str().trim_start_matches("///");
        s.strip_prefix(' ').unwrap_or(s).trim_end().to_string()
    }

    fn outer(&mut self, pairs: &mut Vec<Pair<Rule>>) -> Outer {
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
                                )),
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
    fn split_outer<'i>(&mut self, p: Pair<'i, Rule>) -> (Outer, Vec<Pair<'i, Rule>>) {
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

    fn no_attributes(&mut self, outer: &Outer, what: &str) {
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

    fn item(&mut self, p: Pair<Rule>) -> Option<Item> {
        let (outer, mut rest) = self.split_outer(p);
        let def = rest.pop()?;
        let span = self.span(&def);
        match def.as_rule() {
            Rule::enum_def => self.no_attributes(&outer, "an enum"),
            Rule::buffer_def => self.no_attributes(&outer, "a buffer"),
            _ => {}
        }
        let mut inner = def.clone().into_inner();
        Some(match def.as_rule() {
            Rule::enum_def => {
                inner.next(); // kw
                let name = self.name(inner.next()?);
                let variants = inner
                    .map(|v| {
                        let mut docs = Vec::new();
                        let mut name = None;
                        for c in v.into_inner() {
                            match c.as_rule() {
                                Rule::doc_comment => docs.push(Self::doc(&c)),
                                _ => name = Some(self.name(c)),
                            }
                        }
                        (docs, name.expect("variant has a name"))
                    })
                    .collect();
                Item::Enum(EnumDef {
                    outer,
                    name,
                    variants,
                    span,
                })
            }
            Rule::buffer_def => {
                inner.next();
                let name = self.name(inner.next()?);
                let fields = inner.map(|f| self.field(f)).collect();
                Item::Buffer(BufferDef {
                    outer,
                    name,
                    fields,
                    span,
                })
            }
            Rule::controller_def => {
                inner.next();
                let name = self.name(inner.next()?);
                let mut title = None;
                let mut entries = Vec::new();
                for c in inner {
                    match c.as_rule() {
                        Rule::string_lit => {
                            let s = c.as_str();
                            title = Some(unescape(&s[1..s.len() - 1]));
                        }
                        Rule::entry => {
                            if let Some(e) = self.entry(c) {
                                entries.push(e);
                            }
                        }
                        _ => {}
                    }
                }
                Item::Controller(ControllerDef {
                    outer,
                    name,
                    title,
                    entries,
                    span,
                })
            }
            _ => return None,
        })
    }

    fn field(&mut self, p: Pair<Rule>) -> Field {
        let mut docs = Vec::new();
        let mut name = None;
        let mut ty = None;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::doc_comment => docs.push(Self::doc(&c)),
                Rule::ident => name = Some(self.name(c)),
                Rule::type_expr => ty = Some(self.type_expr(c)),
                _ => {}
            }
        }
        Field {
            docs,
            name: name.expect("field has a name"),
            ty: ty.expect("field has a type"),
        }
    }

    fn type_expr(&mut self, p: Pair<Rule>) -> TypeExpr {
        let c = p.into_inner().next().expect("type_expr has one child");
        match c.as_rule() {
            Rule::array_type => {
                let span = self.span(&c);
                let mut inner = c.into_inner();
                let elem = self.type_expr(inner.next().expect("element type"));
                let len = self.int(inner.next().expect("array length"));
                TypeExpr::Array {
                    elem: Box::new(elem),
                    len,
                    span,
                }
            }
            _ => TypeExpr::Named(self.name(c)),
        }
    }

    fn params<'i>(&mut self, pairs: impl Iterator<Item = Pair<'i, Rule>>) -> Vec<Param> {
        pairs
            .filter(|p| p.as_rule() == Rule::param)
            .map(|p| {
                // A parameter is written like a buffer field: docs, name, type.
                let Field { docs, name, ty } = self.field(p);
                Param { docs, name, ty }
            })
            .collect()
    }

    fn entry(&mut self, p: Pair<Rule>) -> Option<Entry> {
        let span = self.span(&p);
        let (outer, mut rest) = self.split_outer(p);
        let decl = rest.pop()?;
        let rule = decl.as_rule();
        if rule != Rule::plan_def {
            self.no_attributes(&outer, "this entry");
        }
        let mut inner = decl.clone().into_inner();
        inner.next(); // the keyword
        let kind = match rule {
            Rule::level_decl => {
                let n = inner.next()?;
                let s = self.span(&n);
                EntryKind::Level(self.int(n), s)
            }
            Rule::subordinates_decl => {
                EntryKind::Subordinates(inner.map(|n| self.name(n)).collect())
            }
            Rule::reads_decl | Rule::writes_decl => {
                let name = self.name(inner.next()?);
                let ty = self.name(inner.next()?);
                if rule == Rule::reads_decl {
                    EntryKind::Reads(name, ty)
                } else {
                    EntryKind::Writes(name, ty)
                }
            }
            Rule::command_decl => {
                let name = self.name(inner.next()?);
                EntryKind::Command(name, self.params(inner))
            }
            Rule::status_decl => EntryKind::Status(inner.map(|n| self.name(n)).collect()),
            Rule::error_decl => EntryKind::Error(inner.map(|n| self.name(n)).collect()),
            Rule::var_decl => {
                let name = self.name(inner.next()?);
                let ty = self.type_expr(inner.next()?);
                let init = inner.next().map(|e| self.expr(e));
                EntryKind::Var { name, ty, init }
            }
            Rule::hook_decl => {
                let name = self.name(inner.next()?);
                let mut params = Vec::new();
                let mut ret = None;
                for c in inner {
                    match c.as_rule() {
                        Rule::param => params.extend(self.params(std::iter::once(c))),
                        Rule::type_expr => ret = Some(self.type_expr(c)),
                        _ => {}
                    }
                }
                EntryKind::Hook { name, params, ret }
            }
            Rule::plan_def => {
                let kw = decl.clone().into_inner().next()?;
                let verb_pair = inner.next()?;
                let header = self.span(&kw).to(self.span(&verb_pair));
                let verb = self.name(verb_pair);
                let rows = inner.map(|r| self.row(r)).collect();
                EntryKind::Plan(PlanDef { verb, header, rows })
            }
            _ => return None,
        };
        Some(Entry { outer, kind, span })
    }

    fn row(&mut self, p: Pair<Rule>) -> Row {
        let span = self.span(&p);
        let mut docs = Vec::new();
        let mut label = None;
        let mut body = Vec::new();
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::doc_comment => docs.push(Self::doc(&c)),
                Rule::row_label => {
                    let s = self.span(&c);
                    let n = c.as_str()[1..].parse::<u64>().unwrap_or(u64::MAX);
                    label = Some((n, s));
                }
                _ => body.push(c),
            }
        }
        let mut from = None;
        let mut otherwise = None;
        let mut when = None;
        let mut cond = None;
        let mut cond_span = span;
        let mut target = None;
        let mut jobs = Vec::new();
        for c in body {
            match c.as_rule() {
                Rule::from_state => {
                    let c = c.into_inner().next().expect("from has one child");
                    from = Some(match c.as_rule() {
                        Rule::dont_care => self.dont_care(c),
                        _ => From::State(self.name(c)),
                    });
                }
                Rule::kw_otherwise => {
                    cond_span = self.span(&c);
                    otherwise = Some(cond_span);
                }
                Rule::kw_when => when = Some(self.span(&c)),
                Rule::expr => {
                    cond_span = self.span(&c);
                    cond = Some(self.expr(c));
                }
                Rule::target => target = Some(self.target(c)),
                Rule::jobs => jobs = c.into_inner().map(|j| self.job(j)).collect(),
                _ => {}
            }
        }
        let from = match (from, otherwise) {
            (Some(From::State(n)), Some(_)) => {
                self.error(
                    n.span,
                    format!("an `otherwise` row cannot start in state `{}`", n.text),
                    "`otherwise` applies in every state",
                );
                self.diags.last_mut().expect("just pushed").help =
                    Some("write `otherwise -> …` or `*N otherwise -> …`".to_string());
                From::Implicit
            }
            (Some(f), _) => f,
            (None, Some(_)) => From::Implicit,
            (None, None) => {
                self.error(
                    when.unwrap_or(cond_span),
                    "expected a state or `*` before `when`",
                    "this row names no state",
                );
                self.diags.last_mut().expect("just pushed").help =
                    Some("start the row with the state it applies in (`S1 when …`) or `*` for every state".to_string());
                From::Implicit
            }
        };
        debug_assert!(otherwise.is_some() == cond.is_none());
        Row {
            docs,
            label,
            from,
            cond,
            cond_span,
            target: target.expect("row has a target"),
            jobs,
            span,
        }
    }

    fn dont_care(&mut self, p: Pair<Rule>) -> From {
        let span = self.span(&p);
        let digits = &p.as_str()[1..];
        let n = if digits.is_empty() {
            None
        } else {
            Some(digits.parse::<u64>().unwrap_or(u64::MAX))
        };
        From::DontCare(n, span)
    }

    fn target(&mut self, p: Pair<Rule>) -> Target {
        let c = p.into_inner().next().expect("target has one child");
        let span = self.span(&c);
        match c.as_rule() {
            Rule::kw_same => Target::Same(span),
            Rule::error_target => {
                let code = c.into_inner().nth(1).map(|n| self.name(n));
                Target::Error(code, span)
            }
            _ => Target::State(self.name(c)),
        }
    }

    fn job(&mut self, p: Pair<Rule>) -> Job {
        let c = p.into_inner().next().expect("job has one child");
        let span = self.span(&c);
        match c.as_rule() {
            Rule::report_job => {
                let n = self.name(c.into_inner().nth(1).expect("status"));
                Job::Report(n, span)
            }
            _ => {
                let mut inner = c.into_inner();
                let first = inner.next().expect("place");
                match inner.next() {
                    Some(arrow) if arrow.as_rule() == Rule::send_arrow => {
                        // `X <- VERB(args)`: the name before `<-` is the subordinate.
                        let sub_span = self.span(&first);
                        let place = self.postfix(first, 0).0;
                        let sub = match place.kind {
                            ExprKind::Path(None, n) => n,
                            _ => {
                                self.error(
                                    sub_span,
                                    "expected a subordinate's name before `<-`",
                                    "not a controller name",
                                );
                                Name {
                                    text: Default::default(),
                                    span: sub_span,
                                }
                            }
                        };
                        let verb = self.name(inner.next().expect("verb"));
                        let args = inner
                            .map(|a| {
                                let mut ai = a.into_inner();
                                let n = self.name(ai.next().expect("arg name"));
                                let e = self.expr(ai.next().expect("arg value"));
                                (n, e)
                            })
                            .collect();
                        Job::Send {
                            sub,
                            verb,
                            args,
                            span,
                        }
                    }
                    Some(op) => {
                        let place = self.postfix(first, 0).0;
                        let op = match op.as_str() {
                            "+=" => AssignOp::Add,
                            "-=" => AssignOp::Sub,
                            _ => AssignOp::Set,
                        };
                        let value = self.expr(inner.next().expect("assigned value"));
                        Job::Assign {
                            place,
                            op,
                            value,
                            span,
                        }
                    }
                    None => {
                        let place = self.postfix(first, 0).0;
                        if !matches!(place.kind, ExprKind::Call(..)) {
                            self.error(
                                span,
                                "expected a job: an assignment, `X <- VERB`, `report S` or a hook call",
                                "this expression does nothing",
                            );
                        }
                        Job::Call(place)
                    }
                }
            }
        }
    }

    fn expr(&mut self, p: Pair<Rule>) -> Expr {
        self.expr_at(p, 0)
    }

    fn too_deep(&mut self, span: Span) -> Expr {
        self.error(
            span,
            format!("expression nested more than {MAX_EXPR_DEPTH} deep"),
            "too deep",
        );
        self.diags.last_mut().expect("just pushed").help = Some(
            "split it: compute parts in earlier rows' jobs into `var`s, or in a hook".to_string(),
        );
        Expr {
            kind: ExprKind::Bool(false),
            span,
        }
    }

    /// Build an expression whose root sits at tree depth `depth`. Operator
    /// chains are folded by precedence climbing with explicit stacks, and
    /// every node's depth is bounded by [`MAX_EXPR_DEPTH`], so no input can
    /// make this (or the type checker after it) recurse without limit.
    fn expr_at(&mut self, p: Pair<Rule>, depth: usize) -> Expr {
        let span = self.span(&p);
        if depth > MAX_EXPR_DEPTH {
            return self.too_deep(span);
        }
        let mut operands: Vec<(Expr, usize)> = Vec::new();
        let mut ops: Vec<BinOp> = Vec::new();
        let mut failed = false;
        let reduce = |operands: &mut Vec<(Expr, usize)>, op: BinOp| {
            let (r, dr) = operands.pop().expect("right operand");
            let (l, dl) = operands.pop().expect("left operand");
            let span = l.span.to(r.span);
            let d = dl.max(dr) + 1;
            operands.push((
                Expr {
                    kind: ExprKind::Binary(op, Box::new(l), Box::new(r)),
                    span,
                },
                d,
            ));
            d
        };
        for c in p.into_inner() {
            if c.as_rule() == Rule::operand {
                let (e, d) = self.operand(c, depth);
                operands.push((e, d));
                continue;
            }
            let op = bin_op(c.as_str());
            // Left-associative: reduce while the stacked operator binds at least as tightly.
            while let Some(&top) = ops.last() {
                if top.precedence() < op.precedence() {
                    break;
                }
                ops.pop();
                if reduce(&mut operands, top) + depth > MAX_EXPR_DEPTH {
                    failed = true;
                }
            }
            ops.push(op);
            if failed {
                break;
            }
        }
        if failed {
            return self.too_deep(span);
        }
        while let Some(op) = ops.pop() {
            if reduce(&mut operands, op) + depth > MAX_EXPR_DEPTH {
                return self.too_deep(span);
            }
        }
        operands.pop().expect("an expression has an operand").0
    }

    /// `op_unary* postfix (as T)*`; returns the node and its height.
    fn operand(&mut self, p: Pair<Rule>, depth: usize) -> (Expr, usize) {
        let mut prefixes = Vec::new();
        let mut base = None;
        let mut casts = Vec::new();
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::op_unary => prefixes.push((c.as_str() == "!", self.span(&c))),
                Rule::postfix_expr => base = Some(c),
                Rule::ident => casts.push(c),
                _ => {}
            }
        }
        let wrappers = prefixes.len() + casts.len();
        let base = base.expect("operand has a base");
        if wrappers + depth > MAX_EXPR_DEPTH {
            let span = self.span(&base);
            return (self.too_deep(span), 1);
        }
        let (mut e, mut h) = self.postfix(base, depth + wrappers);
        for ty in casts {
            let ty = self.name(ty);
            let span = e.span.to(ty.span);
            e = Expr {
                kind: ExprKind::Cast(Box::new(e), ty),
                span,
            };
            h += 1;
        }
        for (not, op_span) in prefixes.into_iter().rev() {
            let span = op_span.to(e.span);
            let op = if not { UnOp::Not } else { UnOp::Neg };
            e = Expr {
                kind: ExprKind::Unary(op, Box::new(e)),
                span,
            };
            h += 1;
        }
        (e, h)
    }

    fn postfix(&mut self, p: Pair<Rule>, depth: usize) -> (Expr, usize) {
        let mut inner = p.into_inner();
        let first = inner.next().expect("primary");
        let suffixes: Vec<Pair<Rule>> = inner.collect();
        if suffixes.len() + depth > MAX_EXPR_DEPTH {
            let span = self.span(&first);
            return (self.too_deep(span), 1);
        }
        let (mut e, mut h) = self.primary(first, depth + suffixes.len());
        let mut suffixes = suffixes.into_iter().peekable();
        // `cmd.P`: the command parameter, not a field of something named `cmd`.
        if matches!(&e.kind, ExprKind::Path(None, n) if n.text == "cmd") {
            let param = suffixes
                .next_if(|s| {
                    s.clone()
                        .into_inner()
                        .next()
                        .is_some_and(|c| c.as_rule() == Rule::ident)
                })
                .map(|s| s.into_inner().next().expect("field name"));
            match param {
                Some(p) => {
                    let span = e.span.to(self.span(&p));
                    e = Expr {
                        kind: ExprKind::CmdParam(self.name(p)),
                        span,
                    };
                }
                None => {
                    let span = e.span;
                    self.error(
                        span,
                        "`cmd` alone is not a value",
                        "expected `cmd.PARAMETER`",
                    );
                    self.diags.last_mut().expect("just pushed").help =
                        Some("read a parameter of the current command as `cmd.NAME`".to_string());
                }
            }
        }
        for s in suffixes {
            let sspan = self.span(&s);
            let span = e.span.to(sspan);
            let c = s.into_inner().next().expect("suffix has one child");
            e = match c.as_rule() {
                // `status` and `error` are keywords but valid after a dot.
                Rule::kw_status | Rule::kw_error => Expr {
                    kind: ExprKind::Field(
                        Box::new(e),
                        Name {
                            text: c.as_str().into(),
                            span: self.span(&c),
                        },
                    ),
                    span,
                },
                Rule::ident => Expr {
                    kind: ExprKind::Field(Box::new(e), self.name(c)),
                    span,
                },
                _ => {
                    let idx = self.expr_at(c, depth + 1);
                    Expr {
                        kind: ExprKind::Index(Box::new(e), Box::new(idx)),
                        span,
                    }
                }
            };
            h += 1;
        }
        (e, h)
    }

    fn primary(&mut self, p: Pair<Rule>, depth: usize) -> (Expr, usize) {
        let span = self.span(&p);
        let mut height = 1;
        let kind = match p.as_rule() {
            Rule::number if p.as_str().contains(['.', 'e', 'E']) => {
                match p.as_str().replace('_', "").parse::<f64>() {
                    Ok(v) if v.is_finite() => ExprKind::Float(v),
                    _ => {
                        self.error(span, "float literal is out of range", "not a finite f64");
                        ExprKind::Float(0.0)
                    }
                }
            }
            Rule::number => match p.as_str().replace('_', "").parse::<u128>() {
                Ok(v) if v <= u64::MAX as u128 => ExprKind::Int(v),
                _ => {
                    self.error(
                        span,
                        "integer literal is too large",
                        "does not fit in 64 bits",
                    );
                    ExprKind::Int(0)
                }
            },
            Rule::name_expr => {
                let mut inner = p.into_inner();
                let first = inner.next().expect("a name");
                match (first.as_str(), inner.peek().map(|c| c.as_rule())) {
                    ("true", None) => ExprKind::Bool(true),
                    ("false", None) => ExprKind::Bool(false),
                    ("new_command", None) => ExprKind::NewCommand,
                    ("state_cycles", None) => ExprKind::StateCycles,
                    ("plan_cycles", None) => ExprKind::PlanCycles,
                    // Left for `postfix`, which turns `cmd.P` into a parameter.
                    ("cmd", None) => ExprKind::Path(
                        None,
                        Name {
                            text: "cmd".into(),
                            span,
                        },
                    ),
                    (_, Some(Rule::call_args)) => {
                        let name = self.name(first);
                        let args = inner
                            .next()
                            .expect("arguments")
                            .into_inner()
                            .map(|a| self.expr_at(a, depth + 1))
                            .collect();
                        height = 2;
                        ExprKind::Call(name, args)
                    }
                    (_, Some(_)) => {
                        let qualifier = self.name(first);
                        let name = self.name(inner.next().expect("variant"));
                        ExprKind::Path(Some(qualifier), name)
                    }
                    (_, None) => ExprKind::Path(None, self.name(first)),
                }
            }
            Rule::paren => {
                let e = self.expr_at(p.into_inner().next().expect("inner"), depth + 1);
                height = 2;
                ExprKind::Paren(Box::new(e))
            }
            _ => unreachable!("primary alternatives are listed in the grammar"),
        };
        (Expr { kind, span }, height)
    }
}

/// Words of the language that cannot name anything (LANGUAGE.md §1).
pub const RESERVED: [&str; 24] = [
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
        _ => BinOp::Rem,
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
