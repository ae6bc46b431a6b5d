//! The scenario half of `--renumber`: each `fired:` of a step names a row
//! of the plan running in that step by its old number (`E3`, `"*3"`,
//! `"#3"`), which the scenario was written against; it gets the position
//! that row has now ([`super::numbers::Numbers::named`]), the rest of the
//! YAML text byte for byte as it was.
//!
//! Which plan runs in a step is followed from the commands the scenario
//! sends: a one-controller scenario's `command:`, a system scenario's
//! `commands:` (and `command:` of its one root). A verb with `accept when`
//! may be refused, so the plan before it stays possible; a controller no
//! step commands may run any of its plans. A name is changed only when
//! every possible plan says the same row; otherwise, or when two rows
//! carry its number, it is left and reported.

use super::numbers::{without_leading_zeros, Named, Numbers};
use super::{Relabel, Undecided};
use crate::ir::{CtrlId, Ir};
use crate::yaml::{Location, Spanned};
use serde::Deserialize;
use serde_json::Value as Json;
use std::collections::{BTreeMap, BTreeSet};

/// A scenario file as far as renumbering reads it (other keys ignored:
/// `rcsc test` judges them).
#[derive(Deserialize)]
struct RawFile {
    controller: Option<String>,
    system: Option<Json>,
    controllers: Option<Json>,
    #[serde(default)]
    steps: Vec<RawStep>,
}

#[derive(Deserialize)]
struct RawStep {
    command: Option<Json>,
    commands: Option<BTreeMap<String, Json>>,
}

/// The same file with the places of its `fired:` values.
#[derive(Deserialize)]
struct SpannedOne {
    #[serde(default)]
    steps: Vec<SpannedStep<ExpectOne>>,
}

#[derive(Deserialize)]
struct SpannedSystem {
    #[serde(default)]
    steps: Vec<SpannedStep<BTreeMap<String, ExpectOne>>>,
}

#[derive(Deserialize)]
struct SpannedStep<E> {
    expect: Option<E>,
}

#[derive(Deserialize)]
struct ExpectOne {
    fired: Option<Spanned<Json>>,
}

/// What renumbering did to one scenario file.
#[derive(Default)]
pub(super) struct Updated {
    /// The new text, when anything was read (possibly unchanged).
    pub(super) text: Option<String>,
    pub(super) renamed: Vec<Relabel>,
    pub(super) undecided: Vec<Undecided>,
}

/// One `fired:` to judge: the controller, the plans that may run, and the
/// value with its place.
struct Fired<'a> {
    controller: &'a str,
    plans: Option<BTreeSet<usize>>,
    value: &'a Spanned<Json>,
}

/// `text` with its `fired:` numbers moved to the rows' new positions.
pub(super) fn update(path: &str, text: &str, ir: &Ir, numbers: &Numbers) -> Updated {
    let mut out = Updated::default();
    let undecided = |line: usize, message: String| Undecided {
        path: path.to_string(),
        line,
        message,
    };
    let raw: RawFile = match crate::yaml::from_str_names(text) {
        Ok(raw) => raw,
        Err(e) => {
            let line = e.location.map_or(1, |l| l.line() as usize);
            out.undecided.push(undecided(
                line,
                format!(
                    "not read as a scenario ({}); its rows are left as written",
                    e.message
                ),
            ));
            return out;
        }
    };
    let system = raw.system.is_some() || raw.controllers.is_some();
    let running = running_plans(ir, &raw, system);
    let spanned = if system {
        crate::yaml::from_str_names::<SpannedSystem>(text).map(|s| {
            s.steps
                .into_iter()
                .map(|st| st.expect.unwrap_or_default())
                .collect::<Vec<_>>()
        })
    } else {
        crate::yaml::from_str_names::<SpannedOne>(text).map(|s| {
            let name = raw.controller.clone().unwrap_or_default();
            s.steps
                .into_iter()
                .map(|st| st.expect.map(|e| (name.clone(), e)).into_iter().collect())
                .collect::<Vec<BTreeMap<_, _>>>()
        })
    };
    let Ok(expects) = spanned else {
        out.undecided.push(undecided(
            1,
            "its `expect:` entries could not be read; its rows are left as written".into(),
        ));
        return out;
    };
    let mut edits = Vec::new();
    for (step, expect) in expects.iter().enumerate() {
        for (controller, e) in expect {
            let Some(value) = &e.fired else { continue };
            let plans = running
                .get(step)
                .and_then(|m| m.get(controller.as_str()))
                .cloned()
                .unwrap_or(None);
            let fired = Fired {
                controller,
                plans,
                value,
            };
            match judge(&fired, text, numbers) {
                Judged::Keep => {}
                Judged::Edit(edit, renamed) => {
                    edits.push(edit);
                    out.renamed.push(Relabel {
                        path: path.to_string(),
                        ..renamed
                    });
                }
                Judged::Undecided(line, message) => out.undecided.push(undecided(line, message)),
            }
        }
    }
    edits.sort_by_key(|e| e.0);
    edits.dedup_by_key(|e| e.0);
    out.text = Some(super::apply(
        text,
        edits.iter().map(|(s, e, t)| (*s, *e, t.as_str())),
    ));
    out
}

/// For each step, the plans each commanded controller may run in it
/// (`None`: any of its plans).
type Running<'a> = Vec<BTreeMap<&'a str, Option<BTreeSet<usize>>>>;

/// Which plans may run in each step, from the commands sent so far.
fn running_plans<'a>(ir: &'a Ir, raw: &RawFile, system: bool) -> Running<'a> {
    let mut now: BTreeMap<&str, Option<BTreeSet<usize>>> = BTreeMap::new();
    let root = if system {
        single_root(ir, raw)
    } else {
        raw.controller
            .as_deref()
            .and_then(|n| ir.controller_by_name(n))
    };
    let mut out = Vec::new();
    for step in &raw.steps {
        let mut sent: Vec<(CtrlId, &Json)> = Vec::new();
        if let (Some(c), Some(call)) = (root, &step.command) {
            sent.push((c, call));
        }
        for (name, call) in step.commands.iter().flatten() {
            if let Some(c) = ir.controller_by_name(name) {
                sent.push((c, call));
            }
        }
        for (c, call) in sent {
            let ctrl = ir.controller(c);
            let plans = now.entry(ctrl.name.as_str()).or_insert(None);
            let command = verb(call).and_then(|v| ctrl.commands.iter().find(|k| k.name == v));
            *plans = match command.and_then(|k| k.plan.map(|p| (p.index(), k.accept.is_some()))) {
                // Refusable: the plan before may go on.
                Some((p, true)) => plans.take().map(|mut set| {
                    set.insert(p);
                    set
                }),
                Some((p, false)) => Some(BTreeSet::from([p])),
                None => None,
            };
        }
        out.push(now.clone());
    }
    out
}

/// `VERB` or `{ VERB: { … } }`.
fn verb(call: &Json) -> Option<&str> {
    match call {
        Json::String(v) => Some(v),
        Json::Object(map) if map.len() == 1 => map.keys().next().map(String::as_str),
        _ => None,
    }
}

/// The one controller of a system scenario's run whose supervisor is not
/// in the run (the one `command:` goes to), if there is exactly one.
fn single_root(ir: &Ir, raw: &RawFile) -> Option<CtrlId> {
    let run: Vec<CtrlId> = match &raw.controllers {
        Some(Json::Array(names)) => names
            .iter()
            .filter_map(|n| n.as_str().and_then(|n| ir.controller_by_name(n)))
            .collect(),
        _ => (0..ir.controllers.len())
            .map(|i| CtrlId(i as u32))
            .collect(),
    };
    match crate::scenario::roots_of(ir, &run).as_slice() {
        [one] => Some(*one),
        _ => None,
    }
}

enum Judged {
    Keep,
    /// The digits' byte range, the new digits, and the report.
    Edit((usize, usize, String), Relabel),
    Undecided(usize, String),
}

/// What to do with one `fired:` value.
fn judge(f: &Fired<'_>, text: &str, numbers: &Numbers) -> Judged {
    let Json::String(name) = &f.value.value else {
        return Judged::Keep;
    };
    let Some((prefix, digits)) = numbered(name) else {
        // `none`, `otherwise`: not a number.
        return Judged::Keep;
    };
    let line = f.value.referenced.line() as usize;
    let Some(titles) = numbers.plan_titles(f.controller) else {
        return Judged::Keep;
    };
    let candidates: Vec<usize> = match &f.plans {
        Some(set) => set.iter().copied().collect(),
        None => (0..titles.len()).collect(),
    };
    let key = without_leading_zeros(digits);
    let named: Vec<(usize, Named)> = candidates
        .iter()
        .map(|&p| (p, numbers.named(f.controller, p, &key)))
        .filter(|(_, n)| *n != Named::Nothing)
        .collect();
    if let Some((p, Named::Several(rows))) =
        named.iter().find(|(_, n)| matches!(n, Named::Several(_)))
    {
        let rows: Vec<String> = rows.iter().map(|r| format!("E{r}")).collect();
        return Judged::Undecided(
            line,
            format!(
                "`fired: {name}`: `{prefix}{digits}` is written on {} rows of plan `{}` of `{}` (now {}); left as written, say which row is meant",
                rows.len(),
                titles[*p],
                f.controller,
                rows.join(" and ")
            ),
        );
    }
    let rows: BTreeSet<u32> = named
        .iter()
        .filter_map(|(_, n)| match n {
            Named::Row(r) => Some(*r),
            _ => None,
        })
        .collect();
    let new = match rows.len() {
        0 => return Judged::Keep,
        1 => rows.into_iter().next().unwrap_or_default(),
        _ => {
            let by_plan: Vec<String> = named
                .iter()
                .filter_map(|(p, n)| match n {
                    Named::Row(r) => Some(format!("`{}` E{r}", titles[*p])),
                    _ => None,
                })
                .collect();
            return Judged::Undecided(
                line,
                format!(
                    "`fired: {name}` of `{}`: the plans that may run in this step number it differently ({}); left as written",
                    f.controller,
                    by_plan.join(", ")
                ),
            );
        }
    };
    if new.to_string() == digits {
        return Judged::Keep;
    }
    let Some((start, end)) = digits_at(text, &f.value.referenced, prefix, digits) else {
        return Judged::Undecided(
            line,
            format!("`fired: {name}`: its text was not found where the YAML reader put it; left as written"),
        );
    };
    let plan = match named.as_slice() {
        [(p, _)] => titles[*p].to_string(),
        _ => named
            .iter()
            .map(|(p, _)| titles[*p])
            .collect::<Vec<_>>()
            .join(", "),
    };
    let edit = (start, end, new.to_string());
    let renamed = Relabel {
        controller: f.controller.to_string(),
        plan,
        path: String::new(),
        line,
        old: format!("{prefix}{digits}"),
        new: format!("{prefix}{new}"),
    };
    Judged::Edit(edit, renamed)
}

/// `E3`, `*3`, `#3` → (prefix, digits); anything else `None`.
fn numbered(name: &str) -> Option<(char, &str)> {
    let prefix = name
        .chars()
        .next()
        .filter(|c| matches!(c, 'E' | '*' | '#'))?;
    let digits = &name[1..];
    (!digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())).then_some((prefix, digits))
}

/// The byte range of `digits` in the scalar at `at` (plain or quoted),
/// checked against the text.
fn digits_at(text: &str, at: &Location, prefix: char, digits: &str) -> Option<(usize, usize)> {
    let start = match at.span().byte_offset() {
        Some(b) => usize::try_from(b).ok()?,
        None => {
            let line_start = text
                .split_inclusive('\n')
                .take((at.line() as usize).saturating_sub(1))
                .map(str::len)
                .sum::<usize>();
            let column = (at.column() as usize).saturating_sub(1);
            line_start
                + text
                    .get(line_start..)?
                    .chars()
                    .take(column)
                    .map(char::len_utf8)
                    .sum::<usize>()
        }
    };
    let rest = text.get(start..)?;
    let quote = usize::from(rest.starts_with(['"', '\'']));
    let scalar = rest.get(quote..)?.strip_prefix(prefix)?;
    let from = start + quote + prefix.len_utf8();
    let len = scalar.bytes().take_while(u8::is_ascii_digit).count();
    (scalar.get(..len) == Some(digits)).then_some((from, from + len))
}
