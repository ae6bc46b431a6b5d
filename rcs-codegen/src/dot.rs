//! IR → Graphviz DOT: one state graph per plan and the controller
//! hierarchy. Pure functions returning strings; nothing here runs `dot`.
//!
//! Notation (Figure 13, Appendix C): states are circles, `Done` a double
//! circle, `Error` a red octagon; each don't-care row gets its own dashed
//! `*N` pseudo-node with an edge to its target; edges read `EN: condition`
//! with the job list in a smaller second line; `otherwise` is dashed; a
//! `same` edge loops. Nodes and edges appear in the order of the rows.
//!
//! Every node and edge carries an `id` that names what it draws, whatever
//! the layout: `node-<state>` (`node-any-E<N>` for a `*N` pseudo-node),
//! `edge-E<N>` for row N's edge (its position), `ctrl-<name>` in the
//! hierarchy. Graphviz copies them into SVG; the doc site keys its links on
//! them (see [`node_id`], [`edge_id`]), so it does not depend on the rest of
//! the DOT text.

use crate::GENERATED;
use rcs_dsl::ir::{Controller, From, Ir, Plan, Target};
use rcs_dsl::pretty::Printer;
use std::fmt::Write;

/// Escape text for a Graphviz HTML-like label.
fn html(s: &str) -> String {
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
fn quoted(s: &str) -> String {
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

fn header(out: &mut String, source: &str) {
    let _ = writeln!(out, "// {GENERATED} from {source}. Do not edit.");
}

/// The state graph of one plan.
pub fn plan_graph(ir: &Ir, ctrl: &Controller, plan: &Plan) -> String {
    let p = Printer::new(ir, ctrl, Some(plan));
    let verb = &ctrl.commands[plan.verb.index()].name;
    let source = &ir.files[plan.header.file.0 as usize];
    let mut out = String::new();
    header(&mut out, source);
    let _ = writeln!(
        out,
        "digraph {} {{",
        quoted(&format!("{}.{verb}", ctrl.name))
    );
    let title = format!("{} · {verb}", ctrl.name);
    let _ = writeln!(
        out,
        "    graph [label={}, labelloc=t, rankdir=LR, fontname=\"Helvetica\", tooltip={}];",
        quoted(&title),
        quoted(&plan.docs.join("\n"))
    );
    out.push_str("    node [fontname=\"Helvetica\", shape=circle];\n");
    out.push_str("    edge [fontname=\"Helvetica\", fontsize=10];\n");

    // Nodes in order of first appearance in the rows.
    let mut emitted: Vec<String> = Vec::new();
    let mut node = |out: &mut String, id: String, attrs: String| {
        if !emitted.contains(&id) {
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
    for r in &plan.rows {
        let from = from_node(&p, r);
        match r.from {
            From::DontCare(_) => node(
                &mut out,
                from.clone(),
                format!("label={}, style=dashed", quoted(&from)),
            ),
            From::State(_) => node(&mut out, from.clone(), String::new()),
        }
        match r.to {
            Target::Same => {}
            Target::State(_) => node(&mut out, p.target(r), String::new()),
            Target::Done => node(
                &mut out,
                "Done".to_string(),
                "shape=doublecircle".to_string(),
            ),
            Target::Error(_) => node(
                &mut out,
                "Error".to_string(),
                "shape=octagon, color=red, fontcolor=red".to_string(),
            ),
        }
    }
    for r in &plan.rows {
        let from = from_node(&p, r);
        let to = match r.to {
            Target::Same => from.clone(),
            Target::State(_) => p.target(r),
            Target::Done => "Done".to_string(),
            Target::Error(_) => "Error".to_string(),
        };
        let mut label = format!("{}: {}", p.label(r), p.condition(r));
        if let Target::Error(Some(_)) = r.to {
            label.push_str(&format!(" → {}", p.target(r)));
        }
        let mut html_label = html(&label);
        if !r.jobs.is_empty() {
            let jobs: Vec<String> = r.jobs.iter().map(|j| p.job(j)).collect();
            let _ = write!(
                html_label,
                "<BR/><FONT POINT-SIZE=\"8\">{}</FONT>",
                html(&jobs.join("; "))
            );
        }
        let mut attrs = format!(
            "id={}, label=<{html_label}>",
            quoted(&edge_id(&[r.display_name()]))
        );
        if r.is_otherwise() {
            attrs.push_str(", style=dashed");
        }
        let tip = if r.docs.is_empty() {
            format!("{}:{}", ir.files[r.span.file.0 as usize], r.line)
        } else {
            r.docs.join("\n")
        };
        let _ = write!(attrs, ", tooltip={}", quoted(&tip));
        let _ = writeln!(out, "    {} -> {} [{attrs}];", quoted(&from), quoted(&to));
    }
    out.push_str("}\n");
    out
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

fn from_node(p: &Printer, r: &rcs_dsl::ir::Row) -> String {
    match r.from {
        From::DontCare(_) => format!("*{}", r.position),
        From::State(s) => p.state(s),
    }
}

/// The controller tree, one cluster per executive ("CPU").
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
    for (i, cpu) in ir.schedule.iter().enumerate() {
        let _ = writeln!(out, "    subgraph {} {{", quoted(&format!("cluster_{i}")));
        let _ = writeln!(
            out,
            "        label={}; style=dashed; fontname=\"Helvetica\";",
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
                "        {} [id={}, label=<{label}>, tooltip={}];",
                quoted(&ctrl.name),
                quoted(&ctrl_id(&ctrl.name)),
                quoted(&ctrl.docs.join("\n"))
            );
        }
        out.push_str("    }\n");
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
