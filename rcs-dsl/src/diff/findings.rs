//! The findings of `check` (warnings: both sides check without error) on
//! both sides, compared by what they say and where they sit, never by line
//! or byte offset: an edit above a finding moves it, it does not make it new.
//!
//! A finding's key is its code, the controller, plan and row its primary
//! span falls in (the row by its content, so a renumbered row keeps its
//! findings), and its message with row names (`E3`) masked, since
//! renumbering changes those too.

use super::rows::RowView;
use super::Side;
use crate::ir::Ir;
use crate::pretty::Printer;
use crate::source::Span;
use crate::Diagnostic;
use serde::Serialize;

/// One finding, located in the plans.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Finding {
    /// The diagnostic code (`shadowed_row`, …).
    pub code: String,
    pub message: String,
    pub controller: Option<String>,
    /// The plan's verb.
    pub plan: Option<String>,
    /// The row's label on its side.
    pub row: Option<String>,
    /// The file, and the row's line when it sits on a row.
    pub file: Option<String>,
    pub line: Option<u32>,
    #[serde(skip)]
    key: String,
}

impl Finding {
    /// `PR.AHEAD E3` / `PR` / the file: where to look.
    pub fn place(&self) -> String {
        let mut s = self.controller.clone().unwrap_or_default();
        if let Some(p) = &self.plan {
            s.push_str(&format!(".{p}"));
        }
        if let Some(r) = &self.row {
            s.push_str(&format!(" {r}"));
        }
        if s.is_empty() {
            s = self.file.clone().unwrap_or_default();
        }
        s
    }
}

fn within(outer: Span, inner: Span) -> bool {
    outer.file == inner.file && outer.start <= inner.start && inner.end <= outer.end
}

/// `E` followed by digits → `E#`.
fn mask_rows(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let chars: Vec<char> = message.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let starts_word = i == 0 || !chars[i - 1].is_alphanumeric();
        if chars[i] == 'E' && starts_word && chars.get(i + 1).is_some_and(char::is_ascii_digit) {
            out.push_str("E#");
            i += 1;
            while chars.get(i).is_some_and(char::is_ascii_digit) {
                i += 1;
            }
        } else {
            out.push(chars[i]);
            i += 1;
        }
    }
    out
}

fn locate(ir: &Ir, d: &Diagnostic) -> Finding {
    let span = d.labels.iter().find(|l| l.primary).map(|l| l.span);
    let mut f = Finding {
        code: d.code.name().to_string(),
        message: d.message.clone(),
        controller: None,
        plan: None,
        row: None,
        file: span.and_then(|s| ir.files.get(s.file.0 as usize).cloned()),
        line: None,
        key: String::new(),
    };
    let mut row_content = String::new();
    if let Some(span) = span {
        if let Some(c) = ir.controllers.iter().find(|c| within(c.span, span)) {
            f.controller = Some(c.name.clone());
            if let Some(p) = c.plans.iter().find(|p| within(p.span, span)) {
                f.plan = Some(c.commands[p.verb.index()].name.clone());
                if let Some(r) = p.rows.iter().find(|r| within(r.span, span)) {
                    let v = RowView::of(ir, &Printer::new(ir, c, Some(p)), r);
                    f.row = Some(v.label.clone());
                    f.line = Some(v.line);
                    row_content = v.content();
                }
            }
        }
    }
    f.key = format!(
        "{}|{}|{}|{row_content}|{}",
        f.code,
        f.controller.as_deref().unwrap_or(""),
        f.plan.as_deref().unwrap_or(""),
        mask_rows(&f.message)
    );
    f
}

/// (introduced, removed): the findings of `new` with no twin in `old`, and
/// the other way round. Twins pair one to one.
pub(crate) fn diff_findings(old: &Side, new: &Side) -> (Vec<Finding>, Vec<Finding>) {
    let mut olds: Vec<Option<Finding>> = old
        .diagnostics
        .iter()
        .map(|d| Some(locate(old.ir, d)))
        .collect();
    let mut introduced = Vec::new();
    for d in new.diagnostics {
        let f = locate(new.ir, d);
        let twin = olds
            .iter_mut()
            .find(|o| o.as_ref().is_some_and(|o| o.key == f.key));
        match twin {
            Some(slot) => *slot = None,
            None => introduced.push(f),
        }
    }
    (introduced, olds.into_iter().flatten().collect())
}

#[cfg(test)]
mod tests {
    #[test]
    fn row_names_are_masked_in_messages_only_as_words() {
        assert_eq!(
            super::mask_rows("row E3 shadows E10; ERROR E"),
            "row E# shadows E#; ERROR E"
        );
        assert_eq!(super::mask_rows("TYPE2 E2x"), "TYPE2 E#x");
    }
}
