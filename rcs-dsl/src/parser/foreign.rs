//! Stage 1, beside [`super::syntax_error`]: the spellings engineers bring
//! from C, Rust, Structured Text and Python (`if`, `switch`, `&=`, `x++`,
//! `===`, `:=`, `and`, a hex float) named for what they are, with the
//! spelling this language uses, instead of a bare "expected …". Each is
//! recognised at the place pest stopped, from the text around it; anything
//! else keeps the generic message.

/// A recognised foreign spelling: where it is, what to say, how to write it.
pub(super) struct Foreign {
    pub start: usize,
    pub end: usize,
    pub message: String,
    pub label: &'static str,
    pub help: String,
}

/// Compound assignments other languages have, and the job that says it.
const COMPOUND: [(&str, &str); 8] = [
    ("<<=", "<<"),
    (">>=", ">>"),
    ("&=", "&"),
    ("|=", "|"),
    ("^=", "^"),
    ("*=", "*"),
    ("/=", "/"),
    ("%=", "%"),
];

/// Statement words of other languages: a plan decides in its rows.
const STATEMENTS: [&str; 14] = [
    "if", "IF", "elif", "elsif", "ELSIF", "else", "ELSE", "while", "WHILE", "for", "FOR", "loop",
    "return", "goto",
];

/// Words that pick one case of many: a state table says that with rows.
const CASES: [&str; 5] = ["switch", "match", "case", "CASE", "select"];

/// The foreign spelling at `pos` (where parsing stopped), if it is one.
pub(super) fn foreign_spelling(text: &str, pos: usize) -> Option<Foreign> {
    let pos = pos.min(text.len());
    let rest = &text[pos..];
    let before = &text[..pos];
    operator(before, rest, pos)
        .or_else(|| hex_float(before, pos))
        .or_else(|| word(text, pos))
}

fn operator(before: &str, rest: &str, pos: usize) -> Option<Foreign> {
    let at = |len: usize, message: String, help: String| Foreign {
        start: pos,
        end: pos + len,
        message,
        label: "not an operator of this language",
        help,
    };
    for (op, bin) in COMPOUND {
        if rest.starts_with(op) {
            return Some(at(
                op.len(),
                format!("`{op}` is not a job"),
                format!("jobs assign with `=`, `+=` and `-=`: write `x = x {bin} value`"),
            ));
        }
    }
    if rest.starts_with("++") || rest.starts_with("--") {
        let sign = &rest[..1];
        return Some(at(
            2,
            format!("`{sign}{sign}` is not a job"),
            format!("write `x {sign}= 1`"),
        ));
    }
    // `a === b`: pest stops at the third `=`.
    if rest.starts_with('=') && (before.ends_with("==") || before.ends_with("!=")) {
        let op = &before[before.len() - 2..];
        return Some(Foreign {
            start: pos - 2,
            end: pos + 1,
            message: format!("`{op}=` is not an operator of this language"),
            label: "not an operator of this language",
            help: format!("compare with `{op}`: values of one type compare exactly"),
        });
    }
    if rest.starts_with(":=") {
        return Some(at(
            2,
            "`:=` is not an assignment of this language".to_string(),
            "assign with `=` (Structured Text's `:=`), as in `{ x = 1 }`".to_string(),
        ));
    }
    // `a <> b`: pest takes `<` and stops at `>`.
    if rest.starts_with("<>") || (rest.starts_with('>') && before.ends_with('<')) {
        let start = if rest.starts_with("<>") { pos } else { pos - 1 };
        return Some(Foreign {
            start,
            end: start + 2,
            message: "`<>` is not an operator of this language".to_string(),
            label: "not an operator of this language",
            help: "write `!=` for \"not equal\"".to_string(),
        });
    }
    None
}

/// `0x1.8`: a hex literal with a fraction (C99's hex floats).
fn hex_float(before: &str, pos: usize) -> Option<Foreign> {
    let t = before.strip_suffix('.')?;
    let digits = t
        .bytes()
        .rev()
        .take_while(|b| b.is_ascii_hexdigit() || *b == b'_')
        .count();
    let lit = &t[..t.len() - digits];
    if digits == 0 || !(lit.ends_with("0x") || lit.ends_with("0X") || lit.ends_with("0b")) {
        return None;
    }
    let start = lit.len() - 2;
    Some(Foreign {
        start,
        end: pos,
        message: "a hex or binary literal has no fraction".to_string(),
        label: "an integer literal",
        help:
            "`0x` and `0b` write integers (fieldbus words); write a float in decimal, as in `1.5`"
                .to_string(),
    })
}

/// The word at `pos`, or the first word of the statement `pos` is in.
fn word(text: &str, pos: usize) -> Option<Foreign> {
    let is_word = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let bytes = text.as_bytes();
    let word_at = |start: usize| {
        let end = start + bytes[start..].iter().take_while(|b| is_word(**b)).count();
        (start, end, &text[start..end])
    };
    let (s, e, w) = word_at(pos);
    if let Some(f) = logic_word(w, s, e) {
        return Some(f);
    }
    if w == "if" {
        let before = text[..s].trim_end();
        if before.ends_with("accept") {
            return Some(Foreign {
                start: s,
                end: e,
                message: "`accept` is followed by `when`, not `if`".to_string(),
                label: "write `when`",
                help: "a command is refused unless `accept when COND` holds: write `command VERB(…) accept when COND`".to_string(),
            });
        }
        // In place of `when`: `E0: *0 if new_command -> S1`.
        if before.ends_with('*') || before.ends_with(|c: char| c.is_ascii_alphanumeric()) {
            return Some(Foreign {
                start: s,
                end: e,
                message: "a row's condition follows `when`, not `if`".to_string(),
                label: "write `when`",
                help: "`E0: S1 when x > 0 -> S2 { jobs }`".to_string(),
            });
        }
    }
    // The statement's first word: after the last `{`, `;` or line break.
    let start = text[..pos].rfind(['{', ';', '\n']).map_or(0, |i| i + 1);
    let first = start + text[start..pos].len() - text[start..pos].trim_start().len();
    if first >= text.len() || !is_word(bytes[first]) {
        return None;
    }
    let (s, e, w) = word_at(first);
    if STATEMENTS.contains(&w) {
        return Some(Foreign {
            start: s,
            end: e,
            message: format!("`{w}` is not part of the language: a plan decides in its rows"),
            label: "a statement of another language",
            help: "write the decision as a row, `S1 when x > 0 -> S2 { y = 1 }`; in `pre` and `post`, compute with expressions (`y = max(x, 0)`, `clamp`, `abs`)".to_string(),
        });
    }
    if CASES.contains(&w) {
        return Some(Foreign {
            start: s,
            end: e,
            message: format!("`{w}` is not part of the language: a plan is a state table"),
            label: "a statement of another language",
            help: "write one row per case: `S1 when mode == Auto -> S2`, `S1 when mode == Manual -> S3`".to_string(),
        });
    }
    None
}

/// `and`, `or`, `not`, `xor` (Python, Structured Text).
fn logic_word(w: &str, s: usize, e: usize) -> Option<Foreign> {
    let right = match w {
        "and" | "AND" => "`&&`",
        "or" | "OR" => "`||`",
        "not" | "NOT" => "`!`",
        "xor" | "XOR" => "`!=` on bools, `^` on integers",
        _ => return None,
    };
    Some(Foreign {
        start: s,
        end: e,
        message: format!("`{w}` is not an operator of this language"),
        label: "a word of another language",
        help: format!("write {right}"),
    })
}
