//! Code actions: the quick fixes the checks attach to their diagnostics
//! ([`rcs_dsl::diagnostic::Fix`]: "did you mean", a row number that does
//! not match its position), offered for the diagnostics in the range the
//! editor asks about.
//!
//! A fix names the text it replaces; it is offered only where that text
//! stands exactly once, as a whole word, inside the diagnostic's span —
//! so it can never edit something else.
//!
//! Where a row number is wrong, one more action renumbers the whole plan
//! set as `rcsc fmt --renumber` does ([`rcs_dsl::fmt::renumber`]): every
//! label and `*N` to its position, and the `fired:` of the set's
//! scenarios with them (read from disk), as one workspace edit.

use std::collections::HashMap;

use lsp_types::{CodeAction, CodeActionKind, CodeActionOrCommand, TextEdit, WorkspaceEdit};
use rcs_dsl::diagnostic::{Code, Fix};
use rcs_dsl::source::{FileId, Span};

use super::documents::Analysis;
use super::position::LineIndex;

/// Where `fix.was` stands in its span: once, as a whole word.
pub fn fix_range(text: &str, fix: &Fix) -> Option<(usize, usize)> {
    let (start, end) = (fix.span.start as usize, fix.span.end as usize);
    let part = text.get(start..end.min(text.len()))?;
    let word = |c: Option<char>| c.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_');
    let mut found = part.match_indices(fix.was.as_str()).filter(|&(i, w)| {
        !fix.was.is_empty()
            && !word(part[..i].chars().next_back())
            && !word(part[i + w.len()..].chars().next())
    });
    let (i, w) = found.next()?;
    if found.next().is_some() {
        return None;
    }
    Some((start + i, start + i + w.len()))
}

fn overlaps(span: Span, file: FileId, from: usize, to: usize) -> bool {
    span.file == file && (span.start as usize) <= to && from <= span.end as usize
}

/// The quick fixes of the diagnostics of `file` that touch bytes
/// `from..=to`.
pub fn quick_fixes(a: &Analysis, file: FileId, from: usize, to: usize) -> Vec<CodeActionOrCommand> {
    let Some(uri) = a.path(file).and_then(super::path_uri) else {
        return Vec::new();
    };
    let text = a.text(file);
    let lines = LineIndex::new(text);
    let mut actions = Vec::new();
    for d in &a.checked.diagnostics {
        let Some(fix) = &d.fix else { continue };
        if !overlaps(fix.span, file, from, to) {
            continue;
        }
        let Some((start, end)) = fix_range(text, fix) else {
            continue;
        };
        let range = lines.range(start, end);
        let edit = WorkspaceEdit {
            changes: Some(HashMap::from([(
                uri.clone(),
                vec![TextEdit::new(range, fix.with.clone())],
            )])),
            ..WorkspaceEdit::default()
        };
        let Some(span) = super::primary(d) else {
            continue;
        };
        actions.push(CodeActionOrCommand::CodeAction(CodeAction {
            title: format!("Replace `{}` with `{}`", fix.was, fix.with),
            kind: Some(CodeActionKind::QUICKFIX),
            diagnostics: Some(vec![super::convert(a, d, span)]),
            edit: Some(edit),
            is_preferred: Some(true),
            ..CodeAction::default()
        }));
    }
    actions
}

/// "Renumber the plan set's rows", when some row number of `file` is
/// wrong: the edits of `rcsc fmt --renumber` (without its layout), each
/// changed file replaced whole.
pub fn renumber(a: &Analysis, file: FileId) -> Option<CodeActionOrCommand> {
    let wrong: Vec<lsp_types::Diagnostic> = a
        .checked
        .diagnostics
        .iter()
        .filter(|d| d.code == Code::RowNumber)
        .filter_map(|d| {
            let span = super::primary(d)?;
            (span.file == file).then(|| super::convert(a, d, span))
        })
        .collect();
    if wrong.is_empty() {
        return None;
    }
    // Every scenario or no action: one left out would keep its old names.
    let scenarios: Vec<(String, String)> = crate::test_cmd::own_scenario_texts(&a.set)
        .ok()?
        .into_iter()
        .map(|(path, text)| (path.to_string_lossy().into_owned(), text))
        .collect();
    let done = rcs_dsl::fmt::renumber(&a.set, &scenarios).ok()?;
    let mut changes: Vec<(lsp_types::Uri, Vec<TextEdit>)> = Vec::new();
    let old_texts = a
        .set
        .rcs_files
        .iter()
        .map(|&id| a.set.sources.get(id))
        .map(|f| (f.path.as_str(), f.text.as_str()))
        .chain(scenarios.iter().map(|(p, t)| (p.as_str(), t.as_str())));
    let old_texts: HashMap<&str, &str> = old_texts.collect();
    for changed in done.rcs_files.iter().chain(&done.scenarios) {
        let old = old_texts.get(changed.path.as_str())?;
        let uri = super::path_uri(std::path::Path::new(&changed.path))?;
        let whole = LineIndex::new(old).range(0, old.len());
        changes.push((uri, vec![TextEdit::new(whole, changed.text.clone())]));
    }
    if changes.is_empty() {
        return None;
    }
    let files = done.rcs_files.len();
    let scenario_files = done.scenarios.len();
    Some(CodeActionOrCommand::CodeAction(CodeAction {
        title: format!(
            "Renumber every row of the plan set ({files} file{}, {scenario_files} scenario{})",
            if files == 1 { "" } else { "s" },
            if scenario_files == 1 { "" } else { "s" },
        ),
        kind: Some(CodeActionKind::QUICKFIX),
        diagnostics: Some(wrong),
        edit: Some(WorkspaceEdit {
            changes: Some(changes.into_iter().collect()),
            ..WorkspaceEdit::default()
        }),
        ..CodeAction::default()
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fix(text: &str, span: (usize, usize), was: &str) -> Option<(usize, usize)> {
        let fix = Fix {
            span: Span::new(FileId(0), span.0, span.1),
            was: was.into(),
            with: "x".into(),
        };
        fix_range(text, &fix)
    }

    #[test]
    fn a_fix_applies_only_to_one_whole_word() {
        let text = "E1: S1 when ENGNE.done -> Done";
        assert_eq!(fix(text, (12, 22), "ENGNE"), Some((12, 17)));
        // Not inside a longer word, not when it stands twice.
        assert_eq!(fix(text, (0, 30), "S"), None);
        assert_eq!(fix("a == a", (0, 6), "a"), None);
        // Labels with a star: the star is not a word character.
        assert_eq!(fix("*3 when x -> S1", (0, 2), "*3"), Some((0, 2)));
        assert_eq!(fix("*33 when", (0, 3), "*3"), None);
        // A span past the end of a changed text: nothing.
        assert_eq!(fix("short", (2, 40), "or"), None);
        assert_eq!(fix("short", (0, 5), ""), None);
    }
}
