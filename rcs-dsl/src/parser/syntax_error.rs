//! Stage 1: a pest failure as one `syntax` diagnostic — where, what was
//! expected (in the user's words, not pest's rule names) and what was found.

use super::Rule;
use crate::diagnostic::{Code, Diagnostic};
use crate::source::{FileId, Span};

/// Turn a pest failure into one diagnostic: where, what was expected, what was found.
pub(super) fn syntax_error(file: FileId, text: &str, e: pest::error::Error<Rule>) -> Diagnostic {
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
    // `if`, `&=`, `and`, `0x1.8`…: named for what they are.
    if let Some(f) = super::foreign::foreign_spelling(text, pos) {
        return Diagnostic::error(
            Code::Syntax,
            f.message,
            Span::new(file, f.start, f.end),
            f.label,
        )
        .with_help(f.help);
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
    // `accept if COND`, `accept COND`: the clause is `accept when COND`.
    if before.ends_with("accept") && expected.iter().any(|w| w == "`when`") {
        return diagnostic.with_help(
            "a command is refused unless `accept when COND` holds: write `command VERB(…) accept when COND`",
        );
    }
    // `5 s`, `50 ms`: a duration's unit must touch its number (§8).
    let word: String = text[pos.min(text.len())..]
        .chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect();
    let number_before = before.len() < pos
        && before.ends_with(|c: char| c.is_ascii_digit())
        && before
            .trim_end_matches(|c: char| c.is_ascii_digit() || c == '_' || c == '.')
            .ends_with(|c: char| !(c.is_ascii_alphanumeric() || c == '_'));
    let spaced_unit = number_before
        && crate::time::UNITS
            .iter()
            .any(|(u, _)| *u == word || matches!(word.as_str(), "sec" | "secs" | "msec"));
    if spaced_postfix {
        diagnostic.with_help("write calls, fields, indices and `Enum::Variant` without spaces: `h()`, `ship.speed`, `a[0]`")
    } else if spaced_unit {
        let number = before
            .rsplit(|c: char| !(c.is_ascii_digit() || c == '_' || c == '.'))
            .next()
            .unwrap_or("");
        let unit = if crate::time::UNITS.iter().any(|(u, _)| *u == word) {
            word.as_str()
        } else {
            "s"
        };
        diagnostic.with_help(format!(
            "write a duration's unit right after its number, without a space: `{number}{unit}`"
        ))
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
        Rule::item => "an item (`enum`, `buffer`, `const` or `controller`)",
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
        Rule::expr | Rule::operand | Rule::postfix_expr | Rule::paren => "an expression",
        Rule::call_args => "`(`",
        Rule::infix => "an operator",
        Rule::op_unary => "an expression",
        Rule::index => "`[`",
        Rule::lint_level => "`allow`, `warn` or `deny`",
        Rule::kw_when => "`when`",
        Rule::kw_accept => "`accept when …`",
        Rule::kw_otherwise => "`otherwise`",
        Rule::kw_as => "`as`",
        Rule::kw_same => "`same`",
        Rule::kw_report => "`report`",
        Rule::kw_except => "`except`",
        Rule::use_rows => "`use NAME`",
        Rule::binding => "a binding `local: global`",
        Rule::except_states => "`except`",
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
