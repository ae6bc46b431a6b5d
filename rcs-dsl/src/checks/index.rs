//! Stage 3, the `index_range` lint: an index by a run-time value that can
//! fall outside its array on a cycle the interpreter gets to it, ending the
//! plan with `INDEX_RANGE`. The sites, the proofs and the replayed runs
//! come from [`crate::analysis::index_range`]; here they become
//! diagnostics. A site the analysis does not decide says nothing.

use super::Sink;
use crate::analysis::PlanAnalysis;
use crate::diagnostic::Diagnostic;
use crate::ir::{Controller, Ir, Plan, Type};
use crate::lint::Lint;

pub(crate) fn check_index_range(
    ir: &Ir,
    c: &Controller,
    p: &Plan,
    an: &PlanAnalysis,
    out_of_range: &[crate::analysis::index_range::OutOfRange],
    sink: &mut Sink,
) {
    let printer = crate::pretty::Printer::new(ir, c, Some(p));
    for found in out_of_range {
        let site = &an.index_sites()[found.site];
        let index = printer.expr(&site.index);
        let len = site.len;
        let state = p
            .states
            .get(found.witness.state.index())
            .map_or("?", |s| s.name.as_str());
        let (where_, then) = match site.job {
            _ if site.pre => (
                "",
                "`pre` meets this index on the command's first cycle: no row fires, and the plan ends with the error INDEX_RANGE",
            ),
            Some(_) => (
                "in a job",
                "the row fires, its jobs stop at this index, and the plan ends with the error INDEX_RANGE",
            ),
            None => (
                "in its condition",
                "the interpreter gets to this index while trying the rows: no row fires, and the plan ends with the error INDEX_RANGE",
            ),
        };
        let signed = matches!(&site.index.ty, Type::Int(t) if t.range().0 < 0);
        let guard = if signed {
            format!("`{index} >= 0 && {index} < {len}`")
        } else {
            format!("`{index} < {len}`")
        };
        let message = if site.pre {
            format!(
                "`pre` of `{}` can index `{}` outside 0..{len}",
                c.name, site.array
            )
        } else {
            format!(
                "row {} of plan `{}` can index `{}` outside 0..{len} {where_}",
                p.rows
                    .get(site.row)
                    .map_or_else(String::new, |r| r.display_name()),
                c.plan_title(p),
                site.array,
            )
        };
        let last = len.saturating_sub(1);
        let fix = if site.pre {
            // `pre` has no condition: the index itself must stay inside.
            let kept = if signed {
                format!("clamp({index}, 0, {last})")
            } else {
                format!("min({index}, {last})")
            };
            format!("keep the index inside the array: `{kept}`")
        } else {
            format!("guard the row: {guard} in its condition, before the index is read")
        };
        let d = Diagnostic::lint(
            Lint::IndexRange,
            message,
            site.span,
            format!("`{index}` can be outside 0..{len} here"),
        )
        .with_witness(state, &found.witness.shown)
        .with_run(Some(found.run.clone()))
        .with_note(format!("with these inputs {then}"))
        .with_help(format!(
            "{fix}; or accept INDEX_RANGE as the error with `#[allow(index_range)]`"
        ));
        sink.lint(Some(c), (!site.pre).then_some(p), d);
    }
}
