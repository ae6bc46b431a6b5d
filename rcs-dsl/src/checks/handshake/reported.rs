//! `status_never_reported`: a supervisor tests `X.status == S` (or
//! `X.done`) although no row of X that can fire, in the plans X runs for
//! the verbs the supervisor sends it, makes `S` visible. A `report S` in a
//! row that also ends the plan (`-> Done`, `-> Error`), or that a later
//! `report` of the same row follows, is replaced before the status buffer
//! is written (once per cycle, at its end): no supervisor ever sees it, and
//! the finding points at it. `EXECUTING` and `NOT_READY` come from the
//! handshake, never from a row, and a test of `ERROR` is defensive
//! handling: those three are not judged.

use super::super::Sink;
use super::{status_tests, verbs_sent_by, Summary};
use crate::diagnostic::Diagnostic;
use crate::ir::{CommandId, Controller, CtrlId, Ir, StatusId};
use crate::lint::Lint;
use crate::source::Span;

pub(crate) fn check_status_never_reported(
    ir: &Ir,
    ci: CtrlId,
    summaries: &[Summary],
    sink: &mut Sink,
) {
    let c = ir.controller(ci);
    for &x in &c.subordinates {
        // One supervisor only commands X (two is an error of its own).
        if ir.controller(x).supervisor != Some(ci) {
            continue;
        }
        let sent = verbs_sent_by(c, x);
        let Some((reported, for_any)) = statuses_reported(ir, c, summaries, x, &sent) else {
            continue;
        };
        for p in &c.plans {
            for r in &p.rows {
                for (status, span) in status_tests(r, x) {
                    // ERROR is not judged: testing it is the
                    // defensive handling `unhandled_error` asks for,
                    // worth keeping when X's plans change.
                    if status == StatusId::NOT_READY
                        || status == StatusId::EXECUTING
                        || status == StatusId::ERROR
                        || reported.contains(&status)
                    {
                        continue;
                    }
                    let why = match hidden_report(ir, summaries, x, &sent, status) {
                        Some((report, by)) => Unseen::Replaced { report, by },
                        None if for_any.contains(&status) => Unseen::NotWithArgs,
                        None => Unseen::NoRow,
                    };
                    let d = never_reported(ir, c, x, &sent, status, span, why);
                    sink.lint(Some(c), Some(p), d);
                }
            }
        }
    }
}

/// Why a supervisor never sees a status.
#[derive(Clone, Copy)]
enum Unseen {
    /// No row that can fire reports it.
    NoRow,
    /// A row reports it, and a later write of the same row replaces it.
    Replaced { report: Span, by: Span },
    /// Rows report it, but none can fire with the constant arguments sent.
    NotWithArgs,
}

fn never_reported(
    ir: &Ir,
    c: &Controller,
    x: CtrlId,
    sent: &[CommandId],
    status: StatusId,
    span: Span,
    why: Unseen,
) -> Diagnostic {
    let hidden = match why {
        Unseen::Replaced { report, by } => Some((report, by)),
        _ => None,
    };
    let by_args = matches!(why, Unseen::NotWithArgs);
    let xc = ir.controller(x);
    let sub = &xc.name;
    let name = &xc.statuses[status.index()].name;
    let verbs: Vec<String> = sent
        .iter()
        .map(|v| format!("`{}`", xc.commands[v.index()].name))
        .collect();
    let how = match status {
        StatusId::DONE => "ends in `Done`".to_string(),
        _ => format!("has `report {name}`"),
    };
    let note = if sent.is_empty() {
        format!(
            "`{}` never sends `{sub}` a command, so `{sub}` shows `NOT_READY` for ever",
            c.name
        )
    } else if by_args {
        format!(
            "`{}` sends {} with constant arguments only, and with those values no row of \
             `{sub}` that reports `{name}` can fire",
            c.name,
            verbs.join(", ")
        )
    } else if hidden.is_some() {
        format!(
            "`{sub}` writes its status once per cycle, at the end: a `report {name}` replaced \
             later in the same row never reaches the status buffer"
        )
    } else {
        let plural = if verbs.len() == 1 { "" } else { "s" };
        let verbs = verbs.join(", ");
        format!(
            "`{}` sends `{sub}` {verbs}; in `{sub}`'s plan{plural} for {verbs}, no row that can \
             fire {how}",
            c.name
        )
    };
    let mut d = Diagnostic::lint(
        Lint::StatusNeverReported,
        format!(
            "`{}` waits for `{sub}` to report `{name}`, which it never does",
            c.name
        ),
        span,
        format!("`{sub}` never reports `{name}`"),
    );
    if let Some((report, by)) = hidden {
        d = d
            .with_secondary(report, format!("`{sub}` reports `{name}` here…"))
            .with_secondary(by, "…and this replaces it in the same cycle");
    }
    d.with_note(note).with_help(match (status, hidden) {
        (_, Some(_)) => format!(
            "report `{name}` on a cycle of its own: in a row that stays, before the row that ends"
        ),
        (StatusId::DONE, None) => {
            format!("test a status `{sub}` reports, or give `{sub}`'s plan a way to `Done`")
        }
        _ => format!("test a status `{sub}` reports, or make a row of `{sub}` report `{name}`"),
    })
}

/// The statuses `x` makes visible, in the plans `x` runs for `verbs`;
/// `None` when a verb has no plan (nothing to judge). A verb `c` only
/// ever sends with constant arguments counts the statuses `x` makes
/// visible with those arguments; the second list counts every value.
fn statuses_reported(
    ir: &Ir,
    c: &Controller,
    summaries: &[Summary],
    x: CtrlId,
    verbs: &[CommandId],
) -> Option<(Vec<StatusId>, Vec<StatusId>)> {
    let s = &summaries[x.index()];
    let mut reported = Vec::new();
    let mut for_any = Vec::new();
    for v in verbs {
        let pid = ir.controller(x).commands[v.index()].plan?.index();
        let shown = sent_with(c, x, *v, s).unwrap_or_else(|| s.reported[pid].clone());
        for st in shown {
            if !reported.contains(&st) {
                reported.push(st);
            }
        }
        for &st in &s.reported[pid] {
            if !for_any.contains(&st) {
                for_any.push(st);
            }
        }
    }
    Some((reported, for_any))
}

/// When every send of `verb` from `c` to `x` has constant arguments: the
/// statuses `x` makes visible with them. `None` otherwise.
fn sent_with(c: &Controller, x: CtrlId, verb: CommandId, s: &Summary) -> Option<Vec<StatusId>> {
    let mut shown = Vec::new();
    for p in &c.plans {
        for r in &p.rows {
            for j in &r.jobs {
                if j.sends_to().is_none_or(|(sub, _)| sub != x)
                    || !j.commands_sent().contains(&verb)
                {
                    continue;
                }
                let (v, args) = super::rejected::constant_send(j, x)?;
                if v != verb {
                    return None;
                }
                let (.., with) = s
                    .reported_with
                    .iter()
                    .find(|(w, a, _)| *w == verb && *a == args)?;
                shown.extend(with.iter().copied());
            }
        }
    }
    Some(shown)
}

/// A `report status` of `x`'s plans for `verbs` that a later write of its
/// own row replaces: (the report, what replaces it).
fn hidden_report(
    ir: &Ir,
    summaries: &[Summary],
    x: CtrlId,
    verbs: &[CommandId],
    status: StatusId,
) -> Option<(Span, Span)> {
    verbs.iter().find_map(|v| {
        let pid = ir.controller(x).commands[v.index()].plan?.index();
        summaries[x.index()].overwritten[pid]
            .iter()
            .find(|(s, ..)| *s == status)
            .map(|&(_, report, by)| (report, by))
    })
}
