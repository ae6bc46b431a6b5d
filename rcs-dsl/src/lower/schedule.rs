//! Stage 2, lowering: the schedule — which CPU runs which controllers in
//! which order, from the manifest or one CPU by default.

use super::*;

/// The executives: the manifest's `schedule`, or one CPU running every
/// controller top-down (pre-order from each root, in declaration order).
pub(super) fn lower_schedule(ir: &Ir, m: &Manifest, diags: &mut Diagnostics) -> Vec<Cpu> {
    let Some(specs) = &m.schedule else {
        let mut order = Vec::new();
        let mut seen = vec![false; ir.controllers.len()];
        for (i, c) in ir.controllers.iter().enumerate() {
            if c.supervisor.is_none() {
                preorder(ir, CtrlId(i as u32), &mut order, &mut seen);
            }
        }
        // Controllers caught in a cycle have no root; keep them in declaration order.
        for (i, s) in seen.iter().enumerate() {
            if !s {
                order.push(CtrlId(i as u32));
            }
        }
        return vec![Cpu {
            name: "main".to_string(),
            period_ns: DEFAULT_PERIOD_NS,
            order,
            process: None,
            inputs: Vec::new(),
            period_given: false,
        }];
    };
    let mut placed: Vec<Option<Span>> = vec![None; ir.controllers.len()];
    let mut cpus = Vec::new();
    for spec in specs {
        let mut order = Vec::new();
        for (name, span) in &spec.order {
            match ir.controller_by_name(name) {
                None => diags.push(
                    Diagnostic::error(
                        Code::Manifest,
                        format!("`schedule` names `{name}`, which is not a controller"),
                        *span,
                        "unknown controller",
                    )
                    .with_help(format!(
                        "the controllers are: {}",
                        ir.controllers
                            .iter()
                            .map(|c| c.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )),
                ),
                Some(id) => {
                    if let Some(first) = placed[id.index()] {
                        diags.push(
                            Diagnostic::error(
                                Code::Manifest,
                                format!("controller `{name}` is scheduled twice"),
                                *span,
                                "scheduled again here",
                            )
                            .with_secondary(first, "first scheduled here")
                            .with_help("every controller runs exactly once per cycle, on one CPU"),
                        );
                    } else {
                        placed[id.index()] = Some(*span);
                        order.push(id);
                    }
                }
            }
        }
        cpus.push(Cpu {
            name: spec.name.clone(),
            period_ns: spec.period_ns,
            order,
            process: spec.process.as_ref().map(|p| p.0.clone()),
            inputs: Vec::new(),
            period_given: spec.period_given,
        });
    }
    let missing: Vec<&str> = ir
        .controllers
        .iter()
        .zip(&placed)
        .filter(|(_, p)| p.is_none())
        .map(|(c, _)| c.name.as_str())
        .collect();
    if !missing.is_empty() {
        let span = m
            .schedule_span
            .or_else(|| specs.first().map(|s| s.span))
            .expect("a schedule has a span");
        diags.push(
            Diagnostic::error(
                Code::Manifest,
                format!(
                    "the schedule leaves out {}",
                    missing
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                span,
                "not every controller is scheduled",
            )
            .with_help("list every controller exactly once across all CPUs' `order`"),
        );
    }
    crate::placement::lower_inputs(ir, specs, &mut cpus, diags);
    cpus
}

/// Pre-order walk, iterative so that a deep hierarchy cannot exhaust the stack.
fn preorder(ir: &Ir, root: CtrlId, out: &mut Vec<CtrlId>, seen: &mut [bool]) {
    let mut stack = vec![root];
    while let Some(id) = stack.pop() {
        if std::mem::replace(&mut seen[id.index()], true) {
            continue;
        }
        out.push(id);
        stack.extend(ir.controllers[id.index()].subordinates.iter().rev());
    }
}

/// The period each controller's CPU runs at, by controller name, and
/// whether the manifest gives it: read from the manifest before the
/// controllers are lowered, since `state_time > 5s` is lowered to cycles
/// of that period (`lower::time`). A controller no CPU names (an error
/// reported with the schedule) and every controller of a set without a
/// schedule take the default.
pub(super) fn periods(m: &Manifest) -> BTreeMap<String, (u64, bool)> {
    let mut out = BTreeMap::new();
    for spec in m.schedule.iter().flatten() {
        for (name, _) in &spec.order {
            out.entry(name.clone())
                .or_insert((spec.period_ns, spec.period_given));
        }
    }
    out
}
