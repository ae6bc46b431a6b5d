//! The text of every-cycle processing and status data (LANGUAGE.md §7) in
//! the documents generated from the IR: the lines the state tables
//! (`table`) and the plan graphs (`dot`, as a note node) show for a
//! controller's status fields and its `pre`/`post` jobs. Pure functions;
//! empty for a controller that has none, so other outputs do not change.

use rcs_dsl::ir::{Controller, EveryCycle, Ir};
use rcs_dsl::pretty::Printer;

/// One line per status field: `name: type = init`.
pub(crate) fn status_field_lines(ir: &Ir, ctrl: &Controller) -> Vec<String> {
    let p = Printer::new(ir, ctrl, None);
    ctrl.status_fields()
        .map(|(_, v)| {
            let ty = rcs_dsl::type_name(ir, &v.ty);
            match &v.init {
                Some(e) => format!("{}: {ty} = {}", v.name, p.expr(e)),
                None => format!("{}: {ty}", v.name),
            }
        })
        .collect()
}

/// The jobs of a `pre`/`post` block as written, one per line.
pub(crate) fn job_lines(ir: &Ir, ctrl: &Controller, block: Option<&EveryCycle>) -> Vec<String> {
    let p = Printer::new(ir, ctrl, None);
    block
        .map(|b| b.jobs.iter().map(|j| p.job(j)).collect())
        .unwrap_or_default()
}

/// The note of a plan graph: status fields, then `pre` and `post` jobs;
/// `None` when the controller has none of them.
pub(crate) fn note(ir: &Ir, ctrl: &Controller) -> Option<String> {
    let mut parts = Vec::new();
    let fields = status_field_lines(ir, ctrl);
    if !fields.is_empty() {
        parts.push(format!("status fields: {}", fields.join(", ")));
    }
    for (kw, block) in [("pre", ctrl.pre.as_ref()), ("post", ctrl.post.as_ref())] {
        if block.is_some() {
            parts.push(format!(
                "{kw} (every cycle): {}",
                job_lines(ir, ctrl, block).join("; ")
            ));
        }
    }
    (!parts.is_empty()).then(|| parts.join("\n"))
}
