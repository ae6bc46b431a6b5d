//! IR → Graphviz DOT: one state graph per plan and the controller
//! hierarchy. Pure functions returning strings; nothing here runs `dot`.
//!
//! Notation (Figure 13, Appendix C): states are circles, `Done` a double
//! circle, `Error` a red octagon; each don't-care row gets its own dashed
//! `*N` pseudo-node with an edge to its target (an `except` row's node
//! says `except A, B` under its name), and a row of a state set `A | B` is
//! an edge from each of its states. Rows between the same two
//! nodes (several self-loops on one state, say) are **one edge** whose
//! label lists them, one line per row (`EN: condition`, its jobs in a
//! smaller line under it), and a loop of several rows hangs below its
//! state with its label under it, so no arc crosses a label; an edge's label is
//! tied to its arc (`decorate`) where several edges enter one node, so a
//! fan-in label cannot be read as another edge's. The `otherwise` row is
//! not an edge of any state: it is a dashed note, `EN otherwise`, saying
//! what happens in any state when no row matches (an edge from the note
//! when it leaves the state). Nodes appear in the order of the rows.
//!
//! Every node and edge carries an `id`, first among its attributes, that
//! names what it draws whatever the layout: `node-<state>`
//! (`node-any-E<N>` for a `*N` pseudo-node or the `otherwise` note),
//! `edge-E<N>` for row N's edge, `edge-E2-E3-E4` for one edge standing for
//! several rows, `ctrl-<name>` in the hierarchy. Graphviz copies them into
//! SVG; the doc site keys its links on them (see [`node_id`], [`edge_id`]).
//!
//! [`Edge`] and [`edge_attrs`] are shared with the diff graphs
//! (`crate::diff_dot`), which colour each line by what a change did to it.

use crate::GENERATED;
use rcs_dsl::ir::{Controller, Cpu, From, Ir, Plan, Row, Target};
use rcs_dsl::placement::Placement;
use rcs_dsl::pretty::Printer;
use std::fmt::Write;

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

/// One row as a line of an edge label.
#[derive(Clone, Debug, Default)]
pub(crate) struct Line {
    /// The row's name (`E2`), for the edge's `id`; empty for none.
    pub(crate) row: String,
    /// `E2: TB.done && x > 1`.
    pub(crate) text: String,
    /// The job list, `;`-separated; empty for none.
    pub(crate) jobs: String,
    /// Where the row is, or its doc comment.
    pub(crate) tooltip: String,
    /// A font colour for the line (diff graphs); `None`: the default.
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

/// The attributes of an edge: its label (one left-aligned line per row,
/// the jobs in a smaller line under it) and tooltip; `decorate` ties the
/// label to its arc when other edges enter the same node.
fn edge_attrs(edge: &Edge, all: &[Edge]) -> String {
    let mut label = String::new();
    // One row: its line, its jobs centred under it. Several: every line
    // left-aligned, the jobs indented under their row.
    let (br, indent) = match edge.lines.len() {
        1 => ("<BR/>", ""),
        _ => ("<BR ALIGN=\"LEFT\"/>", "   "),
    };
    for line in &edge.lines {
        let (open, close) = match line.color {
            Some(c) => (format!("<FONT COLOR=\"{c}\">"), "</FONT>"),
            None => (String::new(), ""),
        };
        let _ = write!(label, "{open}{}{close}", html(&line.text));
        if !line.jobs.is_empty() {
            let _ = write!(
                label,
                "{br}<FONT POINT-SIZE=\"8\">{open}{indent}{}{close}</FONT>",
                html(&line.jobs)
            );
        }
        if edge.lines.len() > 1 {
            label.push_str(br);
        }
    }
    let tips: Vec<&str> = edge.lines.iter().map(|l| l.tooltip.as_str()).collect();
    let rows: Vec<String> = edge.lines.iter().map(|l| l.row.clone()).collect();
    let id = if rows.iter().any(String::is_empty) {
        String::new()
    } else {
        format!("id={}, ", quoted(&edge_id(&rows)))
    };
    let mut attrs = format!("{id}label=<{label}>, tooltip={}", quoted(&tips.join("\n")));
    let fan_in = all
        .iter()
        .filter(|e| e.to == edge.to && e.from != e.to)
        .count();
    if edge.from != edge.to && fan_in > 1 {
        attrs.push_str(", decorate=true");
    }
    attrs
}

/// The nodes a row leaves from: its state, each state of its set (one
/// edge per state, every one labelled with the row), or its own `*N`
/// pseudo-node (an `except` row's says which states it leaves out).
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

/// The attributes of the `*N` node of an `except` row: dashed, labelled
/// `*N` over `except A, B`.
fn except_node_attrs(p: &Printer, r: &Row) -> Option<String> {
    let From::Except(_, out) = &r.from else {
        return None;
    };
    let names: Vec<String> = out.iter().map(|s| p.state(*s)).collect();
    let label = format!(
        "*{}<BR/><FONT POINT-SIZE=\"8\">except {}</FONT>",
        r.position,
        html(&names.join(", "))
    );
    Some(format!("label=<{label}>, style=dashed"))
}

/// A row's line: `E2: condition` (`→ Error(E)` added when it names one).
pub(crate) fn row_line(ir: &Ir, p: &Printer, r: &Row) -> Line {
    let mut text = format!("{}: {}", p.label(r), p.condition(r));
    if let Target::Error(Some(_)) = r.to {
        text.push_str(&format!(" → {}", p.target(r)));
    }
    let jobs: Vec<String> = r.jobs.iter().map(|j| p.job(j)).collect();
    Line {
        row: r.display_name(),
        text,
        jobs: jobs.join("; "),
        tooltip: tooltip(ir, r),
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

/// The label of the `otherwise` note: what it does, in any state.
pub(crate) fn otherwise_label(p: &Printer, r: &Row) -> String {
    let mut label = format!(
        "{}<BR/><FONT POINT-SIZE=\"8\">any state, no row matched",
        html(&otherwise_name(r))
    );
    if matches!(r.to, Target::Same) {
        label.push_str(": stay");
    }
    label.push_str("</FONT>");
    if !r.jobs.is_empty() {
        let jobs: Vec<String> = r.jobs.iter().map(|j| p.job(j)).collect();
        let _ = write!(
            label,
            "<BR/><FONT POINT-SIZE=\"8\">{}</FONT>",
            html(&jobs.join("; "))
        );
    }
    label
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

/// The state graph of one plan.
pub fn plan_graph(ir: &Ir, ctrl: &Controller, plan: &Plan) -> String {
    let p = Printer::new(ir, ctrl, Some(plan));
    let verb = &ctrl.commands[plan.verb.index()].name;
    let source = &ir.files[plan.header.file.0 as usize];
    let mut out = String::new();
    header(&mut out, source);
    let title = format!("{} · {}", ctrl.name, ctrl.plan_title(plan));
    graph_head(
        &mut out,
        &format!("{}.{verb}", ctrl.name),
        &title,
        &plan.docs,
    );
    // Status fields and `pre`/`post` jobs: what runs every cycle, beside the plan.
    if let Some(note) = crate::every_cycle::note(ir, ctrl) {
        let _ = writeln!(
            out,
            "    \"every cycle\" [shape=note, fontsize=10, label=<{}>];",
            html(&note)
        );
    }

    // Refusal (step 3a): when a command of the plan's verbs is taken.
    let accepts: Vec<String> = plan
        .verbs
        .iter()
        .filter_map(|v| {
            let k = &ctrl.commands[v.index()];
            let a = k.accept.as_ref()?;
            Some(format!("{} accepted only when {}", k.name, p.expr(&a.cond)))
        })
        .collect();
    if !accepts.is_empty() {
        let _ = writeln!(
            out,
            "    \"accept\" [shape=note, fontsize=10, label=<{}>];",
            accepts
                .iter()
                .map(|a| html(a))
                .collect::<Vec<_>>()
                .join("<br/>")
        );
    }

    // Nodes in order of first appearance in the rows.
    let mut emitted: Vec<String> = Vec::new();
    let mut node = |out: &mut String, id: String, r: &Row| {
        if !emitted.contains(&id) {
            let attrs = match except_node_attrs(&p, r).filter(|_| id.starts_with('*')) {
                Some(a) => a,
                None => node_attrs(&id),
            };
            let sep = if attrs.is_empty() { "" } else { ", " };
            let _ = writeln!(
                out,
                "    {} [id={}{sep}{attrs}];",
                quoted(&id),
                quoted(&node_id(&id))
            );
            emitted.push(id);
        }
    };
    let mut edges = Vec::new();
    for r in &plan.rows {
        if r.is_otherwise() {
            let note = otherwise_name(r);
            let _ = writeln!(
                out,
                "    {} [id={}, label=<{}>, shape=note, style=dashed, tooltip={}];",
                quoted(&note),
                quoted(&node_id(&format!("*{}", r.position))),
                otherwise_label(&p, r),
                quoted(&tooltip(ir, r))
            );
            if !matches!(r.to, Target::Same) {
                node(&mut out, to_node(&p, r, ""), r);
                let _ = writeln!(
                    out,
                    "    {} -> {} [id={}, style=dashed];",
                    quoted(&note),
                    quoted(&to_node(&p, r, "")),
                    quoted(&edge_id(&[r.display_name()]))
                );
            }
            continue;
        }
        for from in from_nodes(&p, r) {
            let to = to_node(&p, r, &from);
            node(&mut out, from.clone(), r);
            node(&mut out, to.clone(), r);
            edges.push((from, to, row_line(ir, &p, r)));
        }
    }
    let edges = merge_edges(edges);
    for e in &edges {
        write_edge(&mut out, e, &edges, "");
    }
    out.push_str("}\n");
    out
}

/// One edge. A self-loop of several rows hangs below its node (`:s`
/// ports), where its label sits under the arc: in the default place, with
/// `rankdir=LR`, Graphviz lets the arc run through a label of many lines.
/// A loop of one row keeps the default place, which leaves more room.
/// `extra` attributes follow the label's (`, color=red`).
pub(crate) fn write_edge(out: &mut String, e: &Edge, all: &[Edge], extra: &str) {
    let port = if e.from == e.to && e.lines.len() > 1 {
        ":s"
    } else {
        ""
    };
    let _ = writeln!(
        out,
        "    {}{port} -> {}{port} [{}{extra}];",
        quoted(&e.from),
        quoted(&e.to),
        edge_attrs(e, all)
    );
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

/// `digraph NAME {` and the graph, node and edge defaults.
pub(crate) fn graph_head(out: &mut String, name: &str, title: &str, docs: &[String]) {
    let _ = writeln!(out, "digraph {} {{", quoted(name));
    let _ = writeln!(
        out,
        "    graph [label={}, labelloc=t, rankdir=LR, fontname=\"Helvetica\", tooltip={}];",
        quoted(title),
        quoted(&docs.join("\n"))
    );
    out.push_str("    node [fontname=\"Helvetica\", shape=circle];\n");
    out.push_str("    edge [fontname=\"Helvetica\", fontsize=10];\n");
}
/// The controller tree, one cluster per executive ("CPU"), inside one
/// cluster per process when the manifest places CPUs in several.
pub fn hierarchy_graph(ir: &Ir) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "// {GENERATED} for system {}. Do not edit.", ir.system);
    let _ = writeln!(out, "digraph {} {{", quoted(&ir.system));
    let _ = writeln!(
        out,
        "    graph [label={}, labelloc=t, fontname=\"Helvetica\", rankdir=TB];",
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
            let _ = writeln!(
                out,
                "        label={}; style=solid; fontname=\"Helvetica\";",
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
    let _ = writeln!(
        out,
        "{indent}        label={}; style=dashed; fontname=\"Helvetica\";",
        quoted(&format!("CPU {} · {}", cpu.name, period(cpu.period_ns)))
    );
    for c in &cpu.order {
        let ctrl = ir.controller(*c);
        let mut label = html(&ctrl.name);
        if let Some(t) = ctrl.title.as_ref().filter(|t| !t.is_empty()) {
            let _ = write!(label, "<BR/><FONT POINT-SIZE=\"9\">{}</FONT>", html(t));
        }
        if let Some(l) = ctrl.level {
            let _ = write!(label, "<BR/><FONT POINT-SIZE=\"8\">level {l}</FONT>");
        }
        let _ = writeln!(
            out,
            "{indent}        {} [id={}, label=<{label}>, tooltip={}];",
            quoted(&ctrl.name),
            quoted(&ctrl_id(&ctrl.name)),
            quoted(&ctrl.docs.join("\n"))
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
