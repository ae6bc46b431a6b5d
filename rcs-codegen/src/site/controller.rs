//! A controller's page: who commands it and whom it commands, its
//! commands (each linked to its plan), statuses, errors, buffers (each with
//! every reader and writer), vars, hooks, and the findings about it that
//! are on no plan.

use super::html::{docs, esc, finding, page};
use super::index::buffer_anchor;
use super::plan::Placed;
use super::{buffers_href, ctrl_page, plan_page, root_of, SetDoc, Site};
use rcs_dsl::ir::{BufferId, Controller, CtrlId, Job, Target};
use std::collections::BTreeMap;
use std::fmt::Write;

/// What the four statuses every controller has mean (statuses 0..=3).
const BUILTIN_STATUS: [&str; 4] = [
    "No command has arrived yet since the controller started.",
    "A command is being carried out: its plan has not reached <code>Done</code> or <code>Error</code>.",
    "The last command's plan reached <code>Done</code>.",
    "The last command's plan ended in <code>Error</code>, or the command was refused; the error code says why.",
];

/// The error codes the runtime gives every controller
/// ([`rcs_dsl::error_codes::BUILTIN`]), and when.
const BUILTIN_ERRORS: [(&str, &str); 4] = [
    (
        "UNKNOWN_COMMAND",
        "A command arrived for a verb this controller has no plan for.",
    ),
    (
        "INDEX_RANGE",
        "An index by a value fell outside its array; the plan ends here.",
    ),
    (
        "HOOK_PANIC",
        "A hand-written hook panicked; the executive caught it and ended the plan.",
    ),
    (
        "REFUSED",
        "A command's <code>accept when</code> condition was false: the command was refused.",
    ),
];

/// The rows that report each status and end with each error code, as
/// `(plan index, row position)`.
struct Uses {
    reports: BTreeMap<usize, Vec<(usize, u32)>>,
    errors: BTreeMap<usize, Vec<(usize, u32)>>,
}

impl Uses {
    fn of(c: &Controller) -> Uses {
        let mut uses = Uses {
            reports: BTreeMap::new(),
            errors: BTreeMap::new(),
        };
        for (pi, plan) in c.plans.iter().enumerate() {
            for row in &plan.rows {
                if let Target::Error(Some(e)) = row.to {
                    uses.errors
                        .entry(e.index())
                        .or_default()
                        .push((pi, row.position));
                }
                for job in &row.jobs {
                    if let Job::Report { status, error, .. } = job {
                        let rows = uses.reports.entry(status.index()).or_default();
                        if !rows.contains(&(pi, row.position)) {
                            rows.push((pi, row.position));
                        }
                        if let Some(e) = error {
                            uses.errors
                                .entry(e.index())
                                .or_default()
                                .push((pi, row.position));
                        }
                    }
                }
            }
        }
        uses
    }

    /// `<p>rows reporting it: AHEAD E3, …</p>`, each row a link; nothing for none.
    fn line(&self, what: &str, rows: Option<&Vec<(usize, u32)>>, c: &Controller) -> String {
        let Some(rows) = rows.filter(|r| !r.is_empty()) else {
            return String::new();
        };
        let links: Vec<String> = rows
            .iter()
            .map(|(pi, pos)| {
                let plan = &c.plans[*pi];
                format!(
                    "<a href=\"{}#row-E{pos}\">{} E{pos}</a>",
                    plan_page(c, plan),
                    esc(&c.commands[plan.verb.index()].name)
                )
            })
            .collect();
        format!("<p class=\"uses\">{what} {}</p>\n", links.join(", "))
    }
}

pub(super) fn controller_page(site: &Site, set: &SetDoc, ci: usize, placed: &Placed) -> String {
    let ir = set.ir;
    let c = &ir.controllers[ci];
    let root = root_of(site);
    let link = |id: CtrlId| {
        let o = ir.controller(id);
        format!("<a href=\"{}\">{}</a>", ctrl_page(o), esc(&o.name))
    };
    let mut body = format!(
        "<nav><a href=\"{root}index.html\">{}</a> › {}</nav>\n",
        esc(&ir.system),
        esc(&c.name)
    );
    body.push_str(&super::changes::controller_badge(site, set, c, root));
    if let Some(t) = &c.title {
        let _ = writeln!(body, "<p class=\"title\">{}</p>", esc(t));
    }
    body.push_str(&docs(&c.docs));
    if let Some(inst) = &c.instance_of {
        let mut line = format!(
            "An instance of controller type <a href=\"{}\"><code>{}</code></a>",
            super::types::type_page_name(&inst.ty),
            esc(&inst.ty)
        );
        let args: Vec<String> = inst
            .args
            .iter()
            .map(|(n, v)| format!("<code>{}: {}</code>", esc(n), esc(v)))
            .collect();
        if !args.is_empty() {
            let _ = write!(line, " with {}", args.join(", "));
        }
        let binds: Vec<String> = inst
            .bindings
            .iter()
            .map(|(l, g)| format!("<code>{}</code> is <code>{}</code>", esc(l), esc(g)))
            .collect();
        if !binds.is_empty() {
            let _ = write!(line, "; {}", binds.join(", "));
        }
        let _ = writeln!(body, "<p class=\"instance\">{line}.</p>");
    }
    let sup = c
        .supervisor
        .map(link)
        .unwrap_or_else(|| "the operator".into());
    let subs: Vec<String> = c.subordinates.iter().map(|s| link(*s)).collect();
    let _ = writeln!(
        body,
        "<p>Commanded by {sup}. Subordinates: {}.</p>",
        if subs.is_empty() {
            "none".to_string()
        } else {
            subs.join(", ")
        }
    );
    for d in placed.ctrls.get(&ci).into_iter().flatten() {
        body.push_str(&finding(d));
    }

    body.push_str("<h2>Commands</h2>\n<table>\n<tr><th>verb</th><th>parameters</th><th>plan</th><th>about</th></tr>\n");
    for k in &c.commands {
        let params: Vec<String> = k
            .params
            .iter()
            .map(|p| format!("{}: {}", p.name, rcs_dsl::type_name(ir, &p.ty)))
            .collect();
        let plan = match k.plan {
            Some(p) => format!(
                "<a href=\"{}\">state graph and table</a>",
                plan_page(c, &c.plans[p.index()])
            ),
            None => "—".into(),
        };
        // Refusal (step 3a) beside the verb's own words.
        let accept = k.accept.as_ref().map_or_else(String::new, |a| {
            let p = rcs_dsl::pretty::Printer::new(ir, c, None);
            format!(
                "<p>Accepted only when <code>{}</code>; otherwise refused (the sender sees ERROR, REFUSED; the running plan goes on).</p>",
                esc(&p.expr(&a.cond))
            )
        });
        let _ = writeln!(
            body,
            "<tr id=\"cmd-{}\"><td><b>{}</b></td><td><code>{}</code></td><td>{plan}</td><td>{}{accept}</td></tr>",
            esc(&k.name),
            esc(&k.name),
            esc(&params.join(", ")),
            docs(&k.docs)
        );
    }
    body.push_str("</table>\n");

    let named = |title: &str, rows: Vec<(String, String)>| -> String {
        if rows.is_empty() {
            return String::new();
        }
        let mut s = format!("<h2>{title}</h2>\n<table>\n");
        for (name, about) in rows {
            let _ = writeln!(s, "<tr><td><b>{name}</b></td><td>{about}</td></tr>");
        }
        s.push_str("</table>\n");
        s
    };
    let uses = Uses::of(c);
    body.push_str(&named(
        "Statuses",
        c.statuses
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let about = match BUILTIN_STATUS.get(k) {
                    Some(meaning) => format!("<p class=\"docs\">{meaning}</p>\n"),
                    None => docs(&s.docs),
                };
                let by = uses.line("rows reporting it:", uses.reports.get(&k), c);
                (esc(&s.name), format!("{about}{by}"))
            })
            .collect(),
    ));
    let mut errors: Vec<(String, String)> = c
        .errors
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let by = uses.line("rows ending with it:", uses.errors.get(&k), c);
            (esc(&e.name), format!("{}{by}", docs(&e.docs)))
        })
        .collect();
    errors.extend(BUILTIN_ERRORS.iter().map(|(name, meaning)| {
        (
            format!("{name} <small>(built in)</small>"),
            format!("<p class=\"docs\">{meaning}</p>\n"),
        )
    }));
    body.push_str(&named("Errors", errors));

    let buffer = |b: BufferId, how: &str| {
        let buf = &ir.buffers[b.index()];
        let writer = buf
            .writer
            .map(link)
            .unwrap_or_else(|| "an external input".into());
        let readers: Vec<String> = buf.readers.iter().map(|r| link(*r)).collect();
        let about = c
            .buffer_docs
            .iter()
            .find(|(id, _)| *id == b)
            .map(|(_, d)| docs(d))
            .unwrap_or_default();
        (
            format!(
                "<a href=\"{root}{}#{}\">{}</a>",
                buffers_href(site, set, b.index()),
                esc(&buffer_anchor(ir, &buf.name)),
                esc(&buf.name)
            ),
            format!(
                "{how} · <code>{}</code> · written by {writer} · read by {}{about}",
                esc(&ir.buffer_types[buf.ty.index()].name),
                if readers.is_empty() {
                    "no one".to_string()
                } else {
                    readers.join(", ")
                }
            ),
        )
    };
    let mut bufs: Vec<(String, String)> = c.reads.iter().map(|b| buffer(*b, "reads")).collect();
    bufs.extend(c.writes.iter().map(|b| buffer(*b, "writes")));
    body.push_str(&named("Buffers", bufs));
    body.push_str(&named(
        "Vars",
        c.vars
            .iter()
            .map(|v| {
                (
                    esc(&v.name),
                    format!(
                        "<code>{}</code>{}",
                        esc(&rcs_dsl::type_name(ir, &v.ty)),
                        docs(&v.docs)
                    ),
                )
            })
            .collect(),
    ));
    body.push_str(&named(
        "Hooks",
        c.hooks
            .iter()
            .map(|h| {
                let params: Vec<String> = h
                    .params
                    .iter()
                    .map(|p| format!("{}: {}", p.name, rcs_dsl::type_name(ir, &p.ty)))
                    .collect();
                let ret = match h.ret {
                    rcs_dsl::ir::Type::Unit => String::new(),
                    ref t => format!(" -> {}", rcs_dsl::type_name(ir, t)),
                };
                (
                    esc(&h.name),
                    format!(
                        "<code>({}){}</code>{}",
                        esc(&params.join(", ")),
                        esc(&ret),
                        docs(&h.docs)
                    ),
                )
            })
            .collect(),
    ));
    page(&c.name, root, &body)
}
