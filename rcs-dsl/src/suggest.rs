//! "Did you mean": the one rule every diagnostic about a misspelt name uses
//! to pick the name meant (unknown names, commands, subordinates, buffers,
//! fields, and the `state_typo` lint's states).
//!
//! A name is a likely typo of another when one edit turns one into the
//! other: one character inserted, deleted, replaced, or two neighbours
//! swapped (Damerau–Levenshtein distance 1), or when they differ in case
//! only. More than one edit suggests too much: `S1` is two edits from
//! `S23`, and such suggestions are more often wrong than right.

/// Whether `a` and `b` differ by one edit or by case only (never when equal).
pub fn one_edit(a: &str, b: &str) -> bool {
    if a == b {
        return false;
    }
    if a.eq_ignore_ascii_case(b) {
        return true;
    }
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let (short, long) = if a.len() <= b.len() {
        (&a, &b)
    } else {
        (&b, &a)
    };
    if long.len() - short.len() > 1 {
        return false;
    }
    // The first and last places they differ, counted from each end.
    let prefix = short
        .iter()
        .zip(long.iter())
        .take_while(|(x, y)| x == y)
        .count();
    let suffix = short
        .iter()
        .rev()
        .zip(long.iter().rev())
        .take_while(|(x, y)| x == y)
        .count();
    if short.len() == long.len() {
        let n = short.len();
        // Replaced: one place differs. Swapped: two neighbours, crosswise.
        prefix + suffix + 1 >= n
            || (prefix + suffix + 2 == n
                && short[prefix] == long[prefix + 1]
                && short[prefix + 1] == long[prefix])
    } else {
        // Inserted: what is left of the longer after both ends is one char.
        prefix + suffix >= short.len()
    }
}

/// The one candidate a single edit (or a case change) away from `name`,
/// preferring a case-only difference; `None` when there is none, or when
/// several are equally close (a guess would mislead). Candidates may repeat.
pub fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let mut case_only: Option<&str> = None;
    let mut found: Option<&str> = None;
    let mut ambiguous = false;
    for c in candidates {
        if !one_edit(name, c) {
            continue;
        }
        if c.eq_ignore_ascii_case(name) {
            case_only = Some(c);
        } else if found.is_some_and(|f| f != c) {
            ambiguous = true;
        } else {
            found = Some(c);
        }
    }
    case_only.or(if ambiguous { None } else { found })
}

/// The help line for a misspelt name.
pub fn help(meant: &str) -> String {
    format!("did you mean `{meant}`?")
}

impl crate::diagnostic::Diagnostic {
    /// Make "did you mean `X`?" the help, for the candidate (of
    /// `candidates`) one edit away from `name`, if there is one; the help
    /// the diagnostic had becomes a note.
    pub fn suggest<'a>(
        mut self,
        name: &str,
        candidates: impl IntoIterator<Item = &'a str>,
    ) -> Self {
        if let Some(meant) = closest(name, candidates) {
            if let Some(old) = self.help.replace(help(meant)) {
                self.notes.push(old);
            }
            return self.with_fix(name, meant);
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_edit_is_insert_delete_replace_swap_or_case() {
        assert!(one_edit("S44", "S4"));
        assert!(one_edit("S4", "S44"));
        assert!(one_edit("Dnoe", "Done"));
        assert!(one_edit("Eror", "Error"));
        assert!(one_edit("done", "Done"));
        assert!(one_edit("DONE", "Done"));
        assert!(one_edit("S1", "S2"));
        assert!(one_edit("sane", "same"));
        assert!(one_edit("ab", "ba"));
        assert!(!one_edit("S4", "S4"));
        assert!(!one_edit("S1", "S23"));
        assert!(!one_edit("abc", "cba"));
        assert!(!one_edit("Done", "Dn"));
        assert!(!one_edit("abcd", "badc"));
        assert!(!one_edit("", "ab"));
        assert!(one_edit("", "a"));
    }

    #[test]
    fn closest_prefers_case_and_refuses_to_guess_between_two() {
        assert_eq!(closest("S44", ["S4", "S0", "S7"]), Some("S4"));
        assert_eq!(closest("done", ["Dome", "Done"]), Some("Done"));
        assert_eq!(closest("S3", ["S1", "S2"]), None);
        assert_eq!(closest("S3", ["S1", "S1"]), Some("S1"));
        assert_eq!(closest("speed", ["velocity"]), None);
    }

    #[test]
    fn suggest_moves_the_old_help_to_a_note() {
        let span = crate::source::Span {
            file: crate::source::FileId(0),
            start: 0,
            end: 1,
        };
        let d = crate::diagnostic::Diagnostic::error(crate::Code::UnknownName, "m", span, "l")
            .with_help("declare it");
        let kept = d.clone().suggest("spede", ["speed", "feed"]);
        assert_eq!(kept.help.as_deref(), Some("did you mean `speed`?"));
        assert_eq!(kept.notes, vec!["declare it".to_string()]);
        let none = d.suggest("x", ["speed"]);
        assert_eq!(none.help.as_deref(), Some("declare it"));
        assert!(none.notes.is_empty());
    }
}
