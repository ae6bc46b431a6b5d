//! `state_typo`: a misspelt state, caught at the typo. States are declared
//! by being named, so `-> S44` beside `S4` silently makes a new state; the
//! graph lints then warn far from the typo (`unreachable_state` on what
//! `S4` orphans, `dead_end_state` on `S44`). This check points at the name
//! itself and says which name was meant.
//!
//! It fires only where a typo is the likely story: the state is named by
//! one row only (nothing leads into it, or nothing leaves it), and one edit
//! (see [`crate::suggest`]) turns it into a state another row names, into
//! `S0`, or, for a target, into `Done`, `Error` or `same`. Of two states
//! each named once and one edit apart, only one is reported. Numbered states
//! one digit apart (`S1`, `S2`) are not suggested for each other: plans
//! number their steps, and an unused `S2` beside `S1` is far more often a
//! step not wired yet (the graph lints say so) than a typo.

use super::Sink;
use crate::diagnostic::Diagnostic;
use crate::ir::{Controller, From, Plan, Target};
use crate::lint::Lint;

/// The target keywords a misspelt target state may have meant.
const TARGET_WORDS: [&str; 3] = ["Done", "Error", "same"];

pub(crate) fn check_state_typos(c: &Controller, p: &Plan, sink: &mut Sink) {
    // Per state: the rows naming it (in `from` or as the target).
    let mut rows_naming: Vec<Vec<usize>> = vec![Vec::new(); p.states.len()];
    for (r, row) in p.rows.iter().enumerate() {
        let mut named: Vec<usize> = match &row.from {
            From::DontCare(_) => Vec::new(),
            From::State(s) => vec![s.index()],
            From::States(set) | From::Except(_, set) => set.iter().map(|s| s.index()).collect(),
        };
        if let Target::State(s) = row.to {
            named.push(s.index());
        }
        named.sort_unstable();
        named.dedup();
        for s in named {
            rows_naming[s].push(r);
        }
    }
    for (s, state) in p.states.iter().enumerate().skip(1) {
        let [r] = rows_naming[s][..] else { continue };
        let Some(span) = state.span else { continue };
        let row = &p.rows[r];
        let as_target = row.to == Target::State(crate::ir::StateId(s as u32));
        // States some other row names (S0 always exists: it is the entry).
        let used: Vec<&str> = p
            .states
            .iter()
            .enumerate()
            .filter(|&(t, _)| t != s && (t == 0 || rows_naming[t].iter().any(|&o| o != r)))
            .map(|(_, t)| t.name.as_str())
            .filter(|t| !numbered_neighbours(&state.name, t))
            .collect();
        let words = if as_target { &TARGET_WORDS[..] } else { &[] };
        let Some(meant) = crate::suggest::closest(
            &state.name,
            used.iter().copied().chain(words.iter().copied()),
        ) else {
            continue;
        };
        // Two states each named once, one edit apart (`-> S44` and `S4`'s
        // only row): one finding, at the target the arrow invented (or at
        // the later of two targets or two `from`s).
        if let Some(t) = p.states.iter().position(|t| t.name == meant) {
            if let [rt] = rows_naming[t][..] {
                let t_as_target = p.rows[rt].to == Target::State(crate::ir::StateId(t as u32));
                if (t_as_target && !as_target) || (t_as_target == as_target && s < t) {
                    continue;
                }
            }
        }
        let orphan = if as_target {
            "no row leaves it"
        } else {
            "no row leads into it"
        };
        let mut d = Diagnostic::lint(
            Lint::StateTypo,
            format!(
                "state `{}` of plan `{}` is named only here, one edit from `{meant}`",
                state.name,
                c.plan_title(p)
            ),
            span,
            format!("a new state, and {orphan}"),
        )
        .with_note("a state that really is new needs rows of its own; else `#[allow(state_typo)]`")
        .with_help(crate::suggest::help(meant))
        .with_fix(state.name.as_str(), meant);
        if let Some(other) = p.states.iter().find(|t| t.name == meant) {
            if let Some(at) = other.span {
                d = d.with_secondary(at, format!("`{meant}` is used here"));
            }
        }
        sink.lint(Some(c), Some(p), d);
    }
}

/// `S1` and `S2`: the same name but for one digit replaced by another.
fn numbered_neighbours(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut differ = a.iter().zip(b).filter(|(x, y)| x != y);
    matches!(
        (differ.next(), differ.next()),
        (Some((x, y)), None) if x.is_ascii_digit() && y.is_ascii_digit()
    )
}
