//! The rows no scenario fired (`rcsc test --coverage`), and the row and
//! state counts of each plan set's own scenarios that `rcsc doc
//! --coverage` draws.

use super::files::{assign, load, set_folder};
use super::run::{run_set, Fired};
use rcs_codegen::site::RunCounts;
use rcs_dsl::ir::Ir;
use rcs_dsl::PlanSet;

/// Per plan of the set: rows fired out of rows, and where each unfired row is.
pub fn coverage(set: &PlanSet, ir: &Ir, fired: &Fired) -> (String, usize, usize) {
    let mut text = String::new();
    let (mut hit, mut all) = (0, 0);
    for c in &ir.controllers {
        for (vi, k) in c.commands.iter().enumerate() {
            let Some(pid) = k.plan else { continue };
            let plan = &c.plans[pid.index()];
            // A shared plan (`plan A | B`) is counted once, as its first verb.
            if plan.verb.index() != vi {
                continue;
            }
            let missing: Vec<_> = plan
                .rows
                .iter()
                .filter(|r| fired.row(&c.name, vi as u32, r.position) == 0)
                .collect();
            let n = plan.rows.len();
            hit += n - missing.len();
            all += n;
            text.push_str(&format!(
                "  {:<24} {}/{} rows\n",
                format!("{}.{}", c.name, c.plan_title(plan)),
                n - missing.len(),
                n
            ));
            for r in missing {
                let file = set.sources.get(r.span.file);
                let (line, col) = file.line_col(r.span.start as usize);
                text.push_str(&format!(
                    "      not fired: {:<10} {}:{line}:{col}\n",
                    r.display_name(),
                    file.path
                ));
            }
        }
    }
    (text, hit, all)
}

/// Row hits and cycles per state of each plan set's own scenarios (its
/// `scenarios/` folder), run on the interpreter: what `rcsc doc
/// --coverage` draws. A scenario that fails still counts what it ran.
pub fn scenario_counts(sets: &[PlanSet], irs: &[Ir]) -> Result<Vec<RunCounts>, String> {
    let per_set = assign(sets, &[])?;
    let mut out = Vec::new();
    for ((ir, files), set) in irs.iter().zip(&per_set).zip(sets) {
        let loaded: Vec<_> = files.iter().map(|p| load(ir, p)).collect();
        let mut fired = Fired {
            source: format!(
                "{} of {}",
                crate::output::plural(loaded.len(), "scenario"),
                rcs_dsl::load::display(&set_folder(set).join("scenarios"))
            ),
            ..Fired::default()
        };
        run_set(ir, &loaded, None, &mut fired, None)?;
        out.push(fired);
    }
    Ok(out)
}
