//! The state table a plan graph carries under its drawing: one line per
//! row with its state pattern, target, condition and jobs, as the
//! methodology puts the conditions and job lists in a table beside a
//! small state graph (Figure 13, Appendix C). The graph's edges carry only
//! the rows' names (`E3`), so no long text is laid out by Graphviz's edge
//! label placement, which lets labels of loops and of close edges touch.
//!
//! The table is the graph's own label (an HTML-like `TABLE`), so it is part
//! of the same SVG and Graphviz reserves its space: it cannot overlap the
//! drawing. Every cell is wrapped to a bounded number of characters, so
//! the table's width is bounded whatever the conditions are.

use super::html;
use std::fmt::Write;

/// Characters per line of a condition cell.
const CONDITION_WIDTH: usize = 44;
/// Characters per line of a jobs cell.
const JOBS_WIDTH: usize = 40;
/// Characters per line of a state-pattern cell and of a note.
const FROM_WIDTH: usize = 32;
const NOTE_WIDTH: usize = 90;

/// One line of the table: a row of the plan.
#[derive(Clone, Debug, Default)]
pub(crate) struct TableRow {
    /// `E3`; for a diff, with its change sign (`+ E3`).
    pub(crate) name: String,
    /// The state pattern: `S1`, `*`, `S1 | S2`, `* except S1`, `any`.
    pub(crate) from: String,
    /// `S2`, `same`, `Done`, `Error(FAULT)`.
    pub(crate) to: String,
    pub(crate) condition: String,
    /// The jobs, one per entry.
    pub(crate) jobs: Vec<String>,
    /// The font colour of the line (diff graphs); `None`: the default.
    pub(crate) color: Option<&'static str>,
}

/// `text` broken at spaces into lines of at most `width` characters (a
/// word longer than that is cut).
pub(crate) fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let mut word: Vec<char> = word.chars().collect();
        let len = line.chars().count();
        if len > 0 && len + 1 + word.len() > width {
            lines.push(std::mem::take(&mut line));
        }
        while word.len() > width {
            let rest = word.split_off(width);
            if !line.is_empty() {
                lines.push(std::mem::take(&mut line));
            }
            lines.push(word.into_iter().collect());
            word = rest;
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.extend(word);
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// Wrapped text as the content of a left-aligned cell.
fn cell(text: &str, width: usize, color: Option<&str>) -> String {
    let lines: Vec<String> = wrap(text, width).iter().map(|l| html(l)).collect();
    let text = lines.join("<BR/>");
    match color.filter(|_| !text.is_empty()) {
        Some(c) => {
            format!("<TD ALIGN=\"LEFT\" BALIGN=\"LEFT\"><FONT COLOR=\"{c}\">{text}</FONT></TD>")
        }
        None => format!("<TD ALIGN=\"LEFT\" BALIGN=\"LEFT\">{text}</TD>"),
    }
}

/// The graph's label: `title` over the table of `rows`, then each of
/// `notes` (what runs every cycle, when a command is accepted, a key to
/// the diff colours) on a line of its own. An HTML-like label's content,
/// to go between `<` and `>`.
pub(crate) fn table(title: &str, rows: &[TableRow], notes: &[String]) -> String {
    let mut out = String::from(
        "<TABLE BORDER=\"0\" CELLBORDER=\"1\" CELLSPACING=\"0\" CELLPADDING=\"4\" COLOR=\"#999999\">",
    );
    let _ = write!(
        out,
        "<TR><TD COLSPAN=\"5\" BORDER=\"0\"><FONT POINT-SIZE=\"14\">{}</FONT></TD></TR>",
        html(title)
    );
    if !rows.is_empty() {
        out.push_str("<TR>");
        for head in ["row", "from", "to", "condition", "jobs"] {
            let _ = write!(out, "<TD ALIGN=\"LEFT\" BGCOLOR=\"#f0f3f6\">{head}</TD>");
        }
        out.push_str("</TR>");
    }
    for r in rows {
        out.push_str("<TR>");
        out.push_str(&cell(&r.name, FROM_WIDTH, r.color));
        out.push_str(&cell(&r.from, FROM_WIDTH, r.color));
        out.push_str(&cell(&r.to, FROM_WIDTH, r.color));
        out.push_str(&cell(&r.condition, CONDITION_WIDTH, r.color));
        // Each job starts a line; a long one is wrapped.
        let jobs: Vec<String> = r
            .jobs
            .iter()
            .flat_map(|j| wrap(j, JOBS_WIDTH))
            .map(|l| html(&l))
            .collect();
        let jobs = jobs.join("<BR/>");
        match r.color.filter(|_| !jobs.is_empty()) {
            Some(c) => {
                let _ = write!(
                    out,
                    "<TD ALIGN=\"LEFT\" BALIGN=\"LEFT\"><FONT COLOR=\"{c}\">{jobs}</FONT></TD>"
                );
            }
            None => {
                let _ = write!(out, "<TD ALIGN=\"LEFT\" BALIGN=\"LEFT\">{jobs}</TD>");
            }
        }
        out.push_str("</TR>");
    }
    for note in notes {
        let lines: Vec<String> = note
            .lines()
            .flat_map(|l| wrap(l, NOTE_WIDTH))
            .map(|l| html(&l))
            .collect();
        let _ = write!(
            out,
            "<TR><TD COLSPAN=\"5\" ALIGN=\"LEFT\" BALIGN=\"LEFT\" BORDER=\"0\">{}</TD></TR>",
            lines.join("<BR/>")
        );
    }
    out.push_str("</TABLE>");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrapping_keeps_words_and_bounds_lines() {
        assert_eq!(wrap("a && bb && ccc", 6), vec!["a &&", "bb &&", "ccc"]);
        assert_eq!(wrap("abcdefgh", 3), vec!["abc", "def", "gh"]);
        assert_eq!(wrap("", 5), vec![""]);
        for l in wrap(&"word ".repeat(50), 12) {
            assert!(l.chars().count() <= 12, "{l}");
        }
    }

    #[test]
    fn the_table_escapes_and_colours() {
        let t = table(
            "A · GO",
            &[TableRow {
                name: "E1".into(),
                from: "S1".into(),
                to: "Done".into(),
                condition: "x < 1".into(),
                jobs: vec!["y = 2".into()],
                color: Some("red"),
            }],
            &["status fields: x".into()],
        );
        assert!(t.contains("x &lt; 1"), "{t}");
        assert!(t.contains("<FONT COLOR=\"red\">E1</FONT>"), "{t}");
        assert!(t.contains("status fields: x"), "{t}");
    }
}
