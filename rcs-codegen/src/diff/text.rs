//! The diff as text for a terminal: one line per change, `+` added, `-`
//! removed, `~` changed, `=` renumbered, `⇅` moved in precedence;
//! coloured with ANSI escapes when asked. Text from the plans (names,
//! rows, messages) enters only through [`Paint`] or [`shown`], which escape
//! its control characters, so the only escapes that reach a terminal are
//! the colours.

use super::*;
use rcs_dsl::diff::{Finding, PlanSetDiff};
use std::fmt::Write;

struct Paint(bool);

/// Text from the plans with its control characters escaped.
fn shown(text: &str) -> std::borrow::Cow<'_, str> {
    rcs_dsl::render::escape_controls(text)
}

impl Paint {
    fn mark(&self, mark: char, text: &str) -> String {
        let text = shown(text);
        let code = match mark {
            '+' => "32",
            '-' => "31",
            '~' => "33",
            '⇅' => "35;1",
            _ => "",
        };
        if self.0 && !code.is_empty() {
            format!("\x1b[{code}m{mark} {text}\x1b[0m")
        } else {
            format!("{mark} {text}")
        }
    }

    fn bold(&self, text: &str) -> String {
        let text = shown(text);
        if self.0 {
            format!("\x1b[1m{text}\x1b[0m")
        } else {
            text.into_owned()
        }
    }
}

/// The whole diff as text; `color` adds ANSI colours. Empty when nothing
/// changed.
pub fn text(diff: &PlanSetDiff, color: bool) -> String {
    let paint = Paint(color);
    let mut out = String::new();
    for s in &diff.systems {
        let _ = writeln!(
            out,
            "{}",
            paint.bold(&format!("system {}{}", s.name, presence(s.presence)))
        );
        for i in &s.items {
            let (m, _) = item_line(i);
            let _ = writeln!(out, "  {}", paint.mark(m, &item_label(i)));
        }
        for c in &s.controllers {
            let _ = writeln!(
                out,
                "  {}",
                paint.bold(&format!("controller {}{}", c.name, presence(c.presence)))
            );
            for i in &c.items {
                let (m, t) = item_line(i);
                let _ = writeln!(out, "    {}", paint.mark(m, &t));
            }
            for b in &c.blocks {
                let _ = writeln!(
                    out,
                    "    {}",
                    paint.bold(&format!(
                        "rows {} (lands at {})",
                        b.name,
                        b.plans.join("; ")
                    ))
                );
                for r in &b.rows {
                    block_row(&mut out, &paint, r);
                }
            }
            for p in c.plans.iter().filter(|p| p.changed_outside_blocks()) {
                let _ = writeln!(
                    out,
                    "    {}",
                    paint.bold(&format!("plan {}{}", p.name(), presence(p.presence)))
                );
                for st in &p.states_added {
                    let _ = writeln!(out, "      {}", paint.mark('+', &format!("state {st}")));
                }
                for st in &p.states_removed {
                    let _ = writeln!(out, "      {}", paint.mark('-', &format!("state {st}")));
                }
                for r in p
                    .rows
                    .iter()
                    .filter(|r| r.block().is_none() || !r.is_change())
                {
                    row(&mut out, &paint, r);
                }
                for m in &p.moves {
                    let _ = writeln!(out, "      {}", paint.mark('⇅', &move_line(m)));
                }
            }
        }
        findings(
            &mut out,
            &paint,
            "findings introduced",
            '+',
            &s.findings_introduced,
        );
        findings(
            &mut out,
            &paint,
            "findings removed",
            '-',
            &s.findings_removed,
        );
    }
    out
}

fn row(out: &mut String, paint: &Paint, r: &RowDiff) {
    match (&r.change, &r.old, &r.new) {
        (RowChange::Added, _, Some(n)) => {
            let _ = writeln!(out, "      {}", paint.mark('+', &n.text()));
        }
        (RowChange::Removed, Some(o), _) => {
            let _ = writeln!(out, "      {}", paint.mark('-', &o.text()));
        }
        (RowChange::Changed(_), _, _) => {
            let _ = writeln!(out, "      {}", paint.mark('~', &row_name(r)));
            for (part, a, b) in changed_parts(r) {
                let _ = writeln!(out, "          {part}: {} → {}", shown(&a), shown(&b));
            }
        }
        (RowChange::Same, _, _) if r.renumbered() => {
            let _ = writeln!(out, "      = {}", shown(&row_name(r)));
        }
        _ => {}
    }
}

/// A changed row of a `rows` block: its content, without a plan's label.
fn block_row(out: &mut String, paint: &Paint, r: &RowDiff) {
    match (&r.change, &r.old, &r.new) {
        (RowChange::Added, _, Some(n)) => {
            let _ = writeln!(out, "      {}", paint.mark('+', &n.content()));
        }
        (RowChange::Removed, Some(o), _) => {
            let _ = writeln!(out, "      {}", paint.mark('-', &o.content()));
        }
        (RowChange::Changed(_), Some(o), _) => {
            let _ = writeln!(out, "      {}", paint.mark('~', &o.content()));
            for (part, a, b) in changed_parts(r) {
                let _ = writeln!(out, "          {part}: {} → {}", shown(&a), shown(&b));
            }
        }
        _ => {}
    }
}

fn findings(out: &mut String, paint: &Paint, title: &str, mark: char, list: &[Finding]) {
    if list.is_empty() {
        return;
    }
    let _ = writeln!(out, "  {}", paint.bold(title));
    for f in list {
        let line = format!("{} {}: {}", f.code, f.place(), f.message);
        let _ = writeln!(out, "    {}", paint.mark(mark, &line));
    }
}
