//! DSL names → Rust names, in one place. `.rcs` names follow the plan
//! author's habits (`AHEAD`, `rpmSetpoint`, `S1`); generated Rust must follow
//! Rust's (`Ahead`, `rpm_setpoint`) so that it compiles without warnings.
//! Keywords become raw identifiers; the few names that cannot be raw
//! (`self`, `Self`, `super`, `crate`, `_`) get a trailing underscore.

use proc_macro2::{Ident, Span};

/// Split a name into words at `_` and at lower→upper and letter→digit-run
/// boundaries: `rpmSetpoint` → [rpm, Setpoint], `SPIN_UP` → [SPIN, UP].
fn words(name: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut cur = String::new();
    let mut prev: Option<char> = None;
    for c in name.chars() {
        if c == '_' {
            if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
            prev = None;
            continue;
        }
        let boundary = matches!(prev, Some(p) if p.is_ascii_lowercase() && c.is_ascii_uppercase());
        if boundary && !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
        cur.push(c);
        prev = Some(c);
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// `snake_case`: fields, vars, hooks, parameters, buffers, modules.
pub fn snake(name: &str) -> String {
    let lead = if name.starts_with('_') { "_" } else { "" };
    let w: Vec<String> = words(name)
        .into_iter()
        .map(|w| w.to_ascii_lowercase())
        .collect();
    let s = format!("{lead}{}", w.join("_"));
    if s.is_empty() {
        "_x".to_string()
    } else {
        s
    }
}

/// `UpperCamelCase`: types and enum variants (`AHEAD` → `Ahead`).
pub fn camel(name: &str) -> String {
    let s: String = words(name)
        .into_iter()
        .map(|w| {
            let all_upper = w.chars().all(|c| !c.is_ascii_lowercase());
            let mut cs = w.chars();
            let first = cs.next().map(|c| c.to_ascii_uppercase()).unwrap_or('X');
            let rest: String = if all_upper {
                cs.as_str().to_ascii_lowercase()
            } else {
                cs.as_str().to_string()
            };
            format!("{first}{rest}")
        })
        .collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        format!("X{s}")
    } else {
        s
    }
}

/// `SCREAMING_SNAKE_CASE`: constants (statuses, error codes).
pub fn screaming(name: &str) -> String {
    snake(name).to_ascii_uppercase()
}

const KEYWORDS: [&str; 50] = [
    "as", "break", "const", "continue", "else", "enum", "extern", "false", "fn", "for", "if",
    "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return", "static",
    "struct", "trait", "true", "type", "unsafe", "use", "where", "while", "async", "await", "dyn",
    "abstract", "become", "box", "do", "final", "macro", "override", "priv", "typeof", "unsized",
    "virtual", "yield", "try", "gen", "union", "raw",
];

/// A Rust identifier for an already-converted name.
pub fn ident(name: &str) -> Ident {
    match name {
        "self" | "Self" | "super" | "crate" | "_" => {
            Ident::new(&format!("{name}_"), Span::call_site())
        }
        n if KEYWORDS.contains(&n) && n != "union" && n != "raw" => {
            Ident::new_raw(n, Span::call_site())
        }
        n => Ident::new(n, Span::call_site()),
    }
}

/// `prefix_name` for a generated name built from another (`in_ship`,
/// `cmd_speed`): a raw identifier's `r#` is dropped, since the prefix
/// already keeps the result clear of keywords.
pub fn prefixed(prefix: &str, id: &Ident) -> Ident {
    let name = id.to_string();
    Ident::new(
        &format!("{prefix}_{}", name.trim_start_matches("r#")),
        Span::call_site(),
    )
}

/// Convert names with `f` and make them distinct within one scope (and
/// distinct from `reserved`), appending `_2`, `_3`, … on collision.
pub fn distinct<'a>(
    names: impl IntoIterator<Item = &'a str>,
    f: fn(&str) -> String,
    reserved: &[&str],
) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for n in names {
        let base = f(n);
        let mut candidate = base.clone();
        let mut k = 2;
        while out.contains(&candidate) || reserved.contains(&candidate.as_str()) {
            candidate = format!("{base}_{k}");
            k += 1;
        }
        out.push(candidate);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_rust_conventions() {
        assert_eq!(camel("AHEAD"), "Ahead");
        assert_eq!(camel("SPIN_UP"), "SpinUp");
        assert_eq!(camel("ShipDirection"), "ShipDirection");
        assert_eq!(camel("speed_error"), "SpeedError");
        assert_eq!(camel("S1"), "S1");
        assert_eq!(snake("rpmSetpoint"), "rpm_setpoint");
        assert_eq!(snake("PR"), "pr");
        assert_eq!(snake("AT_GOAL"), "at_goal");
        assert_eq!(screaming("AtGoal"), "AT_GOAL");
        assert_eq!(screaming("TURBINE_TIMEOUT"), "TURBINE_TIMEOUT");
    }

    #[test]
    fn keywords_become_raw_identifiers() {
        assert_eq!(ident("type").to_string(), "r#type");
        assert_eq!(ident("match").to_string(), "r#match");
        assert_eq!(ident("self").to_string(), "self_");
        assert_eq!(ident("Self").to_string(), "Self_");
        assert_eq!(ident("speed").to_string(), "speed");
    }

    #[test]
    fn collisions_get_suffixes() {
        let got = distinct(["rpm_a", "rpmA", "data"], snake, &["data"]);
        assert_eq!(got, ["rpm_a", "rpm_a_2", "data_2"]);
    }
}
