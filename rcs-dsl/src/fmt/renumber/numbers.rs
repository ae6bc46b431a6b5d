//! The numbers written on rows (`EN` labels, `*N` don't-cares), read from
//! the lowered IR and the source text: what each says, where its digits
//! are, and the position of its row. From them [`super::renumber`] makes
//! the edits of the `.rcs` files, and [`super::scenarios`] maps a
//! scenario's old number to the row's position, plan by plan.

use super::{Relabel, Undecided};
use crate::ir::{Controller, From, Ir, Plan, Row};
use crate::load::PlanSet;
use crate::source::FileId;
use std::collections::BTreeMap;

/// One number written on a row: the byte range of its digits and the
/// digits without leading zeros (`E007` says `7`).
#[derive(Clone, Debug)]
struct Written {
    file: FileId,
    start: usize,
    end: usize,
    /// `E` or `*`.
    prefix: char,
    digits: String,
}

struct RowNumbers {
    position: u32,
    written: Vec<Written>,
}

struct PlanNumbers {
    /// `A | B`.
    title: String,
    rows: Vec<RowNumbers>,
}

struct ControllerNumbers {
    /// The name a report gives: the type's for an instance.
    shown: String,
    plans: Vec<PlanNumbers>,
}

/// The written numbers of every plan of a lowered plan set, by controller
/// name (instances of a type each under their own name).
pub(super) struct Numbers {
    controllers: BTreeMap<String, ControllerNumbers>,
}

/// A change of the digits at `start..end` of `file`.
#[derive(Clone, Debug)]
pub(super) struct Edit {
    pub(super) file: FileId,
    pub(super) start: usize,
    pub(super) end: usize,
    pub(super) text: String,
    prefix: char,
    old: String,
    controller: String,
    plan: String,
}

/// What an old number names in one plan.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum Named {
    /// Nothing: the plan has no row of that number or position.
    Nothing,
    /// The row now at this position.
    Row(u32),
    /// Several rows carry the number (a row inserted with a copied label).
    Several(Vec<u32>),
}

impl Numbers {
    pub(super) fn of(set: &PlanSet, ir: &Ir) -> Numbers {
        let controllers = ir
            .controllers
            .iter()
            .map(|c| {
                let shown = match &c.instance_of {
                    Some(of) => format!("type {}", of.ty),
                    None => c.name.clone(),
                };
                let plans = c
                    .plans
                    .iter()
                    .map(|p| PlanNumbers {
                        title: title(c, p),
                        rows: p
                            .rows
                            .iter()
                            .map(|r| RowNumbers {
                                position: r.position,
                                written: written(set, r),
                            })
                            .collect(),
                    })
                    .collect();
                (c.name.clone(), ControllerNumbers { shown, plans })
            })
            .collect();
        Numbers { controllers }
    }

    /// The edits that make every written number its row's position, sorted
    /// by place, and the places two rows would have written differently
    /// (left as they are).
    pub(super) fn edits(&self, set: &PlanSet) -> (Vec<Edit>, Vec<Undecided>) {
        let mut by_place: BTreeMap<(FileId, usize), Edit> = BTreeMap::new();
        let mut conflicts: BTreeMap<(FileId, usize), Undecided> = BTreeMap::new();
        for c in self.controllers.values() {
            for p in &c.plans {
                for r in &p.rows {
                    for w in &r.written {
                        let new = r.position.to_string();
                        let raw = &set.sources.get(w.file).text[w.start..w.end];
                        let key = (w.file, w.start);
                        match by_place.get(&key) {
                            Some(e) if e.text != new => {
                                let file = set.sources.get(w.file);
                                conflicts.entry(key).or_insert_with(|| Undecided {
                                    path: file.path.clone(),
                                    line: file.line_col(w.start).0,
                                    message: format!(
                                        "`{}{raw}` is one row at two positions ({} and {new}); left as it is",
                                        w.prefix, e.text
                                    ),
                                });
                            }
                            Some(_) => {}
                            None => {
                                by_place.insert(
                                    key,
                                    Edit {
                                        file: w.file,
                                        start: w.start,
                                        end: w.end,
                                        text: new,
                                        prefix: w.prefix,
                                        old: raw.to_string(),
                                        controller: c.shown.clone(),
                                        plan: p.title.clone(),
                                    },
                                );
                            }
                        }
                    }
                }
            }
        }
        let edits = by_place
            .into_iter()
            .filter(|(key, e)| !conflicts.contains_key(key) && e.old != e.text)
            .map(|(_, e)| e)
            .collect();
        (edits, conflicts.into_values().collect())
    }

    /// The report of `edits`.
    pub(super) fn relabels(&self, set: &PlanSet, edits: &[Edit]) -> Vec<Relabel> {
        edits
            .iter()
            .map(|e| {
                let file = set.sources.get(e.file);
                Relabel {
                    controller: e.controller.clone(),
                    plan: e.plan.clone(),
                    path: file.path.clone(),
                    line: file.line_col(e.start).0,
                    old: format!("{}{}", e.prefix, e.old),
                    new: format!("{}{}", e.prefix, e.text),
                }
            })
            .collect()
    }

    /// The controller's plan titles, by plan index; `None` for a name that
    /// is no controller of the set.
    pub(super) fn plan_titles(&self, controller: &str) -> Option<Vec<&str>> {
        let c = self.controllers.get(controller)?;
        Some(c.plans.iter().map(|p| p.title.as_str()).collect())
    }

    /// What old number `digits` (no leading zeros) names in plan `plan` of
    /// `controller`: the row that carries it, else the row at that
    /// position if it carries no number (its name is its position).
    pub(super) fn named(&self, controller: &str, plan: usize, digits: &str) -> Named {
        let Some(p) = self
            .controllers
            .get(controller)
            .and_then(|c| c.plans.get(plan))
        else {
            return Named::Nothing;
        };
        let carrying: Vec<u32> = p
            .rows
            .iter()
            .filter(|r| r.written.iter().any(|w| w.digits == digits))
            .map(|r| r.position)
            .collect();
        match carrying.as_slice() {
            [one] => Named::Row(*one),
            [] => match digits.parse::<usize>().ok().and_then(|i| p.rows.get(i)) {
                Some(r) => Named::Row(r.position),
                None => Named::Nothing,
            },
            several => Named::Several(several.to_vec()),
        }
    }
}

/// `A | B`: a plan's verbs as its header writes them.
fn title(c: &Controller, p: &Plan) -> String {
    p.verbs
        .iter()
        .filter_map(|v| c.commands.get(v.index()))
        .map(|cmd| cmd.name.as_str())
        .collect::<Vec<_>>()
        .join(" | ")
}

/// The numbers written on `r`: its label's digits and its `*N`'s, found in
/// the text at the row's spans (a shared row carries none: a block's rows
/// may not be numbered).
fn written(set: &PlanSet, r: &Row) -> Vec<Written> {
    let mut out = Vec::new();
    if r.shared.is_some() {
        return out;
    }
    if let Some(span) = r.label_span {
        out.extend(digits_after(set, span.file, span.start as usize, 'E'));
    }
    if let From::DontCare(Some(_)) | From::Except(Some(_), _) = r.from {
        out.extend(digits_after(
            set,
            r.from_span.file,
            r.from_span.start as usize,
            '*',
        ));
    }
    out
}

/// The digits right after `prefix` at `at` in `file`, if the text is so.
fn digits_after(set: &PlanSet, file: FileId, at: usize, prefix: char) -> Option<Written> {
    let text = &set.sources.get(file).text;
    let rest = text.get(at..)?.strip_prefix(prefix)?;
    let len = rest.bytes().take_while(u8::is_ascii_digit).count();
    if len == 0 {
        return None;
    }
    let start = at + prefix.len_utf8();
    Some(Written {
        file,
        start,
        end: start + len,
        prefix,
        digits: without_leading_zeros(&rest[..len]),
    })
}

/// `007` → `7`, `0` → `0`: numbers compared as numbers, however long.
pub(super) fn without_leading_zeros(digits: &str) -> String {
    let trimmed = digits.trim_start_matches('0');
    if trimmed.is_empty() {
        "0".to_string()
    } else {
        trimmed.to_string()
    }
}

/// A row of `ir` whose written label or `*N` is not its position, named
/// for an error message.
pub(super) fn first_misnumbered(ir: &Ir) -> Option<String> {
    for c in &ir.controllers {
        for p in &c.plans {
            for r in &p.rows {
                let star = match r.from {
                    From::DontCare(n) | From::Except(n, _) => n,
                    _ => None,
                };
                if [r.label, star]
                    .into_iter()
                    .flatten()
                    .any(|n| n != r.position)
                {
                    return Some(format!(
                        "E{} of plan `{}` of `{}`",
                        r.position,
                        title(c, p),
                        c.name
                    ));
                }
            }
        }
    }
    None
}

/// `ir`'s meaning without the numbers written on rows (and without places).
pub(super) fn meaning(ir: &Ir) -> serde_json::Value {
    let mut ir = ir.clone();
    for c in &mut ir.controllers {
        for p in &mut c.plans {
            for r in &mut p.rows {
                r.label = None;
                match &mut r.from {
                    From::DontCare(n) | From::Except(n, _) => *n = None,
                    _ => {}
                }
            }
        }
    }
    super::super::meaning::without_places(&ir)
}
