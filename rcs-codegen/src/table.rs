//! IR → Markdown state tables, one file per controller with one table per
//! plan, in Appendix C's layout: Row | IF event | current state | THEN next
//! state | job list, and a last column with the rows' doc comments when
//! any row of the plan has one. The `otherwise` row reads `E10 otherwise`
//! as in the graphs: condition `otherwise`, current state `any`. A pure
//! function returning a string.

use crate::GENERATED;
use rcs_dsl::ir::{Controller, From, Ir, Row, Target};
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
        // A row of one state that stays, stays there; any other row
        // (`*`, a set, `except`, `otherwise`) wherever it fired.
        Target::Same => match r.from {
            From::State(_) => format!("{} (same)", p.from(r)),
            _ => "same".to_string(),
        },
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
    if let Some(inst) = &ctrl.instance_of {
        let _ = writeln!(out, "{}\n", instance_line(inst));
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
    every_cycle(ir, ctrl, &mut out);
    for (ci, cmd) in ctrl.commands.iter().enumerate() {
        let Some(pid) = cmd.plan else { continue };
        let plan = &ctrl.plans[pid.index()];
        // A plan shared by verbs (`plan A | B`) is one table, where its
        // first verb stands, titled with all of them.
        if plan.verb.index() != ci {
            continue;
        }
        let title = ctrl.plan_title(plan);
        let p = Printer::new(ir, ctrl, Some(plan));
        let params: Vec<String> = cmd
            .params
            .iter()
            .map(|x| format!("{}: {}", x.name, rcs_dsl::type_name(ir, &x.ty)))
            .collect();
        if params.is_empty() {
            let _ = writeln!(out, "## {title}\n");
        } else {
            let _ = writeln!(out, "## {title}({})\n", params.join(", "));
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
        // Refusal (step 3a): each verb of the plan with `accept when`.
        for v in &plan.verbs {
            let k = &ctrl.commands[v.index()];
            if let Some(a) = &k.accept {
                let _ = writeln!(
                    out,
                    "{} is accepted only when {}; otherwise it is refused: the running plan goes on and the sender sees ERROR (REFUSED).\n",
                    k.name,
                    code(&p.expr(&a.cond))
                );
            }
        }
        let notes = plan.rows.iter().any(|r| !r.docs.is_empty());
        out.push_str("| Row | IF (event) | current state | THEN next state | job list |");
        out.push_str(if notes { " notes |\n" } else { "\n" });
        out.push_str("|---|---|---|---|---|");
        out.push_str(if notes { "---|\n" } else { "\n" });
        for r in &plan.rows {
            // A set's `|` escaped, so that it stays in its cell.
            let from = if r.is_otherwise() {
                "any".to_string()
            } else {
                cell(&p.from(r))
            };
            let (next, jobs) = next_and_jobs(&p, r);
            let mut row = if r.is_otherwise() {
                crate::dot::otherwise_name(r)
            } else {
                p.label(r)
            };
            if let Some(shared) = &r.shared {
                let _ = write!(row, " (`{}`)", shared.block);
            }
            let mut jobs: Vec<String> = jobs.iter().map(|j| code(j)).collect();
            match r.to {
                Target::Done => jobs.push("status DONE".to_string()),
                Target::Error(_) | Target::ErrorOf(_) => jobs.push("status ERROR".to_string()),
                _ => {}
            }
            let _ = write!(
                out,
                "| {row} | {} | {from} | {next} | {} |",
                code(&p.condition(r)),
                if jobs.is_empty() {
                    "—".to_string()
                } else {
                    jobs.join("<br>")
                }
            );
            if notes {
                let _ = write!(out, " {} |", cell(&r.docs.join(" ")));
            }
            out.push('\n');
        }
        let mut blocks: Vec<&str> = plan
            .rows
            .iter()
            .filter_map(|r| r.shared.as_ref().map(|s| s.block.as_str()))
            .collect();
        blocks.dedup();
        if !blocks.is_empty() {
            let list: Vec<String> = blocks.iter().map(|b| format!("`rows {b}`")).collect();
            let _ = writeln!(
                out,
                "\nRows marked (`NAME`) are placed by `use NAME` from {}, written once for every plan that uses it.",
                list.join(", ")
            );
        }
        out.push('\n');
    }
    out
}

/// "An instance of `T`(args), with …": an instance's line under its
/// title, for its tables and its page.
pub fn instance_line(inst: &rcs_dsl::ir::InstanceOf) -> String {
    let args: Vec<String> = inst.args.iter().map(|(n, v)| format!("{n}: {v}")).collect();
    let mut line = format!("An instance of controller type `{}`", inst.ty);
    if !args.is_empty() {
        let _ = write!(line, " with {}", args.join(", "));
    }
    if !inst.bindings.is_empty() {
        let b: Vec<String> = inst
            .bindings
            .iter()
            .map(|(l, g)| format!("`{l}` is `{g}`"))
            .collect();
        let _ = write!(line, "; {}", b.join(", "));
    }
    line.push('.');
    line
}

/// Status fields and `pre`/`post` jobs, before the tables (nothing for a
/// controller without them).
fn every_cycle(ir: &Ir, ctrl: &Controller, out: &mut String) {
    let fields = crate::every_cycle::status_field_lines(ir, ctrl);
    if !fields.is_empty() {
        let list: Vec<String> = fields.iter().map(|f| code(f)).collect();
        let _ = writeln!(
            out,
            "Status fields (published every cycle): {}.\n",
            list.join(", ")
        );
    }
    for (what, block) in [
        ("Every cycle, before the rows (`pre`)", ctrl.pre.as_ref()),
        ("Every cycle, after the row (`post`)", ctrl.post.as_ref()),
    ] {
        if block.is_some() {
            let jobs: Vec<String> = crate::every_cycle::job_lines(ir, ctrl, block)
                .iter()
                .map(|j| code(j))
                .collect();
            let _ = writeln!(out, "{what}: {}.\n", jobs.join("; "));
        }
    }
}
