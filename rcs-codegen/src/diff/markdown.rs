//! The diff as GitHub-flavoured markdown, for a pull-request comment: per
//! changed plan a table of its changed rows, then the moves in precedence
//! (called out: the most dangerous edit) and the findings introduced or
//! removed.

use super::*;
use rcs_dsl::diff::{Finding, PlanSetDiff, RowView};
use std::fmt::Write;

fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

fn code(s: &str) -> String {
    if s.is_empty() {
        String::new()
    } else {
        format!("`{}`", cell(s))
    }
}

/// A row's content without its label: `S1 when x > 5 -> S2 { … }`.
fn content(v: &Option<RowView>) -> String {
    v.as_ref().map_or(String::new(), |v| code(&v.content()))
}

/// The whole diff as markdown; `No semantic change.` when empty.
pub fn markdown(diff: &PlanSetDiff) -> String {
    let mut out = String::new();
    if diff.is_empty() {
        out.push_str("No semantic change.\n");
        return out;
    }
    for s in &diff.systems {
        let _ = writeln!(out, "## System `{}`{}\n", s.name, presence(s.presence));
        items(&mut out, &s.items);
        for c in &s.controllers {
            let _ = writeln!(out, "### Controller `{}`{}\n", c.name, presence(c.presence));
            items(&mut out, &c.items);
            for b in &c.blocks {
                let _ = writeln!(
                    out,
                    "#### Rows `{}` (lands at {})\n",
                    b.name,
                    b.plans.join("; ")
                );
                out.push_str("| Change | Before | After |\n|---|---|---|\n");
                for r in &b.rows {
                    let what = match &r.change {
                        RowChange::Changed(parts) => format!("changed ({})", parts.join(", ")),
                        _ => row_word(r).to_string(),
                    };
                    let _ = writeln!(
                        out,
                        "| {what} | {} | {} |",
                        content(&r.old),
                        content(&r.new)
                    );
                }
                out.push('\n');
            }
            for p in c.plans.iter().filter(|p| p.changed_outside_blocks()) {
                let _ = writeln!(out, "#### Plan `{}`{}\n", p.name(), presence(p.presence));
                for st in &p.states_added {
                    let _ = writeln!(out, "- ➕ state `{st}`");
                }
                for st in &p.states_removed {
                    let _ = writeln!(out, "- ➖ state `{st}`");
                }
                if !p.states_added.is_empty() || !p.states_removed.is_empty() {
                    out.push('\n');
                }
                let changed: Vec<&RowDiff> = p
                    .rows
                    .iter()
                    .filter(|r| r.change != RowChange::Same || r.renumbered())
                    .filter(|r| r.block().is_none() || !r.is_change())
                    .collect();
                if !changed.is_empty() {
                    out.push_str("| Row | Change | Before | After |\n|---|---|---|---|\n");
                    for r in changed {
                        let what = match &r.change {
                            RowChange::Changed(parts) => format!("changed ({})", parts.join(", ")),
                            _ => row_word(r).to_string(),
                        };
                        let _ = writeln!(
                            out,
                            "| {} | {what} | {} | {} |",
                            row_name(r),
                            content(&r.old),
                            content(&r.new)
                        );
                    }
                    out.push('\n');
                }
                if !p.moves.is_empty() {
                    out.push_str("**⚠️ Moved in precedence**\n\n");
                    for m in &p.moves {
                        let _ = writeln!(out, "- {}", move_line(m));
                    }
                    out.push('\n');
                }
            }
        }
        findings(&mut out, "Findings introduced", &s.findings_introduced);
        findings(&mut out, "Findings removed", &s.findings_removed);
    }
    out
}

fn items(out: &mut String, list: &[ItemChange]) {
    for i in list {
        let (mark, text) = item_line(i);
        let sign = match mark {
            '+' => "➕",
            '-' => "➖",
            _ => "✏️",
        };
        let _ = writeln!(out, "- {sign} {}", code(&text));
    }
    if !list.is_empty() {
        out.push('\n');
    }
}

fn findings(out: &mut String, title: &str, list: &[Finding]) {
    if list.is_empty() {
        return;
    }
    let _ = writeln!(out, "**{title}**\n");
    for f in list {
        let _ = writeln!(
            out,
            "- `{}` {}: {}",
            f.code,
            code(&f.place()),
            cell(&f.message)
        );
    }
    out.push('\n');
}
