//! A plan's page: its state graph (linked), its states (with the cycles
//! runs spent there), its state table (doc comments, hits, the findings of
//! `rcsc check` on the row they concern) and its source lines. Every row
//! links to its edge and its source line; every edge, node and source line
//! links back. Also where each finding goes ([`place_findings`]).

use super::html::{docs, esc, finding, page};
use super::index::graph_or_notice;
use super::{ctrl_page, root_of, SetDoc, Site};
use crate::table::next_and_jobs;
use rcs_dsl::ir::{Controller, From, Plan, StateId, Target};
use rcs_dsl::pretty::Printer;
use rcs_dsl::source::Span;
use rcs_dsl::Diagnostic;
use std::collections::BTreeMap;
use std::fmt::Write;

/// The findings of one plan set, each on the most precise thing its
/// primary label lies in: a row, else a plan, else a controller, else the
/// set.
#[derive(Default)]
pub(super) struct Placed<'a> {
    pub set: Vec<&'a Diagnostic>,
    pub ctrls: BTreeMap<usize, Vec<&'a Diagnostic>>,
    pub plans: BTreeMap<(usize, usize), Vec<&'a Diagnostic>>,
    pub rows: BTreeMap<(usize, usize, usize), Vec<&'a Diagnostic>>,
}

impl<'a> Placed<'a> {
    /// The rows of plan `pi` of controller `ci` with a finding, by name,
    /// each with the most severe finding's severity.
    pub(super) fn row_severities(
        &self,
        ci: usize,
        pi: usize,
        plan: &rcs_dsl::ir::Plan,
    ) -> BTreeMap<String, &'static str> {
        let mut out = BTreeMap::new();
        for ((_, _, ri), ds) in self.rows.range((ci, pi, 0)..(ci, pi + 1, 0)) {
            let Some(row) = plan.rows.get(*ri) else {
                continue;
            };
            let worst = ds.iter().map(|d| d.severity).min_by_key(|s| match s {
                rcs_dsl::Severity::Error => 0,
                rcs_dsl::Severity::Warning => 1,
                rcs_dsl::Severity::Note => 2,
            });
            if let Some(sev) = worst {
                out.insert(row.display_name(), sev.as_str());
            }
        }
        out
    }

    /// Every finding placed on controller `ci`: on it, its plans and rows.
    pub(super) fn of_controller(&self, ci: usize) -> impl Iterator<Item = &'a Diagnostic> + '_ {
        let on = self.ctrls.get(&ci).into_iter().flatten();
        let plans = self
            .plans
            .range((ci, 0)..(ci + 1, 0))
            .flat_map(|(_, v)| v.iter());
        let rows = self
            .rows
            .range((ci, 0, 0)..(ci + 1, 0, 0))
            .flat_map(|(_, v)| v.iter());
        on.chain(plans).chain(rows).copied()
    }
}

fn inside(outer: Span, inner: Span) -> bool {
    outer.file == inner.file
        && outer.start <= inner.start
        && inner.start < outer.end.max(outer.start + 1)
}

pub(super) fn place_findings<'a>(set: &SetDoc<'a>) -> Placed<'a> {
    let mut placed = Placed::default();
    for d in set.findings {
        let Some(label) = d.labels.iter().find(|l| l.primary).or(d.labels.first()) else {
            placed.set.push(d);
            continue;
        };
        let at = label.span;
        let Some(ci) = set.ir.controllers.iter().position(|c| inside(c.span, at)) else {
            placed.set.push(d);
            continue;
        };
        let ctrl = &set.ir.controllers[ci];
        let Some(pi) = ctrl.plans.iter().position(|p| inside(p.span, at)) else {
            placed.ctrls.entry(ci).or_default().push(d);
            continue;
        };
        match ctrl.plans[pi].rows.iter().position(|r| inside(r.span, at)) {
            Some(ri) => placed.rows.entry((ci, pi, ri)).or_default().push(d),
            None => placed.plans.entry((ci, pi)).or_default().push(d),
        }
    }
    placed
}

/// 1-based line of a byte offset.
pub(super) fn line_of(text: &str, offset: u32) -> usize {
    let end = (offset as usize).min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The `id`s of the drawn edges and nodes, by row or state name: which
/// element of the SVG to link a row or state to (an edge may draw several
/// rows).
fn drawn(svg: Option<&String>, prefix: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let Some(svg) = svg else { return out };
    let mut rest = svg.as_str();
    while let Some(at) = rest.find(" id=\"") {
        let value = &rest[at + 5..];
        let Some(len) = value.find('"') else { break };
        // Graphviz writes `-` in ids as `&#45;`.
        let id = value[..len].replace("&#45;", "-");
        if let Some(names) = id.strip_prefix(prefix) {
            let names: Vec<&str> = if prefix == "edge-" {
                names.split('-').collect()
            } else {
                vec![names]
            };
            for n in names {
                out.entry(n.to_string()).or_insert_with(|| id.clone());
            }
        }
        rest = &value[len..];
    }
    out
}

pub(super) fn plan_page(
    site: &Site,
    set: &SetDoc,
    ci: usize,
    pi: usize,
    svg: Option<&String>,
    placed: &Placed,
) -> String {
    let ir = set.ir;
    let ctrl = &ir.controllers[ci];
    let plan = &ctrl.plans[pi];
    let verb = &ctrl.commands[plan.verb.index()];
    let root = root_of(site);
    let text = set
        .sources
        .get(plan.span.file.0 as usize)
        .copied()
        .unwrap_or("");
    let file = ir
        .files
        .get(plan.span.file.0 as usize)
        .map(String::as_str)
        .unwrap_or("");
    let mut body = format!(
        "<nav><a href=\"{root}index.html\">{}</a> › <a href=\"{}\">{}</a> › {}</nav>\n",
        esc(&ir.system),
        ctrl_page(ctrl),
        esc(&ctrl.name),
        esc(&verb.name)
    );
    body.push_str(&super::changes::plan_badge(site, set, ctrl, plan, root));
    body.push_str(&docs(&verb.docs));
    body.push_str(&docs(&plan.docs));
    if let Some(r) = set.runs {
        let _ = writeln!(
            body,
            "<p class=\"runs\">Hits and cycles from {}; edges are drawn heavier the more their rows fired, rows that never fired are marked.</p>",
            esc(&r.source)
        );
    }
    for d in placed.plans.get(&(ci, pi)).into_iter().flatten() {
        body.push_str(&finding(d));
    }
    body.push_str(&graph_or_notice(
        svg,
        &format!("{}.{}", ctrl.name, verb.name),
    ));
    states(&mut body, ctrl, plan, set, svg, text);
    rows(&mut body, set, ci, pi, svg, placed);
    source(&mut body, plan, text, file);
    page(&format!("{}.{}", ctrl.name, verb.name), root, &body)
}

fn states(
    body: &mut String,
    ctrl: &Controller,
    plan: &Plan,
    set: &SetDoc,
    svg: Option<&String>,
    text: &str,
) {
    let nodes = drawn(svg, "node-");
    body.push_str("<h2>States</h2>\n<ul class=\"states\">\n");
    let p = Printer::new(set.ir, ctrl, Some(plan));
    let mut names: Vec<String> = plan.states.iter().map(|s| s.name.clone()).collect();
    for terminal in ["Done", "Error"] {
        let reached = plan.rows.iter().any(|r| match r.to {
            Target::Done => terminal == "Done",
            Target::Error(_) | Target::ErrorOf(_) => terminal == "Error",
            _ => false,
        });
        if reached {
            names.push(terminal.to_string());
        }
    }
    let row_link = |r: &rcs_dsl::ir::Row| {
        format!(
            "<a href=\"#row-{}\">{}</a>",
            r.display_name(),
            esc(&p.label(r))
        )
    };
    for (i, name) in names.iter().enumerate() {
        let _ = write!(body, "<li id=\"state-{}\"><b>{}</b>", esc(name), esc(name));
        if let Some(node) = nodes.get(name) {
            let _ = write!(body, " <a href=\"#{}\">graph</a>", esc(node));
        }
        if let Some(Some(span)) = plan.states.get(i).map(|s| s.span) {
            let _ = write!(
                body,
                " <a href=\"#L{}\">line {}</a>",
                line_of(text, span.start),
                line_of(text, span.start)
            );
        }
        if let (Some(r), Some(_)) = (set.runs, plan.states.get(i)) {
            let n = r.state(&ctrl.name, plan.verb.0, i as u32);
            let _ = write!(body, " <span class=\"cycles\">{n} cycles</span>");
        }
        let from: Vec<String> = plan
            .rows
            .iter()
            .filter(|r| r.from.names(StateId(i as u32)))
            .map(row_link)
            .collect();
        if !from.is_empty() {
            let _ = write!(body, " — rows: {}", from.join(" "));
        }
        if i == 0 && !nodes.contains_key(name) {
            // S0 is where every command starts; the graph draws the rows
            // that leave it as their own `*N` nodes (or from the states
            // they name), so S0 has no circle: say so where it is listed.
            let entry: Vec<String> = plan
                .rows
                .iter()
                .filter(|r| r.is_entry && r.from.applies_in(StateId(0)))
                .map(row_link)
                .collect();
            let _ = write!(
                body,
                " — where every command starts; not drawn as a state: {}",
                if entry.is_empty() {
                    "the rows that apply in every state leave it".to_string()
                } else {
                    format!(
                        "the entry row{} {} leave{} it",
                        if entry.len() == 1 { "" } else { "s" },
                        entry.join(" "),
                        if entry.len() == 1 { "s" } else { "" }
                    )
                }
            );
        }
        body.push_str("</li>\n");
    }
    body.push_str("</ul>\n");
}

fn rows(
    body: &mut String,
    set: &SetDoc,
    ci: usize,
    pi: usize,
    svg: Option<&String>,
    placed: &Placed,
) {
    let ctrl = &set.ir.controllers[ci];
    let plan = &ctrl.plans[pi];
    let p = Printer::new(set.ir, ctrl, Some(plan));
    let edges = drawn(svg, "edge-");
    let runs = set.runs;
    body.push_str("<h2>State table</h2>\n<table class=\"rows\">\n<tr><th>row</th><th>IF (event)</th><th>current state</th><th>THEN next state</th><th>job list</th>");
    if runs.is_some() {
        body.push_str("<th>hits</th>");
    }
    body.push_str("<th>notes</th></tr>\n");
    for (ri, r) in plan.rows.iter().enumerate() {
        let name = r.display_name();
        let hits = runs.map(|c| c.row(&ctrl.name, plan.verb.0, r.position));
        let class = match hits {
            Some(0) => " class=\"never\"",
            _ => "",
        };
        let (next, jobs) = next_and_jobs(&p, r);
        let mut jobs: Vec<String> = jobs
            .iter()
            .map(|j| format!("<code>{}</code>", esc(j)))
            .collect();
        match r.to {
            Target::Done => jobs.push("status DONE".into()),
            Target::Error(_) | Target::ErrorOf(_) => jobs.push("status ERROR".into()),
            _ => {}
        }
        // Each state named links to its entry in the list of states.
        let link = |s: &StateId| format!("<a href=\"#state-{0}\">{0}</a>", esc(&p.state(*s)));
        let current = match &r.from {
            From::State(s) => link(s),
            From::States(set) => set.iter().map(link).collect::<Vec<_>>().join(" | "),
            From::DontCare(_) | From::Except(..) => esc(&p.from(r)),
        };
        let graph = match edges.get(&name) {
            Some(e) => format!(" <a class=\"to-graph\" href=\"#{}\">graph</a>", esc(e)),
            None => String::new(),
        };
        let _ = write!(
            body,
            "<tr id=\"row-{name}\"{class}><td><b>{}</b>{graph} <a class=\"to-source\" href=\"#L{}\">line {}</a></td><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td>",
            esc(&p.label(r)),
            r.line,
            r.line,
            esc(&p.condition(r)),
            current,
            esc(&next),
            if jobs.is_empty() { "—".to_string() } else { jobs.join("<br>") }
        );
        if let Some(n) = hits {
            let mark = if n == 0 { " never fired" } else { "" };
            let _ = write!(body, "<td class=\"hits\">{n}{mark}</td>");
        }
        body.push_str("<td>");
        body.push_str(&docs(&r.docs));
        for d in placed.rows.get(&(ci, pi, ri)).into_iter().flatten() {
            body.push_str(&finding(d));
        }
        body.push_str("</td></tr>\n");
    }
    body.push_str("</table>\n");
}

fn source(body: &mut String, plan: &Plan, text: &str, file: &str) {
    let first = line_of(text, plan.span.start);
    let last = line_of(text, plan.span.end.saturating_sub(1).max(plan.span.start));
    let row_at: BTreeMap<usize, String> = plan
        .rows
        .iter()
        .map(|r| (r.line as usize, r.display_name()))
        .collect();
    let _ = writeln!(
        body,
        "<h2>Source</h2>\n<p class=\"file\">{}, lines {first}–{last}</p>\n<pre class=\"source\">",
        esc(file)
    );
    source_lines(body, text, first..=last, &row_at);
    body.push_str("</pre>\n");
    // Rows placed by `use` and states first named in them are written in
    // their `rows` block, outside the plan's lines: those lines follow, so
    // that every row and state links to where it is written.
    let mut shared: Vec<std::ops::RangeInclusive<usize>> = Vec::new();
    let spans = plan
        .rows
        .iter()
        .map(|r| r.span)
        .chain(plan.states.iter().filter_map(|s| s.span))
        .filter(|s| s.file == plan.span.file);
    for span in spans {
        let (a, b) = (
            line_of(text, span.start),
            line_of(text, span.end.saturating_sub(1).max(span.start)),
        );
        if (first..=last).contains(&a) || shared.iter().any(|r| r.contains(&a)) {
            continue;
        }
        shared.push(a..=b);
    }
    shared.sort_by_key(|r| *r.start());
    if shared.is_empty() {
        return;
    }
    let _ = writeln!(
        body,
        "<p class=\"file\">{}: the shared rows this plan uses</p>\n<pre class=\"source\">",
        esc(file)
    );
    for lines in shared {
        source_lines(body, text, lines, &row_at);
    }
    body.push_str("</pre>\n");
}

/// Lines of `text`, each with its `L{n}` anchor and a link to its row.
fn source_lines(
    body: &mut String,
    text: &str,
    lines: std::ops::RangeInclusive<usize>,
    row_at: &BTreeMap<usize, String>,
) {
    let (first, last) = (*lines.start(), *lines.end());
    for (i, line) in text
        .lines()
        .enumerate()
        .skip(first.saturating_sub(1))
        .take((last + 1).saturating_sub(first))
    {
        let n = i + 1;
        let number = match row_at.get(&n) {
            Some(row) => {
                format!("<a class=\"ln\" href=\"#row-{row}\" title=\"row {row}\">{n:>4}</a>")
            }
            None => format!("<a class=\"ln\" href=\"#L{n}\">{n:>4}</a>"),
        };
        let _ = writeln!(
            body,
            "<span id=\"L{n}\" class=\"line\">{number} {}</span>",
            esc(line)
        );
    }
}
