//! IR → Graphviz DOT: one state graph per plan and the controller
//! hierarchy. Pure functions returning strings; nothing here runs `dot`.
//!
//! Notation (Figure 13, Appendix C): states are circles, `Done` a double
//! circle, `Error` a red octagon; each don't-care row gets its own dashed
//! `*N` pseudo-node with an edge to its target, and a row of a state set
//! `A | B` is an edge from each of its states. Rows between the same two
//! nodes (several self-loops on one state, say) are **one edge**. The
//! `otherwise` row is not an edge of any state: it is a dashed note,
//! `EN otherwise` (an edge from the note when it leaves the state). Nodes
//! appear in the order of the rows.
//!
//! **A layout that cannot collide** (issue 29). An edge is labelled with
//! its rows' names only (`E3`, `E3 E4`), in one font size; the rows'
//! state patterns, targets, conditions and jobs are in the state table
//! under the drawing ([`legend`]), which is the graph's own label, wrapped
//! to a bounded width, and so part of the SVG with space of its own. What
//! runs every cycle (status fields, `pre`/`post`) and when a command is
//! accepted are lines under that table, not notes in the drawing. Short
//! labels are what Graphviz places without overlap: long multi-line labels
//! (and loops hung from ports) were what made them run into each other
//! and under `*N` nodes. A graph whose chain of states is too long for a
//! page drawn left to right is drawn top to bottom ([`rankdir`]), so the
//! site does not shrink its text. No text is smaller than 11 pt. The test
//! `tests/graph_layout/` renders every graph and checks all of this.
//!
//! Every node and edge carries an `id`, first among its attributes, that
//! names what it draws whatever the layout: `node-<state>`
//! (`node-any-E<N>` for a `*N` pseudo-node or the `otherwise` note),
//! `edge-E<N>` for row N's edge, `edge-E2-E3-E4` for one edge standing for
//! several rows, `ctrl-<name>` in the hierarchy. Graphviz copies them into
//! SVG; the doc site keys its links on them (see [`node_id`], [`edge_id`]).
//!
//! [`Edge`], [`write_edge`] and the [`legend`] are shared with the diff
//! graphs (`crate::diff_dot`), which colour each name by what a change did
//! to its row.

pub(crate) mod legend;

use crate::GENERATED;
use legend::TableRow;
use rcs_dsl::ir::{Controller, Cpu, From, Ir, Plan, Row, Target};
use rcs_dsl::placement::Placement;
use rcs_dsl::pretty::Printer;
use std::fmt::Write;

/// The text size of edge labels, notes and the state table, in points:
/// 14.7 px at full size, still 10 px when the site shrinks a graph to
/// 68% to fit its page.
pub(crate) const SMALL_FONT: u32 = 11;
/// How wide, in points, a graph may be before its text would fall under
/// 10 px on the site's page (1,200 px wide: `site.css`, at a 1,280-px
/// window): 11 pt is 10 px at 68%, 1,200 px / 0.68 = 1,765 px = 1,323 pt;
/// with room to spare for what the estimate in [`rankdir`] misses.
pub(crate) const PAGE_POINTS: usize = 1000;

/// Escape text for a Graphviz HTML-like label.
pub(crate) fn html(s: &str) -> String {
    markup(s, "<BR/>")
}

/// Escape text for HTML or XML (content and double-quoted attributes),
/// each line break written as `newline`.
pub(crate) fn markup(s: &str, newline: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\n' => out.push_str(newline),
            c => out.push(c),
        }
    }
    out
}

/// Escape text for a quoted DOT string.
pub(crate) fn quoted(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

pub(crate) fn header(out: &mut String, source: &str) {
    let _ = writeln!(out, "// {GENERATED} from {source}. Do not edit.");
}

/// One row as a name on an edge.
#[derive(Clone, Debug, Default)]
pub(crate) struct Line {
    /// The row's name (`E2`), for the edge's `id`; empty for none.
    pub(crate) row: String,
    /// What the edge shows for the row: `E2` (in a diff, `+E2`).
    pub(crate) name: String,
    /// The row in full and where it is, or its doc comment.
    pub(crate) tooltip: String,
    /// A font colour for the name (diff graphs); `None`: the default.
    pub(crate) color: Option<&'static str>,
}

/// All the rows from one node to another, drawn as one edge.
#[derive(Clone, Debug)]
pub(crate) struct Edge {
    pub(crate) from: String,
    pub(crate) to: String,
    pub(crate) lines: Vec<Line>,
}

/// Rows as (from, to, line) → one edge per node pair, in order of first
/// appearance, its lines in row order.
pub(crate) fn merge_edges(rows: impl IntoIterator<Item = (String, String, Line)>) -> Vec<Edge> {
    let mut edges: Vec<Edge> = Vec::new();
    for (from, to, line) in rows {
        match edges.iter_mut().find(|e| e.from == from && e.to == to) {
            Some(e) => e.lines.push(line),
            None => edges.push(Edge {
                from,
                to,
                lines: vec![line],
            }),
        }
    }
    edges
}

/// Names per line of an edge label: `E1 E2 E3 E4`, then the next line.
const NAMES_PER_LINE: usize = 4;

/// The attributes of an edge: its `id` (`id="edge-E3", `, or empty), its
/// label (its rows' names, four to a line: `label=<…>`) and its tooltip
/// (each row in full: `tooltip="…"`).
fn edge_attrs(edge: &Edge) -> (String, String, String) {
    let mut label = String::new();
    for (i, line) in edge.lines.iter().enumerate() {
        if i > 0 {
            label.push_str(if i % NAMES_PER_LINE == 0 {
                "<BR/>"
            } else {
                " "
            });
        }
        match line.color {
            Some(c) => {
                let _ = write!(label, "<FONT COLOR=\"{c}\">{}</FONT>", html(&line.name));
            }
            None => label.push_str(&html(&line.name)),
        }
    }
    // A borderless cell around the names keeps a margin between them and
    // any line: Graphviz places an edge's label box touching its edge.
    let label = format!(
        "<TABLE BORDER=\"0\" CELLBORDER=\"0\" CELLSPACING=\"0\" CELLPADDING=\"3\"><TR><TD>{label}</TD></TR></TABLE>"
    );
    let tips: Vec<&str> = edge.lines.iter().map(|l| l.tooltip.as_str()).collect();
    let rows: Vec<String> = edge.lines.iter().map(|l| l.row.clone()).collect();
    let id = if rows.iter().any(String::is_empty) {
        String::new()
    } else {
        format!("id={}, ", quoted(&edge_id(&rows)))
    };
    (
        id,
        format!("label=<{label}>"),
        format!("tooltip={}", quoted(&tips.join("\n"))),
    )
}

/// The nodes a row leaves from: its state, each state of its set (one
/// edge per state, every one labelled with the row), or its own `*N`
/// pseudo-node (an `except` row's too; the table says which states it
/// leaves out).
pub(crate) fn from_nodes(p: &Printer, r: &Row) -> Vec<String> {
    match &r.from {
        From::DontCare(_) | From::Except(..) => vec![format!("*{}", r.position)],
        From::State(s) => vec![p.state(*s)],
        From::States(set) => set.iter().map(|s| p.state(*s)).collect(),
    }
}

/// The node a row goes to when it leaves from node `from` (`same`: there).
pub(crate) fn to_node(p: &Printer, r: &Row, from: &str) -> String {
    match r.to {
        Target::Same => from.to_string(),
        Target::State(_) => p.target(r),
        Target::Done => "Done".to_string(),
        Target::Error(_) | Target::ErrorOf(_) => "Error".to_string(),
    }
}

/// A row's line of the state table.
fn table_row(p: &Printer, r: &Row) -> TableRow {
    let from = match &r.from {
        _ if r.is_otherwise() => "any (no row matched)".to_string(),
        From::DontCare(_) => "*".to_string(),
        From::State(s) => p.state(*s),
        From::States(set) => p.states(set),
        From::Except(_, out) => format!("* except {}", p.states(out)),
    };
    TableRow {
        name: p.label(r),
        from,
        to: p.target(r),
        condition: if r.is_otherwise() {
            "otherwise".to_string()
        } else {
            p.condition(r)
        },
        jobs: r.jobs.iter().map(|j| p.job(j)).collect(),
        color: None,
    }
}

/// A row's name on its edge, its tooltip the row in full.
fn row_line(ir: &Ir, p: &Printer, r: &Row) -> Line {
    Line {
        row: r.display_name(),
        name: p.label(r),
        tooltip: format!("{}: {}\n{}", p.label(r), p.condition(r), tooltip(ir, r)),
        color: None,
    }
}

fn tooltip(ir: &Ir, r: &Row) -> String {
    if r.docs.is_empty() {
        format!("{}:{}", ir.files[r.span.file.0 as usize], r.line)
    } else {
        r.docs.join("\n")
    }
}

/// The name of the `otherwise` note: `E10 otherwise`, as the tables and
/// diagnostics name the row.
pub fn otherwise_name(r: &Row) -> String {
    format!("{} otherwise", r.display_name())
}

/// The attributes of a node that is not a plain state.
pub(crate) fn node_attrs(id: &str) -> String {
    match id {
        "Done" => "shape=doublecircle".to_string(),
        "Error" => "shape=octagon, color=red, fontcolor=red".to_string(),
        _ if id.starts_with('*') => format!("label={}, style=dashed", quoted(id)),
        _ => String::new(),
    }
}

/// `LR` (states left to right, as the methodology draws them) unless the
/// longest chain of states would make the drawing wider than a page, then
/// `TB`. A node's rank is estimated as its distance from the nodes no edge
/// enters (the `*N` nodes, the first state); a rank across takes about
/// 110 pt left to right (a circle, a short label, the space between), a
/// node about 80 pt side by side top to bottom.
pub(crate) fn rankdir(nodes: &[String], edges: &[Edge]) -> &'static str {
    let index = |n: &str| nodes.iter().position(|m| m == n);
    let entered: Vec<bool> = nodes
        .iter()
        .map(|n| edges.iter().any(|e| e.to == *n && e.from != e.to))
        .collect();
    let mut depth: Vec<Option<usize>> = vec![None; nodes.len()];
    let mut queue: std::collections::VecDeque<usize> =
        (0..nodes.len()).filter(|i| !entered[*i]).collect();
    if queue.is_empty() && !nodes.is_empty() {
        queue.push_back(0);
    }
    for i in &queue {
        depth[*i] = Some(0);
    }
    while let Some(i) = queue.pop_front() {
        let d = depth[i].unwrap_or(0);
        for e in edges.iter().filter(|e| e.from == nodes[i]) {
            if let Some(j) = index(&e.to).filter(|j| depth[*j].is_none()) {
                depth[j] = Some(d + 1);
                queue.push_back(j);
            }
        }
    }
    let ranks = depth.iter().flatten().max().map_or(1, |d| d + 1);
    let mut widest = 1;
    for d in 0..ranks {
        widest = widest.max(depth.iter().filter(|x| **x == Some(d)).count());
    }
    if ranks * 110 > PAGE_POINTS && widest * 80 < ranks * 110 {
        "TB"
    } else {
        "LR"
    }
}

/// What the doc site marks on a plan's graph, by row name (`E2`): how
/// many cycles fired each row (`--coverage`, `--trace`), and the rows with
/// a finding, by severity (`error`, `warning`, `note`).
#[derive(Clone, Debug, Default)]
pub struct RowMarks {
    pub hits: Option<std::collections::BTreeMap<String, u64>>,
    pub findings: std::collections::BTreeMap<String, &'static str>,
}

impl RowMarks {
    /// A row's name as its edge shows it: `E2`, with `⚠` after a row with
    /// a finding; red when it never fired or has an error, orange for a
    /// warning. The hit counts go in the state table beside the name (on
    /// the edge, a long label is what Graphviz cannot keep clear of lines).
    fn mark(&self, line: &mut Line) {
        if let Some(color) = self.color(&line.row) {
            line.color = Some(color);
        }
        if self.findings.contains_key(&line.row) {
            line.name.push_str(" ⚠");
        }
    }

    /// The row's name in the state table: `E2 ×12 ⚠`.
    fn mark_table(&self, key: &str, row: &mut TableRow) {
        if let Some(n) = self.hits.as_ref().map(|h| h.get(key).copied().unwrap_or(0)) {
            row.name = format!("{} ×{}", row.name, compact(n));
        }
        if self.findings.contains_key(key) {
            row.name.push_str(" ⚠");
        }
        if let Some(color) = self.color(key) {
            row.color = Some(color);
        }
    }

    fn color(&self, row: &str) -> Option<&'static str> {
        match self.findings.get(row) {
            Some(&"error") => return Some("#b00000"),
            Some(_) => return Some("#b06000"),
            None => {}
        }
        let never = self
            .hits
            .as_ref()
            .is_some_and(|h| h.get(row).copied().unwrap_or(0) == 0);
        never.then_some("#b00000")
    }
}

/// A count in at most four characters: `7`, `950`, `12k`, `2.5M`, `3G`.
fn compact(n: u64) -> String {
    const UNITS: [(u64, &str); 3] = [(1_000_000_000, "G"), (1_000_000, "M"), (1_000, "k")];
    for (unit, suffix) in UNITS {
        if n >= unit {
            let whole = n / unit;
            return if whole < 10 {
                // One decimal, rounded down: never more than it was.
                format!("{whole}.{}{suffix}", (n % unit) * 10 / unit)
            } else {
                format!("{whole}{suffix}")
            };
        }
    }
    n.to_string()
}

/// The state graph of one plan.
pub fn plan_graph(ir: &Ir, ctrl: &Controller, plan: &Plan) -> String {
    plan_graph_marked(ir, ctrl, plan, &RowMarks::default())
}

/// The state graph of one plan with each row's name marked (hits,
/// findings) as [`RowMarks`] says: what the doc site draws.
pub fn plan_graph_marked(ir: &Ir, ctrl: &Controller, plan: &Plan, marks: &RowMarks) -> String {
    let p = Printer::new(ir, ctrl, Some(plan));
    let verb = &ctrl.commands[plan.verb.index()].name;
    let source = &ir.files[plan.header.file.0 as usize];
    let mut notes = Vec::new();
    // Status fields and `pre`/`post` jobs: what runs every cycle, beside the plan.
    if let Some(note) = crate::every_cycle::note(ir, ctrl) {
        notes.push(note);
    }
    // Refusal (step 3a): when a command of the plan's verbs is taken.
    for v in &plan.verbs {
        let k = &ctrl.commands[v.index()];
        if let Some(a) = k.accept.as_ref() {
            notes.push(format!("{} accepted only when {}", k.name, p.expr(&a.cond)));
        }
    }

    // Nodes in order of first appearance in the rows.
    let mut nodes: Vec<(String, String)> = Vec::new();
    let mut node = |id: String, attrs: String| {
        if !nodes.iter().any(|(n, _)| *n == id) {
            nodes.push((id, attrs));
        }
    };
    let mut edges = Vec::new();
    let mut extra = String::new();
    for r in &plan.rows {
        if r.is_otherwise() {
            let note = otherwise_name(r);
            let to = to_node(&p, r, "");
            node(
                note.clone(),
                format!(
                    "id={}, shape=note, style=dashed, fontsize={SMALL_FONT}, tooltip={}",
                    quoted(&node_id(&format!("*{}", r.position))),
                    quoted(&tooltip(ir, r))
                ),
            );
            if !matches!(r.to, Target::Same) {
                node(to.clone(), String::new());
                let _ = writeln!(
                    extra,
                    "    {} -> {} [id={}, style=dashed];",
                    quoted(&note),
                    quoted(&to),
                    quoted(&edge_id(&[r.display_name()]))
                );
            }
            continue;
        }
        for from in from_nodes(&p, r) {
            let to = to_node(&p, r, &from);
            node(from.clone(), String::new());
            node(to.clone(), String::new());
            let mut line = row_line(ir, &p, r);
            marks.mark(&mut line);
            edges.push((from, to, line));
        }
    }
    let edges = merge_edges(edges);
    let names: Vec<String> = nodes.iter().map(|(n, _)| n.clone()).collect();

    let mut out = String::new();
    header(&mut out, source);
    let title = format!("{} · {}", ctrl.name, ctrl.plan_title(plan));
    let rows: Vec<TableRow> = plan
        .rows
        .iter()
        .map(|r| {
            let mut row = table_row(&p, r);
            marks.mark_table(&r.display_name(), &mut row);
            row
        })
        .collect();
    graph_head(
        &mut out,
        &format!("{}.{verb}", ctrl.name),
        &plan.docs,
        rankdir(&names, &edges),
        &legend::table(&title, &rows, &notes),
    );
    for (id, attrs) in &nodes {
        let attrs = if attrs.is_empty() {
            let plain = node_attrs(id);
            let sep = if plain.is_empty() { "" } else { ", " };
            format!("id={}{sep}{plain}", quoted(&node_id(id)))
        } else {
            attrs.clone()
        };
        let _ = writeln!(out, "    {} [{attrs}];", quoted(id));
    }
    out.push_str(&extra);
    for e in &edges {
        write_edge(&mut out, e, "");
    }
    out.push_str("}\n");
    out
}

/// One edge; `extra` attributes follow the label's (`, color=red`).
///
/// A self-loop is drawn through its label: the label is a node of its own
/// (`loop S1`, plain text) with a line from the state to it and an arrow
/// back. Graphviz places a loop's own label after routing the other edges,
/// so another edge may run through it; a node, it routes around.
pub(crate) fn write_edge(out: &mut String, e: &Edge, extra: &str) {
    let (id, label, tooltip) = edge_attrs(e);
    let from = quoted(&e.from);
    if e.from != e.to {
        let to = quoted(&e.to);
        let _ = writeln!(out, "    {from} -> {to} [{id}{label}, {tooltip}{extra}];");
        return;
    }
    let node = quoted(&format!("loop {}", e.from));
    let _ = writeln!(
        out,
        "    {node} [shape=plaintext, fontsize={SMALL_FONT}, {label}];"
    );
    let _ = writeln!(
        out,
        "    {from} -> {node} [{id}{tooltip}, arrowhead=none{extra}];"
    );
    // The way back has no `id`: the SVG would hold it twice.
    let _ = writeln!(out, "    {node} -> {from} [{tooltip}{extra}];");
}

/// The `id` of the node named `name` in a plan graph: `node-<state>`, or
/// `node-any-E<N>` for the `*N` pseudo-node of row N.
pub fn node_id(name: &str) -> String {
    match name.strip_prefix('*') {
        Some(n) => format!("node-any-E{n}"),
        None => format!("node-{name}"),
    }
}

/// The `id` of the edge drawing these rows (named `E<position>`):
/// `edge-E3`, or `edge-E2-E3-E4` for one edge that stands for several.
pub fn edge_id(rows: &[String]) -> String {
    format!("edge-{}", rows.join("-"))
}

/// The `id` of a controller's node in the hierarchy.
pub fn ctrl_id(name: &str) -> String {
    format!("ctrl-{name}")
}

/// `digraph NAME {`, the graph's label (the state table, at the
/// bottom), and the graph, node and edge defaults.
pub(crate) fn graph_head(
    out: &mut String,
    name: &str,
    docs: &[String],
    rankdir: &str,
    label: &str,
) {
    let _ = writeln!(out, "digraph {} {{", quoted(name));
    let _ = writeln!(
        out,
        "    graph [label=<{label}>, labelloc=b, rankdir={rankdir}, pad=0.3, nodesep=0.4, ranksep=0.5, fontname=\"Helvetica\", fontsize={SMALL_FONT}, tooltip={}];",
        quoted(&docs.join("\n"))
    );
    out.push_str("    node [fontname=\"Helvetica\", shape=circle];\n");
    let _ = writeln!(
        out,
        "    edge [fontname=\"Helvetica\", fontsize={SMALL_FONT}];"
    );
}
/// The controller tree, one cluster per executive ("CPU"), inside one
/// cluster per process when the manifest places CPUs in several.
pub fn hierarchy_graph(ir: &Ir) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "// {GENERATED} for system {}. Do not edit.", ir.system);
    let _ = writeln!(out, "digraph {} {{", quoted(&ir.system));
    let _ = writeln!(
        out,
        "    graph [label={}, labelloc=t, fontname=\"Helvetica\", rankdir=TB, pad=0.3];",
        quoted(&format!("{} hierarchy", ir.system))
    );
    out.push_str("    node [fontname=\"Helvetica\", shape=box, style=rounded];\n");
    // With several processes, one cluster per process around its CPUs'
    // clusters; with one, the CPU clusters alone (as before placement).
    let placement = Placement::of(ir);
    let distributed = placement.is_distributed();
    for (p, process) in placement.processes.iter().enumerate() {
        let indent = if distributed { "    " } else { "" };
        if distributed {
            let _ = writeln!(
                out,
                "    subgraph {} {{",
                quoted(&format!("cluster_process_{p}"))
            );
            out.push_str("        style=solid;\n        label=\"\";\n");
            let _ = writeln!(
                out,
                "        {} [shape=plaintext, label={}];",
                quoted(&format!("process_label_{p}")),
                quoted(&format!("process {process}"))
            );
        }
        let cpus = ir
            .schedule
            .iter()
            .enumerate()
            .filter(|(i, _)| placement.cpu_process.get(*i) == Some(&p));
        for (i, cpu) in cpus {
            cpu_cluster(&mut out, ir, indent, i, cpu);
            if distributed {
                let _ = writeln!(
                    out,
                    "        {} -> {} [style=invis];",
                    quoted(&format!("process_label_{p}")),
                    quoted(&format!("cpu_label_{i}"))
                );
            }
        }
        if distributed {
            out.push_str("    }\n");
        }
    }
    for ctrl in &ir.controllers {
        for s in &ctrl.subordinates {
            let _ = writeln!(
                out,
                "    {} -> {};",
                quoted(&ctrl.name),
                quoted(&ir.controller(*s).name)
            );
        }
    }
    out.push_str("}\n");
    out
}

/// One executive's cluster of the hierarchy graph, its lines indented by
/// `indent` more than a top-level cluster's.
fn cpu_cluster(out: &mut String, ir: &Ir, indent: &str, i: usize, cpu: &Cpu) {
    let _ = writeln!(
        out,
        "{indent}    subgraph {} {{",
        quoted(&format!("cluster_{i}"))
    );
    // The cluster's name is a node above its controllers (an invisible
    // edge to each keeps it there), not the cluster's label: Graphviz
    // routes edges around nodes, but through a cluster's label.
    // `label=""`: a cluster inherits the graph's label (the title) otherwise.
    let _ = writeln!(
        out,
        "{indent}        style=dashed;\n{indent}        label=\"\";"
    );
    let label = quoted(&format!("cpu_label_{i}"));
    let _ = writeln!(
        out,
        "{indent}        {label} [shape=plaintext, label={}];",
        quoted(&format!("CPU {} · {}", cpu.name, period(cpu.period_ns)))
    );
    for c in &cpu.order {
        let ctrl = ir.controller(*c);
        // One cell per line: lines of different sizes in one cell touch.
        let mut label = format!(
            "<TABLE BORDER=\"0\" CELLSPACING=\"0\" CELLPADDING=\"1\"><TR><TD>{}</TD></TR>",
            html(&ctrl.name)
        );
        if let Some(t) = ctrl.title.as_ref().filter(|t| !t.is_empty()) {
            let _ = write!(
                label,
                "<TR><TD><FONT POINT-SIZE=\"{SMALL_FONT}\">{}</FONT></TD></TR>",
                html(t)
            );
        }
        if let Some(l) = ctrl.level {
            let _ = write!(
                label,
                "<TR><TD><FONT POINT-SIZE=\"{SMALL_FONT}\">level {l}</FONT></TD></TR>"
            );
        }
        label.push_str("</TABLE>");
        let _ = writeln!(
            out,
            "{indent}        {} [id={}, label=<{label}>, tooltip={}];",
            quoted(&ctrl.name),
            quoted(&ctrl_id(&ctrl.name)),
            quoted(&ctrl.docs.join("\n"))
        );
    }
    for c in &cpu.order {
        let _ = writeln!(
            out,
            "{indent}        {label} -> {} [style=invis];",
            quoted(&ir.controller(*c).name)
        );
    }
    let _ = writeln!(out, "{indent}    }}");
}

/// A period as people write it: `30 ms`, `500 µs`, `1 s`.
pub fn period(ns: u64) -> String {
    if ns.is_multiple_of(1_000_000_000) {
        format!("{} s", ns / 1_000_000_000)
    } else if ns.is_multiple_of(1_000_000) {
        format!("{} ms", ns / 1_000_000)
    } else if ns.is_multiple_of(1_000) {
        format!("{} µs", ns / 1_000)
    } else {
        format!("{ns} ns")
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn counts_are_compact_and_never_rounded_up() {
        let c = super::compact;
        assert_eq!(c(0), "0");
        assert_eq!(c(999), "999");
        assert_eq!(c(1_000), "1.0k");
        assert_eq!(c(1_999), "1.9k");
        assert_eq!(c(12_345), "12k");
        assert_eq!(c(2_469_134), "2.4M");
        assert_eq!(c(999_999_999), "999M");
        assert_eq!(c(u64::MAX), "18446744073G");
    }
}
