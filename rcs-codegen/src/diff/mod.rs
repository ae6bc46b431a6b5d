//! Renderers of a semantic diff ([`rcs_dsl::diff::PlanSetDiff`]): text
//! for a terminal, markdown for a pull-request comment, and a
//! diff-coloured state graph per changed plan. Pure functions returning
//! strings, like the other back ends; `rcsc diff` prints or writes them.

mod dot;
mod markdown;
mod text;

pub use dot::diff_dot;
pub use markdown::markdown;
pub use text::text;

use rcs_dsl::diff::{Effect, ItemChange, Move, Presence, RowChange, RowDiff};

/// What happened to a row, in one word.
pub(crate) fn row_word(r: &RowDiff) -> &'static str {
    match &r.change {
        RowChange::Added => "added",
        RowChange::Removed => "removed",
        RowChange::Changed(_) => "changed",
        RowChange::Same if r.renumbered() => "renumbered",
        RowChange::Same => "unchanged",
    }
}

/// `E3 (was E2)` when renumbered, else `E3`.
pub(crate) fn row_name(r: &RowDiff) -> String {
    match (&r.old, &r.new) {
        (Some(o), Some(n)) if o.label != n.label => format!("{} (was {})", n.label, o.label),
        _ => r.label().to_string(),
    }
}

/// One line about a changed declaration: `command AHEAD(speed: f64) → …`.
pub(crate) fn item_line(i: &ItemChange) -> (char, String) {
    match (&i.old, &i.new) {
        (None, Some(n)) => ('+', n.clone()),
        (Some(o), None) => ('-', o.clone()),
        (Some(o), Some(n)) => ('~', format!("{o} → {n}")),
        (None, None) => ('~', i.name.clone()),
    }
}

/// An item as one says it: its kind, then its text — unless the text
/// already starts with the kind's keyword (`command DRAIN(rate: u8)`,
/// `buffer Sensors { … }`), where the kind would only repeat it.
pub(crate) fn item_label(i: &ItemChange) -> String {
    let (_, text) = item_line(i);
    let keyword = i.kind.split(' ').next().unwrap_or(i.kind);
    let says_kind = text
        .strip_prefix(keyword)
        .is_some_and(|rest| rest.starts_with(' '));
    if says_kind {
        text
    } else {
        format!("{} {text}", i.kind)
    }
}

/// `E1 (was E2) now precedes E2 (was E1): …` and what that does.
pub(crate) fn move_line(m: &Move) -> String {
    let was = |now: &str, was: &str| {
        if now == was {
            now.to_string()
        } else {
            format!("{now} (was {was})")
        }
    };
    let mut s = format!(
        "{} now precedes {}",
        was(&m.now_first, &m.was),
        was(&m.now_second, &m.second_was)
    );
    let other = if m.now_second == m.second_was {
        m.now_second.clone()
    } else {
        format!("{} (then {})", m.now_second, m.second_was)
    };
    match &m.effect {
        Effect::ChangesFiring { state, input } => s.push_str(&format!(
            ": changes which row fires — in {state} with {input}, {} fires where before {other} or an earlier row did",
            m.now_first
        )),
        Effect::Undecided => s.push_str(
            ": both can match in a common state; the analysis cannot tell whether the row that fires changes",
        ),
    }
    s
}

/// `plan PR.AHEAD` with `(added)` / `(removed)` when one-sided.
pub(crate) fn presence(p: Presence) -> &'static str {
    match p {
        Presence::Added => " (added)",
        Presence::Removed => " (removed)",
        Presence::Both => "",
    }
}

/// The parts of a changed row, old → new, one per line.
pub(crate) fn changed_parts(r: &RowDiff) -> Vec<(String, String, String)> {
    let (Some(o), Some(n), RowChange::Changed(parts)) = (&r.old, &r.new, &r.change) else {
        return Vec::new();
    };
    parts
        .iter()
        .map(|part| {
            let (a, b) = match *part {
                "from" => (o.from.clone(), n.from.clone()),
                "condition" => (o.condition.clone(), n.condition.clone()),
                "target" => (o.target.clone(), n.target.clone()),
                _ => (jobs(&o.jobs), jobs(&n.jobs)),
            };
            (part.to_string(), a, b)
        })
        .collect()
}

fn jobs(j: &[String]) -> String {
    if j.is_empty() {
        "{}".to_string()
    } else {
        format!("{{ {} }}", j.join("; "))
    }
}
