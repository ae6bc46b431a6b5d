//! Checks of the controller hierarchy: `span_of_control` (7±2) and `level_order`.

use super::Sink;
use crate::diagnostic::Diagnostic;
use crate::ir::Ir;
use crate::lint::Lint;

pub(crate) fn check_span_of_control(ir: &Ir, sink: &mut Sink) {
    let max = ir.limits.max_subordinates as usize;
    for c in &ir.controllers {
        if c.subordinates.len() <= max {
            continue;
        }
        let (first, more) = match c.subordinates_lists.split_first() {
            Some((first, more)) => (*first, more),
            None => (c.name_span, &[][..]),
        };
        let mut d = Diagnostic::lint(
            Lint::SpanOfControl,
            format!(
                "`{}` supervises {} controllers; the limit is {max}",
                c.name,
                c.subordinates.len()
            ),
            first,
            "too many subordinates",
        );
        for span in more {
            d = d.with_secondary(*span, "more subordinates here");
        }
        sink.lint(
            Some(c),
            None,
            d.with_note("a supervisor coordinates 7±2 subordinates at most (§3.5)")
                .with_help("group subordinates under an intermediate controller"),
        );
    }
}

pub(crate) fn check_level_order(ir: &Ir, sink: &mut Sink) {
    for c in &ir.controllers {
        let Some(level) = c.level else { continue };
        for (sub, span) in c.subordinates.iter().zip(&c.subordinate_spans) {
            let s = &ir.controllers[sub.index()];
            let Some(sub_level) = s.level else { continue };
            if sub_level < level {
                continue;
            }
            sink.lint(
                Some(c),
                None,
                Diagnostic::lint(
                    Lint::LevelOrder,
                    format!("subordinate `{}` is at level {sub_level}, not below its supervisor `{}` at level {level}", s.name, c.name),
                    *span,
                    format!("level {sub_level}"),
                )
                .with_secondary(s.name_span, format!("`{}` declared here", s.name))
                .with_help("a subordinate sits at a lower RCS level than its supervisor (§2.3.3)"),
            );
        }
    }
}
