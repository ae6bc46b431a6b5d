//! IR → Markdown state tables, one file per controller with one table per
//! plan, in Appendix C's layout: Row | IF event | current state | THEN next
//! state | job list. A pure function returning a string.

use crate::GENERATED;
use rcs_dsl::ir::{Controller, Ir, Row, Target};
use rcs_dsl::pretty::Printer;
use std::fmt::Write;

/// Text inside a table cell: `|` would end the cell, a newline the row.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

fn code(s: &str) -> String {
    format!("`{}`", cell(s))
}

/// A row's THEN cell (the next state; `S1 (same)` for `same`) and its jobs
/// as the language writes them, for every table of rows (here and the doc
/// site's).
pub fn next_and_jobs(p: &Printer, r: &Row) -> (String, Vec<String>) {
    let next = match r.to {
        Target::Same => format!(
            "{} (same)",
            if r.is_dont_care() {
                "—".to_string()
            } else {
                p.from(r)
            }
        ),
        _ => p.target(r),
    };
    (next, r.jobs.iter().map(|j| p.job(j)).collect())
}

/// The state tables of every plan of one controller.
pub fn controller_tables(ir: &Ir, ctrl: &Controller) -> String {
    let mut out = String::new();
    let source = &ir.files[ctrl.span.file.0 as usize];
    let _ = writeln!(out, "<!-- {GENERATED} from {source}. Do not edit. -->\n");
    match &ctrl.title {
        Some(t) => {
            let _ = writeln!(out, "# {} — {}\n", ctrl.name, t);
        }
        None => {
            let _ = writeln!(out, "# {}\n", ctrl.name);
        }
    }
    if !ctrl.docs.is_empty() {
        let _ = writeln!(out, "{}\n", ctrl.docs.join("\n"));
    }
    let subs: Vec<&str> = ctrl
        .subordinates
        .iter()
        .map(|s| ir.controller(*s).name.as_str())
        .collect();
    let sup = ctrl
        .supervisor
        .map(|s| ir.controller(s).name.as_str())
        .unwrap_or("the operator");
    let _ = writeln!(
        out,
        "Commanded by {sup}; commands {}.\n",
        if subs.is_empty() {
            "no subordinates".to_string()
        } else {
            subs.join(", ")
        }
    );
    for cmd in &ctrl.commands {
        let Some(pid) = cmd.plan else { continue };
        let plan = &ctrl.plans[pid.index()];
        let p = Printer::new(ir, ctrl, Some(plan));
        let params: Vec<String> = cmd
            .params
            .iter()
            .map(|x| format!("{}: {}", x.name, rcs_dsl::type_name(ir, &x.ty)))
            .collect();
        if params.is_empty() {
            let _ = writeln!(out, "## {}\n", cmd.name);
        } else {
            let _ = writeln!(out, "## {}({})\n", cmd.name, params.join(", "));
        }
        let docs: Vec<&String> = cmd.docs.iter().chain(&plan.docs).collect();
        if !docs.is_empty() {
            let _ = writeln!(
                out,
                "{}\n",
                docs.iter()
                    .map(|s| s.as_str())
                    .collect::<Vec<_>>()
                    .join("\n")
            );
        }
        out.push_str("| Row | IF (event) | current state | THEN next state | job list |\n");
        out.push_str("|---|---|---|---|---|\n");
        for r in &plan.rows {
            let (next, jobs) = next_and_jobs(&p, r);
            let mut jobs: Vec<String> = jobs.iter().map(|j| code(j)).collect();
            match r.to {
                Target::Done => jobs.push("status DONE".to_string()),
                Target::Error(_) => jobs.push("status ERROR".to_string()),
                _ => {}
            }
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} |",
                p.label(r),
                code(&p.condition(r)),
                p.from(r),
                next,
                if jobs.is_empty() {
                    "—".to_string()
                } else {
                    jobs.join("<br>")
                }
            );
        }
        out.push('\n');
    }
    out
}
