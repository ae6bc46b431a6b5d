//! The site's root: `index.html` (per plan set its hierarchy graph, its
//! controllers and its buffers, each buffer with its writer and readers)
//! and `search.js`, the search index every page loads.

use super::html::{esc, finding, page};
use super::plan::Placed;
use super::{ctrl_page, folder, hierarchy_key, plan_page, svg, Site, Svgs};
use rcs_dsl::ir::Ir;
use std::fmt::Write;

/// The anchor of a buffer in the index.
pub(super) fn buffer_anchor(ir: &Ir, name: &str) -> String {
    format!("b-{}.{name}", ir.system)
}

/// A graph's SVG, or the notice that stands for it.
pub(super) fn graph_or_notice(svg: Option<&String>, what: &str) -> String {
    match svg {
        Some(s) => format!("<div class=\"graph\">\n{}\n</div>\n", svg::inline(s)),
        None => format!(
            "<p class=\"notice\">No drawing of {}: Graphviz <code>dot</code> was not found when the site was built. Install Graphviz (e.g. <code>apt-get install graphviz</code>) and run <code>rcsc doc</code> again.</p>\n",
            esc(what)
        ),
    }
}

pub(super) fn index_page(site: &Site, svgs: &Svgs, placed: &[Placed]) -> String {
    let mut body = String::new();
    for (set, placed) in site.sets.iter().zip(placed) {
        let ir = set.ir;
        let folder = folder(site, set);
        let _ = writeln!(body, "<section id=\"set-{}\">", esc(&ir.system));
        let _ = writeln!(body, "<h2>Plan set {}</h2>", esc(&ir.system));
        if let Some(r) = set.runs {
            let _ = writeln!(
                body,
                "<p class=\"runs\">Row hits and cycles per state from {}.</p>",
                esc(&r.source)
            );
        }
        body.push_str(&graph_or_notice(
            svgs.get(&hierarchy_key(&folder)),
            &format!("the {} hierarchy", ir.system),
        ));
        for d in &placed.set {
            body.push_str(&finding(d));
        }
        body.push_str("<h3>Controllers</h3>\n<table>\n<tr><th>controller</th><th>title</th><th>CPU</th><th>supervisor</th><th>plans</th></tr>\n");
        // With several processes, the CPU column names the process too.
        let distributed = rcs_dsl::placement::Placement::of(ir).is_distributed();
        for (ci, c) in ir.controllers.iter().enumerate() {
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
                    format!("<a href=\"{folder}{}\">{}</a>", ctrl_page(s), esc(&s.name))
                }
                None => "the operator".into(),
            };
            let plans: Vec<String> = c
                .plans
                .iter()
                .map(|p| {
                    format!(
                        "<a href=\"{folder}{}\">{}</a>",
                        plan_page(c, p),
                        esc(&c.commands[p.verb.index()].name)
                    )
                })
                .collect();
            let _ = writeln!(
                body,
                "<tr><td><a href=\"{folder}{}\">{}</a></td><td>{}</td><td>{}</td><td>{sup}</td><td>{}</td></tr>",
                ctrl_page(c),
                esc(&c.name),
                esc(c.title.as_deref().unwrap_or("")),
                esc(&cpu),
                plans.join(" ")
            );
        }
        body.push_str("</table>\n");
        if !ir.buffers.is_empty() {
            body.push_str("<h3>Buffers</h3>\n<table>\n<tr><th>buffer</th><th>type</th><th>written by</th><th>read by</th></tr>\n");
            for b in &ir.buffers {
                let link = |c: rcs_dsl::ir::CtrlId| {
                    let c = ir.controller(c);
                    format!("<a href=\"{folder}{}\">{}</a>", ctrl_page(c), esc(&c.name))
                };
                let writer = b
                    .writer
                    .map(link)
                    .unwrap_or_else(|| "an external input".into());
                let readers: Vec<String> = b.readers.iter().map(|r| link(*r)).collect();
                let _ = writeln!(
                    body,
                    "<tr id=\"{}\"><td>{}</td><td>{}</td><td>{writer}</td><td>{}</td></tr>",
                    esc(&buffer_anchor(ir, &b.name)),
                    esc(&b.name),
                    esc(&ir.buffer_types[b.ty.index()].name),
                    readers.join(", ")
                );
            }
            body.push_str("</table>\n");
        }
        body.push_str("</section>\n");
    }
    page("Plans", "", &body)
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
        for b in &ir.buffers {
            entries.push((
                b.name.clone(),
                "buffer",
                format!("index.html#{}", buffer_anchor(ir, &b.name)),
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
