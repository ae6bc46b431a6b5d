//! `rcsc doc --diff`: the site's "Changes" page (`diff-changes.html`, at
//! the root) from a semantic diff ([`rcs_dsl::diff::PlanSetDiff`]) of the
//! documented plans against an older version — per changed plan its
//! diff-coloured state graph ([`crate::diff::diff_dot`]), its changed
//! rows, states and moves in precedence, and a link to its page; per
//! system the declarations changed and the findings introduced or removed.
//! Also the badges the index, controller and plan pages show when they
//! changed. A hyphen cannot occur in a controller's name, so the page can
//! never be a controller's.

use super::html::{esc, page};
use super::index::graph_or_notice;
use super::{ctrl_page, folder, plan_page, Changes, GraphSource, SetDoc, Site, Svgs};
use crate::diff::{changed_parts, item_label, item_line, move_line, presence, row_name, row_word};
use rcs_dsl::diff::{ControllerDiff, Finding, ItemChange, PlanDiff, RowChange, SystemDiff};
use rcs_dsl::ir::{Controller, Plan};
use std::fmt::Write;

/// The page, from the site's root.
pub(super) const CHANGES_PAGE: &str = "diff-changes.html";

/// The system diff of a documented set: by name, or the only one when
/// one set was compared with one (the diff pairs those whatever their
/// names).
fn system_of<'a>(site: &Site, changes: &'a Changes, set: &SetDoc) -> Option<&'a SystemDiff> {
    let systems = &changes.diff.systems;
    systems
        .iter()
        .find(|s| s.name == set.ir.system)
        .or_else(|| (site.sets.len() == 1 && systems.len() == 1).then(|| &systems[0]))
}

/// The documented set a system diff belongs to.
fn set_of<'s, 'a>(site: &'s Site<'a>, changes: &Changes, s: &SystemDiff) -> Option<&'s SetDoc<'a>> {
    site.sets
        .iter()
        .find(|set| system_of(site, changes, set).is_some_and(|d| std::ptr::eq(d, s)))
}

fn plan_anchor(system: &str, p: &PlanDiff) -> String {
    format!("plan-{system}.{}", p.name())
}

fn ctrl_anchor(system: &str, c: &ControllerDiff) -> String {
    format!("ctrl-{system}.{}", c.name)
}

fn graph_key(system: &str, p: &PlanDiff) -> String {
    format!("diff/{system}/{}", p.name())
}

/// The diff graph of every changed plan.
pub(super) fn graphs(changes: &Changes) -> Vec<GraphSource> {
    let mut out = Vec::new();
    for s in &changes.diff.systems {
        for p in s.controllers.iter().flat_map(|c| &c.plans) {
            out.push(GraphSource {
                key: graph_key(&s.name, p),
                dot: crate::diff::diff_dot(p, &changes.against),
            });
        }
    }
    out
}

/// The badge a changed controller's page shows (from its set's folder,
/// `root` leading back to the site's root).
pub(super) fn controller_badge(site: &Site, set: &SetDoc, ctrl: &Controller, root: &str) -> String {
    let Some(changes) = &site.changes else {
        return String::new();
    };
    let Some(s) = system_of(site, changes, set) else {
        return String::new();
    };
    match s.controllers.iter().find(|c| c.name == ctrl.name) {
        Some(c) => badge(root, &ctrl_anchor(&s.name, c)),
        None => String::new(),
    }
}

/// The badge a changed plan's page shows.
pub(super) fn plan_badge(
    site: &Site,
    set: &SetDoc,
    ctrl: &Controller,
    plan: &Plan,
    root: &str,
) -> String {
    let Some(changes) = &site.changes else {
        return String::new();
    };
    let verb = &ctrl.commands[plan.verb.index()].name;
    let found = system_of(site, changes, set).and_then(|s| {
        s.controllers
            .iter()
            .filter(|c| c.name == ctrl.name)
            .flat_map(|c| &c.plans)
            .find(|p| &p.verb == verb)
            .map(|p| plan_anchor(&s.name, p))
    });
    match found {
        Some(anchor) => badge(root, &anchor),
        None => String::new(),
    }
}

fn badge(root: &str, anchor: &str) -> String {
    format!(
        "<p class=\"badge\"><a href=\"{root}{CHANGES_PAGE}#{}\">changed in this diff</a></p>\n",
        esc(anchor)
    )
}

/// The index's line about the diff.
pub(super) fn index_banner(changes: &Changes) -> String {
    let plans: usize = changes
        .diff
        .systems
        .iter()
        .flat_map(|s| &s.controllers)
        .map(|c| c.plans.len())
        .sum();
    let what = if changes.diff.is_empty() {
        "no semantic change".to_string()
    } else {
        format!("{plans} plan{} changed", if plans == 1 { "" } else { "s" })
    };
    format!(
        "<p class=\"badge\"><a href=\"{CHANGES_PAGE}\">Changes against {}</a>: {what}.</p>\n",
        esc(&changes.against)
    )
}

/// The Changes page.
pub(super) fn changes_page(site: &Site, changes: &Changes, svgs: &Svgs) -> String {
    let mut body = format!(
        "<nav><a href=\"index.html\">index</a> › changes</nav>\n<p>What the plans documented here change against <code>{}</code>: rows added (green), removed (red, dashed), changed (orange) and moved in precedence (⇅, the most dangerous edit: it can change which row fires), states added and removed, declarations, and the findings of <code>rcsc check</code> the change introduced or removed.</p>\n",
        esc(&changes.against)
    );
    if changes.diff.is_empty() {
        body.push_str("<p>No semantic change.</p>\n");
    }
    for s in &changes.diff.systems {
        let set = set_of(site, changes, s);
        let folder = set.map(|set| folder(site, set)).unwrap_or_default();
        let _ = writeln!(
            body,
            "<section id=\"system-{}\">\n<h2>System {}{}</h2>",
            esc(&s.name),
            esc(&s.name),
            presence(s.presence)
        );
        items(&mut body, &s.items);
        if s.items.is_empty() && s.controllers.is_empty() {
            // A set added or removed whole: say so instead of an empty
            // heading.
            let line = match (s.presence, set) {
                (rcs_dsl::diff::Presence::Added, Some(set)) => {
                    let plans: usize = set.ir.controllers.iter().map(|c| c.plans.len()).sum();
                    format!(
                        "A new plan set: {} controller{}, {plans} plan{}; see <a href=\"index.html#set-{}\">its part of the index</a>.",
                        set.ir.controllers.len(),
                        if set.ir.controllers.len() == 1 { "" } else { "s" },
                        if plans == 1 { "" } else { "s" },
                        esc(&set.ir.system)
                    )
                }
                (rcs_dsl::diff::Presence::Removed, _) => format!(
                    "The plan set is gone: <code>{}</code> had it, the plans documented here do not.",
                    esc(&changes.against)
                ),
                _ => "Nothing changed in its declarations or plans.".to_string(),
            };
            let _ = writeln!(body, "<p class=\"whole-set\">{line}</p>");
        }
        for c in &s.controllers {
            let ctrl = set.and_then(|set| set.ir.controllers.iter().find(|k| k.name == c.name));
            let name = match ctrl {
                Some(k) => format!("<a href=\"{folder}{}\">{}</a>", ctrl_page(k), esc(&c.name)),
                None => esc(&c.name),
            };
            let _ = writeln!(
                body,
                "<h3 id=\"{}\">Controller {name}{}</h3>",
                esc(&ctrl_anchor(&s.name, c)),
                presence(c.presence)
            );
            items(&mut body, &c.items);
            for b in &c.blocks {
                let _ = writeln!(
                    body,
                    "<p class=\"block-change\">Rows <code>{}</code> changed, once for every plan that uses it: {}.</p>",
                    esc(&b.name),
                    esc(&b.plans.join("; "))
                );
            }
            for p in &c.plans {
                let plan = ctrl.and_then(|k| {
                    k.plans
                        .iter()
                        .find(|pl| k.commands[pl.verb.index()].name == p.verb)
                        .map(|pl| plan_page(k, pl))
                });
                plan_section(
                    &mut body,
                    &s.name,
                    p,
                    plan.map(|pg| format!("{folder}{pg}")),
                    svgs,
                );
            }
        }
        findings(&mut body, "Findings introduced", &s.findings_introduced);
        findings(&mut body, "Findings removed", &s.findings_removed);
        body.push_str("</section>\n");
    }
    page(&format!("Changes against {}", changes.against), "", &body)
}

fn plan_section(body: &mut String, system: &str, p: &PlanDiff, href: Option<String>, svgs: &Svgs) {
    let name = match &href {
        Some(h) => format!("<a href=\"{h}\">{}</a>", esc(&p.name())),
        None => esc(&p.name()),
    };
    let _ = writeln!(
        body,
        "<div class=\"changed-plan\" id=\"{}\">\n<h4>Plan {name}{}</h4>",
        esc(&plan_anchor(system, p)),
        presence(p.presence)
    );
    body.push_str(&graph_or_notice(
        svgs.get(&graph_key(system, p)),
        &format!("the changes of {}", p.name()),
    ));
    if !p.states_added.is_empty() || !p.states_removed.is_empty() {
        body.push_str("<ul class=\"states\">\n");
        for st in &p.states_added {
            let _ = writeln!(
                body,
                "<li class=\"added\">state <code>{}</code> added</li>",
                esc(st)
            );
        }
        for st in &p.states_removed {
            let _ = writeln!(
                body,
                "<li class=\"removed\">state <code>{}</code> removed</li>",
                esc(st)
            );
        }
        body.push_str("</ul>\n");
    }
    let changed: Vec<_> = p
        .rows
        .iter()
        .filter(|r| r.change != RowChange::Same || r.renumbered())
        .collect();
    if !changed.is_empty() {
        body.push_str("<table class=\"diff\">\n<tr><th>row</th><th>change</th><th>before</th><th>after</th></tr>\n");
        for r in changed {
            let word = row_word(r);
            let what = match &r.change {
                RowChange::Changed(_) => {
                    let parts: Vec<String> = changed_parts(r)
                        .into_iter()
                        .map(|(part, a, b)| {
                            format!(
                                "<div>{}: <code>{}</code> → <code>{}</code></div>",
                                esc(&part),
                                esc(&a),
                                esc(&b)
                            )
                        })
                        .collect();
                    format!("changed{}", parts.join(""))
                }
                _ => word.to_string(),
            };
            let side = |v: &Option<rcs_dsl::diff::RowView>| {
                v.as_ref()
                    .map(|v| format!("<code>{}</code>", esc(&v.content())))
                    .unwrap_or_default()
            };
            let _ = writeln!(
                body,
                "<tr class=\"{word}\"><td>{}</td><td>{what}</td><td>{}</td><td>{}</td></tr>",
                esc(&row_name(r)),
                side(&r.old),
                side(&r.new)
            );
        }
        body.push_str("</table>\n");
    }
    if !p.moves.is_empty() {
        body.push_str(
            "<p class=\"moved\"><b>⇅ Moved in precedence</b></p>\n<ul class=\"moves\">\n",
        );
        for m in &p.moves {
            let _ = writeln!(body, "<li>{}</li>", esc(&move_line(m)));
        }
        body.push_str("</ul>\n");
    }
    body.push_str("</div>\n");
}

fn items(body: &mut String, list: &[ItemChange]) {
    if list.is_empty() {
        return;
    }
    body.push_str("<ul class=\"items\">\n");
    for i in list {
        let (mark, _) = item_line(i);
        let class = match mark {
            '+' => "added",
            '-' => "removed",
            _ => "changed",
        };
        let _ = writeln!(
            body,
            "<li class=\"{class}\"><code>{}</code></li>",
            esc(&item_label(i))
        );
    }
    body.push_str("</ul>\n");
}

fn findings(body: &mut String, title: &str, list: &[Finding]) {
    if list.is_empty() {
        return;
    }
    let class = if title.ends_with("introduced") {
        "introduced"
    } else {
        "removed"
    };
    let _ = writeln!(body, "<h3>{title}</h3>\n<ul class=\"findings {class}\">");
    for f in list {
        let _ = writeln!(
            body,
            "<li><code>{}</code> {}: {}</li>",
            esc(&f.code),
            esc(&f.place()),
            super::markdown::message_html(&f.message)
        );
    }
    body.push_str("</ul>\n");
}
