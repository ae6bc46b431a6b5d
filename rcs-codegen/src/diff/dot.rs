//! A changed plan as a diff-coloured state graph: the rows of both
//! versions drawn in the notation of [`crate::dot`] (one edge per pair of
//! nodes, one label line per row), each line coloured by what happened to
//! its row — added green, removed red, changed orange, moved in precedence
//! marked `⇅` — and each edge coloured by its rows (red and dashed when all
//! of them were removed). States added are green, removed red and dashed.
//! As in a plan graph, an edge shows its rows' names (with their change
//! sign, `+E5`) and the rows in full are in the state table under the
//! drawing, each line in its row's colour, the key to the signs under it.

use crate::dot::legend::{self, TableRow};
use crate::dot::{
    graph_head, merge_edges, node_attrs, quoted, rankdir, write_edge, Line, SMALL_FONT,
};
use rcs_dsl::diff::{PlanDiff, RowChange, RowDiff};
use std::fmt::Write;

const GREEN: &str = "darkgreen";
const RED: &str = "red";
const ORANGE: &str = "darkorange";

fn color(r: &RowDiff) -> Option<&'static str> {
    match r.change {
        RowChange::Added => Some(GREEN),
        RowChange::Removed => Some(RED),
        RowChange::Changed(_) => Some(ORANGE),
        RowChange::Same => None,
    }
}

/// The diff graph of one plan. `source` names where the plans came from
/// (`HEAD~1..working tree`), for the header comment.
pub fn diff_dot(plan: &PlanDiff, source: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// {} diff of {} ({source}). Do not edit.",
        crate::GENERATED,
        plan.name()
    );
    let name = plan.name();
    let moved: Vec<&str> = plan
        .moves
        .iter()
        .flat_map(|m| [m.now_first.as_str(), m.now_second.as_str()])
        .collect();
    let mut nodes: Vec<String> = Vec::new();
    let mut edges = Vec::new();
    let mut notes = Vec::new();
    let mut rows = Vec::new();
    for r in &plan.rows {
        let Some(v) = r.new.as_ref().or(r.old.as_ref()) else {
            continue;
        };
        let mark = if r.new.is_some() && moved.contains(&v.label.as_str()) {
            "⇅ "
        } else {
            ""
        };
        let sign = match r.change {
            RowChange::Added => "+ ",
            RowChange::Removed => "− ",
            RowChange::Changed(_) => "~ ",
            RowChange::Same => "",
        };
        let mut tooltip = format!("{}:{}", v.file, v.line);
        if let (RowChange::Changed(_), Some(o)) = (&r.change, &r.old) {
            tooltip.push_str(&format!("\nwas: {}", o.text()));
        }
        rows.push(TableRow {
            name: format!("{mark}{sign}{}", v.label),
            from: if v.otherwise {
                "any (no row matched)".to_string()
            } else {
                v.from.clone()
            },
            to: v.target.clone(),
            condition: v.condition.clone(),
            jobs: v.jobs.clone(),
            color: color(r),
        });
        tooltip = format!("{}\n{tooltip}", v.text());
        // No ids: a row may stand on both sides of a diff under one name.
        let line = Line {
            row: String::new(),
            name: format!("{mark}{}{}", sign.trim_end(), v.label),
            tooltip,
            color: color(r),
        };
        if v.otherwise {
            // Not an edge of any state: a note, with an arrow when it
            // leaves the state (as in `crate::dot`).
            let to = (v.target != "same").then(|| v.to_node(""));
            if let Some(t) = to.as_ref().filter(|t| !nodes.contains(t)) {
                nodes.push(t.clone());
            }
            notes.push((format!("{} otherwise", v.label), line, to));
            continue;
        }
        // A set is one edge per state, each with the row's line.
        for from in v.from_nodes() {
            let to = v.to_node(&from);
            for n in [&from, &to] {
                if !nodes.contains(n) {
                    nodes.push(n.clone());
                }
            }
            edges.push((from, to, line.clone()));
        }
    }
    let edges = merge_edges(edges);
    let key = "+ added · − removed · ~ changed · ⇅ moved in precedence".to_string();
    graph_head(
        &mut out,
        &name,
        &[],
        rankdir(&nodes, &edges),
        &legend::table(&name.replacen('.', " · ", 1), &rows, &[key]),
    );
    for n in &nodes {
        let mut attrs = node_attrs(n);
        if plan.states_added.contains(n) {
            attrs = format!("color={GREEN}, fontcolor={GREEN}, penwidth=2");
        } else if plan.states_removed.contains(n) {
            attrs = format!("color={RED}, fontcolor={RED}, style=dashed");
        }
        let _ = writeln!(out, "    {} [{attrs}];", quoted(n));
    }
    for (id, line, to) in &notes {
        let c = line.color.unwrap_or("black");
        let _ = writeln!(
            out,
            "    {} [label={}, shape=note, style=dashed, fontsize={SMALL_FONT}, color={c}, fontcolor={c}, tooltip={}];",
            quoted(id),
            quoted(&format!("{} otherwise", line.name)),
            quoted(&line.tooltip)
        );
        if let Some(to) = to {
            let _ = writeln!(
                out,
                "    {} -> {} [style=dashed, color={c}];",
                quoted(id),
                quoted(to)
            );
        }
    }
    for e in &edges {
        let colors: Vec<Option<&str>> = e.lines.iter().map(|l| l.color).collect();
        let mut attrs = String::new();
        let first = colors.first().copied().flatten();
        if let Some(c) = first.filter(|_| colors.iter().all(|c| *c == first)) {
            let _ = write!(attrs, ", color={c}");
            if c == RED {
                attrs.push_str(", style=dashed");
            }
        } else if colors.iter().any(Option::is_some) {
            let _ = write!(attrs, ", color={ORANGE}");
        }
        if e.lines.iter().any(|l| l.name.starts_with('⇅')) {
            attrs.push_str(", penwidth=2");
        }
        write_edge(&mut out, e, &attrs);
    }
    out.push_str("}\n");
    out
}
