//! The site's root: `index.html` (per plan set its hierarchy graph, its
//! controllers and its buffers, each buffer with its writer and readers;
//! for a large set the clusters of [`super::clusters`] instead) and
//! `search.js`, the search index pages load when the search box is used.

use super::html::{esc, finding, page};
use super::plan::Placed;
use super::{buffers_href, clusters, ctrl_page, folder, hierarchy_key, plan_page, svg, Site, Svgs};
use rcs_dsl::ir::Ir;
use rcs_dsl::{Diagnostic, Severity};
use std::fmt::Write;

/// The anchor of a buffer in the index.
pub(super) fn buffer_anchor(ir: &Ir, name: &str) -> String {
    format!("b-{}.{name}", ir.system)
}

/// A graph's SVG, or the notice that stands for it. The SVG is shrunk to
/// the page's width but not below the width that keeps its smallest text
/// at 10 px (`--min-width`, see `site.css`; the box scrolls past it), and
/// `site.js` gives it a full-size view.
pub(super) fn graph_or_notice(svg: Option<&String>, what: &str) -> String {
    match svg {
        Some(s) => {
            let s = svg::inline(s);
            let style = svg::min_width_px(s)
                .map(|px| format!(" style=\"--min-width: {px}px\""))
                .unwrap_or_default();
            format!("<div class=\"graph\"{style}>\n{s}\n</div>\n")
        }
        None => format!(
            "<p class=\"notice\">No drawing of {}: Graphviz <code>dot</code> was not found when the site was built. Install Graphviz (e.g. <code>apt-get install graphviz</code>) and run <code>rcsc doc</code> again.</p>\n",
            esc(what)
        ),
    }
}

pub(super) fn index_page(site: &Site, svgs: &Svgs, placed: &[Placed]) -> String {
    let mut body = String::new();
    if let Some(c) = &site.changes {
        body.push_str(&super::changes::index_banner(c));
    }
    body.push_str(&contents(site));
    for (set, placed) in site.sets.iter().zip(placed) {
        let ir = set.ir;
        let folder = folder(site, set);
        let _ = writeln!(body, "<section id=\"set-{}\">", esc(&ir.system));
        let _ = writeln!(
            body,
            "<h2>Plan set {} {}</h2>",
            esc(&ir.system),
            Counts::of(set.findings.iter()).badge("")
        );
        if let Some(r) = set.runs {
            let _ = writeln!(
                body,
                "<p class=\"runs\">Row hits and cycles per state from {}.</p>",
                esc(&r.source)
            );
        }
        if clusters::is_large(ir) {
            body.push_str(&clusters::index_section(site, set, svgs, placed));
            body.push_str("</section>\n");
            continue;
        }
        body.push_str(&graph_or_notice(
            svgs.get(&hierarchy_key(&folder)),
            &format!("the {} hierarchy", ir.system),
        ));
        for d in &placed.set {
            body.push_str(&finding(d));
        }
        let all: Vec<usize> = (0..ir.controllers.len()).collect();
        body.push_str(&controllers_table(ir, &folder, &all, Some(placed)));
        let buffers: Vec<usize> = (0..ir.buffers.len()).collect();
        body.push_str(&buffers_table(ir, &folder, &buffers));
        body.push_str("</section>\n");
    }
    page("Plans", "", &body)
}

/// How many findings, by severity.
#[derive(Default)]
pub(super) struct Counts {
    errors: usize,
    warnings: usize,
    notes: usize,
}

impl Counts {
    pub(super) fn of<'a>(findings: impl Iterator<Item = &'a Diagnostic>) -> Counts {
        let mut c = Counts::default();
        for d in findings {
            match d.severity {
                Severity::Error => c.errors += 1,
                Severity::Warning => c.warnings += 1,
                Severity::Note => c.notes += 1,
            }
        }
        c
    }

    /// `2 warnings · 1 note`, linked to `href` (unless empty), or a quiet
    /// `no findings`.
    pub(super) fn badge(&self, href: &str) -> String {
        let mut parts = Vec::new();
        for (n, one, class) in [
            (self.errors, "error", "error"),
            (self.warnings, "warning", "warning"),
            (self.notes, "note", "note"),
        ] {
            if n > 0 {
                parts.push(format!(
                    "<span class=\"count {class}\">{n} {one}{}</span>",
                    if n == 1 { "" } else { "s" }
                ));
            }
        }
        if parts.is_empty() {
            return "<span class=\"count none\">no findings</span>".into();
        }
        let text = parts.join(" · ");
        if href.is_empty() {
            text
        } else {
            format!("<a href=\"{href}\">{text}</a>")
        }
    }
}

/// The table of contents at the top of the index: each plan set with its
/// findings, and the Changes page when there is one.
fn contents(site: &Site) -> String {
    let mut out = String::from("<nav class=\"toc\">\n<h2>Contents</h2>\n<ul>\n");
    for set in &site.sets {
        let plans: usize = set.ir.controllers.iter().map(|c| c.plans.len()).sum();
        let _ = writeln!(
            out,
            "<li><a href=\"#set-{0}\">{0}</a> — {1} controller{2}, {plans} plan{3} — {4}</li>",
            esc(&set.ir.system),
            set.ir.controllers.len(),
            if set.ir.controllers.len() == 1 {
                ""
            } else {
                "s"
            },
            if plans == 1 { "" } else { "s" },
            Counts::of(set.findings.iter()).badge(&format!("#set-{}", esc(&set.ir.system)))
        );
    }
    if site.changes.is_some() {
        let _ = writeln!(
            out,
            "<li><a href=\"{}\">Changes</a></li>",
            super::changes::CHANGES_PAGE
        );
    }
    out.push_str("</ul>\n</nav>\n");
    out
}

/// The table of the controllers `members` (indexes), linking to their
/// pages through `prefix` (the set's folder, from the page).
pub(super) fn controllers_table(
    ir: &Ir,
    prefix: &str,
    members: &[usize],
    counts: Option<&Placed>,
) -> String {
    let mut out = String::new();
    out.push_str("<h3>Controllers</h3>\n<table>\n<tr><th>controller</th><th>title</th><th>CPU</th><th>supervisor</th><th>plans</th>");
    if counts.is_some() {
        out.push_str("<th>findings</th>");
    }
    out.push_str("</tr>\n");
    // With several processes, the CPU column names the process too.
    let distributed = rcs_dsl::placement::Placement::of(ir).is_distributed();
    for &ci in members {
        let c = &ir.controllers[ci];
        let cpu = ir
            .schedule
            .iter()
            .find(|cpu| cpu.order.iter().any(|o| o.index() == ci))
            .map(|cpu| {
                if distributed {
                    format!("{} (process {})", cpu.name, ir.process_of(cpu))
                } else {
                    cpu.name.clone()
                }
            })
            .unwrap_or_else(|| "—".into());
        let sup = match c.supervisor {
            Some(s) => {
                let s = ir.controller(s);
                format!("<a href=\"{prefix}{}\">{}</a>", ctrl_page(s), esc(&s.name))
            }
            None => "the operator".into(),
        };
        let plans: Vec<String> = c
            .plans
            .iter()
            .map(|p| {
                format!(
                    "<a href=\"{prefix}{}\">{}</a>",
                    plan_page(c, p),
                    esc(&c.commands[p.verb.index()].name)
                )
            })
            .collect();
        let mut title = esc(c.title.as_deref().unwrap_or(""));
        if let Some(inst) = &c.instance_of {
            let _ = write!(
                title,
                "{}<a href=\"{prefix}{}\">{}</a> instance",
                if title.is_empty() { "" } else { " — " },
                super::types::type_page_name(&inst.ty),
                esc(&inst.ty)
            );
        }
        let findings = match counts {
            Some(placed) => format!(
                "<td>{}</td>",
                Counts::of(placed.of_controller(ci)).badge(&format!("{prefix}{}", ctrl_page(c)))
            ),
            None => String::new(),
        };
        let _ = writeln!(
            out,
            "<tr><td><a href=\"{prefix}{}\">{}</a></td><td>{}</td><td>{}</td><td>{sup}</td><td>{}</td>{findings}</tr>",
            ctrl_page(c),
            esc(&c.name),
            title,
            esc(&cpu),
            plans.join(" ")
        );
    }
    out.push_str("</table>\n");
    out
}

/// The table of the buffers `which` (indexes) with the writer and readers
/// of each (nothing when there are none); `prefix` as for
/// [`controllers_table`].
pub(super) fn buffers_table(ir: &Ir, prefix: &str, which: &[usize]) -> String {
    let mut out = String::new();
    if !which.is_empty() {
        out.push_str("<h3>Buffers</h3>\n<table>\n<tr><th>buffer</th><th>type</th><th>written by</th><th>read by</th></tr>\n");
        for b in which.iter().filter_map(|b| ir.buffers.get(*b)) {
            let link = |c: rcs_dsl::ir::CtrlId| {
                let c = ir.controller(c);
                format!("<a href=\"{prefix}{}\">{}</a>", ctrl_page(c), esc(&c.name))
            };
            let writer = b
                .writer
                .map(link)
                .unwrap_or_else(|| "an external input".into());
            let readers: Vec<String> = b.readers.iter().map(|r| link(*r)).collect();
            let _ = writeln!(
                out,
                "<tr id=\"{}\"><td>{}</td><td>{}</td><td>{writer}</td><td>{}</td></tr>",
                esc(&buffer_anchor(ir, &b.name)),
                esc(&b.name),
                esc(&ir.buffer_types[b.ty.index()].name),
                readers.join(", ")
            );
        }
        out.push_str("</table>\n");
    }
    out
}

/// A JSON string literal.
fn json(s: &str) -> String {
    serde_json::Value::from(s).to_string()
}

/// The search index: every controller, verb, buffer and state with the
/// page (from the root) that shows it, as a JSON array in a script.
pub(super) fn search_js(site: &Site) -> String {
    let mut entries: Vec<(String, &str, String)> = Vec::new();
    for set in &site.sets {
        let ir = set.ir;
        let folder = folder(site, set);
        for c in &ir.controllers {
            entries.push((
                c.name.clone(),
                "controller",
                format!("{folder}{}", ctrl_page(c)),
            ));
            for k in &c.commands {
                let href = match k.plan {
                    Some(p) => format!("{folder}{}", plan_page(c, &c.plans[p.index()])),
                    None => format!("{folder}{}#cmd-{}", ctrl_page(c), k.name),
                };
                entries.push((format!("{}.{}", c.name, k.name), "verb", href));
            }
            for p in &c.plans {
                for s in &p.states {
                    entries.push((
                        format!("{}.{}.{}", c.name, c.commands[p.verb.index()].name, s.name),
                        "state",
                        format!("{folder}{}#state-{}", plan_page(c, p), s.name),
                    ));
                }
            }
        }
        for (bi, b) in ir.buffers.iter().enumerate() {
            entries.push((
                b.name.clone(),
                "buffer",
                format!(
                    "{}#{}",
                    buffers_href(site, set, bi),
                    buffer_anchor(ir, &b.name)
                ),
            ));
        }
    }
    let mut out = format!("// {}\nwindow.RCS_SEARCH = [\n", crate::GENERATED);
    for (i, (name, kind, href)) in entries.iter().enumerate() {
        let comma = if i + 1 < entries.len() { "," } else { "" };
        let _ = writeln!(out, "[{},{},{}]{comma}", json(name), json(kind), json(href));
    }
    out.push_str("];\n");
    out
}
