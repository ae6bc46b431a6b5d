//! Mis-indented keys in a YAML document, found from its text. The YAML
//! library reports where it noticed a problem, which for indentation is
//! often not where the problem is: a key indented less than its siblings
//! ends their mapping, and the library then reports the mapping "missing
//! field `order`" at a line that is right. This module finds the line that
//! is wrong, so the manifest's diagnostic can point at it and say what YAML
//! made of it.

/// A key written at the wrong indentation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Misplaced {
    /// Byte range of the key's name in the text.
    pub start: usize,
    pub end: usize,
    /// 1-based line of the key.
    pub line: usize,
    /// Its indentation, in columns (a `- ` before it counts).
    pub indent: usize,
    /// The indentation its siblings have.
    pub expected: usize,
    /// The sibling the expectation comes from (the key the library pointed
    /// at, or the key on the line above).
    pub sibling: String,
}

/// One line's key: indentation, name, and the name's byte range.
fn key_of(text: &str, line_start: usize, line: &str) -> Option<(usize, String, usize, usize)> {
    let body = line.trim_start_matches(' ');
    let mut indent = line.len() - body.len();
    let body = match body.strip_prefix("- ") {
        Some(rest) => {
            let rest_trimmed = rest.trim_start_matches(' ');
            indent += 2 + rest.len() - rest_trimmed.len();
            rest_trimmed
        }
        None => body,
    };
    let colon = body.find(':')?;
    let name = &body[..colon];
    let is_key = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        && body[colon + 1..]
            .chars()
            .next()
            .is_none_or(|c| c == ' ' || c == '\t');
    if !is_key {
        return None;
    }
    let start = line_start + indent;
    debug_assert!(text[start..].starts_with(name));
    Some((indent, name.to_string(), start, start + name.len()))
}

/// Lines of `text` with their byte offsets, 1-based numbers.
fn lines(text: &str) -> impl Iterator<Item = (usize, usize, &str)> {
    let mut offset = 0;
    text.split('\n').enumerate().map(move |(i, l)| {
        let start = offset;
        offset += l.len() + 1;
        (i + 1, start, l.trim_end_matches('\r'))
    })
}

/// The library said a mapping lacks key `missing`, pointing at line
/// `line`, column `column` (1-based) — one of that mapping's keys. If the
/// document has a `missing:` key at another indentation, nearest after that
/// line (else before), that is the key meant: return it.
pub fn missing_key_elsewhere(
    text: &str,
    missing: &str,
    line: usize,
    column: usize,
) -> Option<Misplaced> {
    let expected = column.checked_sub(1)?;
    let sibling = lines(text)
        .find(|(n, _, _)| *n == line)
        .and_then(|(_, start, l)| key_of(text, start, l))
        .filter(|(indent, ..)| *indent == expected)
        .map(|(_, name, ..)| name)?;
    let candidates: Vec<Misplaced> = lines(text)
        .filter_map(|(n, start, l)| {
            let (indent, name, s, e) = key_of(text, start, l)?;
            (name == missing && indent != expected).then(|| Misplaced {
                start: s,
                end: e,
                line: n,
                indent,
                expected,
                sibling: sibling.clone(),
            })
        })
        .collect();
    candidates
        .iter()
        .find(|m| m.line > line)
        .or_else(|| candidates.iter().rev().find(|m| m.line < line))
        .cloned()
}

/// The library found a `key:` where no mapping may start, at 1-based line
/// `line`: if that line's key is indented more than a `key: value` on the
/// line above, return it (YAML reads it as part of that value).
pub fn key_under_a_value(text: &str, line: usize) -> Option<Misplaced> {
    let all: Vec<(usize, usize, &str)> = lines(text).collect();
    let (_, start, l) = *all.iter().find(|(n, _, _)| *n == line)?;
    let (indent, _, s, e) = key_of(text, start, l)?;
    let (_, above_start, above) = *all[..line - 1]
        .iter()
        .rev()
        .find(|(_, _, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))?;
    let (above_indent, above_name, _, above_end) = key_of(text, above_start, above)?;
    let has_value = !text[above_end + 1..above_start + above.len()]
        .trim()
        .is_empty();
    (has_value && indent > above_indent).then_some(Misplaced {
        start: s,
        end: e,
        line,
        indent,
        expected: above_indent,
        sibling: above_name,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_key_indented_less_than_its_siblings_is_found() {
        let text = "schedule:\n  - cpu: main\n    period: 10ms\n  order: [A]\n";
        let m = missing_key_elsewhere(text, "order", 3, 5).unwrap();
        assert_eq!((m.line, m.indent, m.expected), (4, 2, 4));
        assert_eq!(&text[m.start..m.end], "order");
        assert_eq!(m.sibling, "period");
    }

    #[test]
    fn a_key_really_missing_is_not_found_elsewhere() {
        let text = "schedule:\n  - cpu: main\n    period: 10ms\n";
        assert_eq!(missing_key_elsewhere(text, "order", 3, 5), None);
        // At the right indentation in another entry: not this one's.
        let text = "schedule:\n  - cpu: a\n    period: 1ms\n  - cpu: b\n    order: [A]\n";
        assert_eq!(missing_key_elsewhere(text, "order", 3, 5), None);
    }

    #[test]
    fn a_key_indented_under_a_value_is_found() {
        let text = "schedule:\n  - cpu: main\n    period: 10ms\n      order: [A]\n";
        let m = key_under_a_value(text, 4).unwrap();
        assert_eq!((m.indent, m.expected), (6, 4));
        assert_eq!(&text[m.start..m.end], "order");
        assert_eq!(m.sibling, "period");
        // Under a key without a value, deeper is right.
        assert_eq!(key_under_a_value("a:\n  b: 1\n", 2), None);
    }
}
