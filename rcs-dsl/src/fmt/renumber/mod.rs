//! `rcsc fmt --renumber`: every written row label `EN` and numbered
//! don't-care `*N` set to its row's precedence position (the rule
//! `row_number` checks), and the scenarios that name a row by its old
//! number pointed at the same row again.
//!
//! ```text
//! PlanSet ──lower──▶ IR ──written numbers vs positions──▶ edits ──▶ texts ──lower──▶ same IR?
//! scenarios ──yaml (spans)──▶ `fired:` names ──old number → new position──▶ edits
//! ```
//!
//! It sits beside the formatter ([`super::format`]) and, like it, is pure:
//! texts in, texts out, no I/O, so that the CLI and the language server's
//! "renumber rows" action share it. Only the digits change — no other byte
//! moves, so an unformatted file stays unformatted — and before returning
//! the new texts are lowered again and must give the IR of the old ones
//! but for the numbers written, or nothing is returned.
//!
//! Positions come from the lowered IR, so rows placed by `use NAME` take
//! their places as every other tool counts them (LANGUAGE.md §8).

mod numbers;
mod scenarios;
#[cfg(test)]
mod tests;

use crate::diagnostic::Diagnostic;
use crate::ir::Ir;
use crate::load::PlanSet;
use crate::source::FileId;
use numbers::{Edit, Numbers};

/// The result of renumbering a plan set: the files that change and what
/// changed. Nothing is in it unless the whole set could be renumbered.
#[derive(Debug, Default)]
pub struct Renumbered {
    /// `.rcs` files whose text changes, by their path in the plan set.
    pub rcs_files: Vec<ChangedFile>,
    /// Scenario files whose text changes, by the path they were given as.
    pub scenarios: Vec<ChangedFile>,
    /// Every number rewritten in a `.rcs` file, in file order.
    pub relabelled: Vec<Relabel>,
    /// Every scenario number changed, in file order.
    pub renamed: Vec<Relabel>,
    /// What was left as it was because it could not be decided (a label
    /// written on two rows of one plan, a scenario naming a row of a plan
    /// it cannot tell), each with its place.
    pub undecided: Vec<Undecided>,
}

/// One file's new text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ChangedFile {
    pub path: String,
    pub text: String,
}

/// One number rewritten: `E3` → `E4` (or `*3` → `*4`, `#3` → `#4`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Relabel {
    /// The controller (for a row of a controller type, the type).
    pub controller: String,
    /// The plan's verbs as its header writes them (`A | B`).
    pub plan: String,
    pub path: String,
    /// 1-based line of the number.
    pub line: usize,
    pub old: String,
    pub new: String,
}

/// Something left as written, and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Undecided {
    pub path: String,
    /// 1-based line.
    pub line: usize,
    pub message: String,
}

/// Why nothing was renumbered.
#[derive(Debug)]
pub enum RenumberError {
    /// The plan set does not parse or lower: its errors, with spans in the
    /// set's sources.
    Diagnostics(Vec<Diagnostic>),
    /// The renumbered texts would not give the same plans (a bug of the
    /// renumbering, reported instead of writing changed plans).
    Changed(String),
}

impl std::fmt::Display for RenumberError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RenumberError::Diagnostics(diags) => {
                let errors = diags
                    .iter()
                    .filter(|d| d.severity == crate::Severity::Error)
                    .count();
                write!(
                    f,
                    "the plan set has errors ({errors}); nothing was renumbered"
                )
            }
            RenumberError::Changed(why) => write!(
                f,
                "renumbering would change the plans ({why}); nothing was renumbered \
                 (please report this as a bug)"
            ),
        }
    }
}

impl std::error::Error for RenumberError {}

/// Renumber the rows of `set` and the `fired:` names of `scenarios`
/// (`(path, text)` of each `*.scenario.yaml` of the set). Returns only the
/// files that change. `Err` when the set does not lower (its diagnostics)
/// or, a bug, when the result would not lower to the same IR.
pub fn renumber(
    set: &PlanSet,
    scenarios: &[(String, String)],
) -> Result<Renumbered, RenumberError> {
    let ir = crate::lower_or_diagnostics(set).map_err(RenumberError::Diagnostics)?;
    let numbers = Numbers::of(set, &ir);
    let mut out = Renumbered::default();
    let (edits, conflicts) = numbers.edits(set);
    out.undecided.extend(conflicts);
    out.relabelled = numbers.relabels(set, &edits);
    let new_texts = apply_to_set(set, &edits);
    verify(set, &ir, &new_texts)?;
    for (id, text) in new_texts {
        let file = set.sources.get(id);
        if text != file.text {
            out.rcs_files.push(ChangedFile {
                path: file.path.clone(),
                text,
            });
        }
    }
    for (path, text) in scenarios {
        let updated = scenarios::update(path, text, &ir, &numbers);
        out.undecided.extend(updated.undecided);
        out.renamed.extend(updated.renamed);
        if let Some(text) = updated.text.filter(|t| t != text) {
            out.scenarios.push(ChangedFile {
                path: path.clone(),
                text,
            });
        }
    }
    Ok(out)
}

/// Each `.rcs` file of the set with `edits` applied (every file, changed
/// or not, in the set's order).
fn apply_to_set(set: &PlanSet, edits: &[Edit]) -> Vec<(FileId, String)> {
    set.rcs_files
        .iter()
        .map(|&id| {
            let mine = edits
                .iter()
                .filter(|e| e.file == id)
                .map(|e| (e.start, e.end, e.text.as_str()));
            (id, apply(&set.sources.get(id).text, mine))
        })
        .collect()
}

/// `text` with each byte range replaced (ranges sorted, not overlapping,
/// on character boundaries: they hold ASCII digits).
fn apply<'e>(text: &str, edits: impl Iterator<Item = (usize, usize, &'e str)>) -> String {
    let mut out = String::with_capacity(text.len() + 8);
    let mut at = 0;
    for (start, end, new) in edits {
        out.push_str(&text[at..start]);
        out.push_str(new);
        at = end;
    }
    out.push_str(&text[at..]);
    out
}

/// The new texts lower to the old IR but for the numbers written, and
/// every number written in them is its row's position.
fn verify(set: &PlanSet, before: &Ir, new_texts: &[(FileId, String)]) -> Result<(), RenumberError> {
    let manifest = set
        .manifest_file
        .map(|id| set.sources.get(id).text.as_str());
    let files = new_texts
        .iter()
        .map(|(id, text)| (set.sources.get(*id).path.as_str(), text.as_str()));
    let again = PlanSet::from_texts(&set.name, files, manifest);
    let after = crate::lower_or_diagnostics(&again).map_err(|diags| {
        let first = diags.first().map(|d| d.message.clone()).unwrap_or_default();
        RenumberError::Changed(format!("the result does not lower: {first}"))
    })?;
    if let Some(row) = numbers::first_misnumbered(&after) {
        return Err(RenumberError::Changed(format!(
            "row {row} still has a number that is not its position"
        )));
    }
    let (a, b) = (numbers::meaning(before), numbers::meaning(&after));
    if a != b {
        return Err(RenumberError::Changed(format!(
            "the IR differs at {}",
            super::meaning::first_difference(&a, &b, String::new())
        )));
    }
    Ok(())
}
