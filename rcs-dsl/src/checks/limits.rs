//! Stage 3, first of the checks: counts the runtime numbers in 16 bits —
//! states and rows of a plan, commands, statuses and error codes of a
//! controller, its subordinates. Past those, generated code and the status
//! buffer could not tell two of them apart, so a set that exceeds one gets
//! `too_large` and no further checks (the analysis of a plan that large
//! would take long and prove nothing useful).

use super::Sink;
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::Ir;
use crate::source::Span;

/// The most states or rows of one plan, and commands, error codes or
/// subordinates of one controller: ids run from 0 to 65,534, with room
/// left for the runtime's own markers.
pub const MAX_COUNT: usize = u16::MAX as usize;
/// The most custom statuses of one controller: status codes are 16-bit,
/// and the four built-in statuses come first.
pub const MAX_CUSTOM_STATUSES: usize = MAX_COUNT - 4;

/// Report every count over its limit; `true` when there was one.
pub(crate) fn check_limits(ir: &Ir, sink: &mut Sink) -> bool {
    let mut over = false;
    let mut report = |what: String, count: usize, limit: usize, span: Span| {
        over = true;
        sink.error(
            Diagnostic::error(
                Code::TooLarge,
                format!("{what} has {count}, more than the {limit} the runtime can number"),
                span,
                "declared here",
            )
            .with_help("split it: several plans or controllers, each within the limit"),
        );
    };
    for c in &ir.controllers {
        let customs = c.statuses.len().saturating_sub(4);
        for (what, count, limit) in [
            ("commands", c.commands.len(), MAX_COUNT),
            ("custom statuses", customs, MAX_CUSTOM_STATUSES),
            ("error codes", c.errors.len(), MAX_COUNT),
            ("subordinates", c.subordinates.len(), MAX_COUNT),
        ] {
            if count > limit {
                report(
                    format!("controller `{}`: {what}", c.name),
                    count,
                    limit,
                    c.span,
                );
            }
        }
        for p in &c.plans {
            let verb = &c.plan_title(p);
            for (what, count) in [("states", p.states.len()), ("rows", p.rows.len())] {
                if count > MAX_COUNT {
                    let name = format!("plan `{verb}` of `{}`: {what}", c.name);
                    report(name, count, MAX_COUNT, p.header);
                }
            }
        }
    }
    over
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnostic::Diagnostics;
    use crate::ir::{State, StatusDef};
    use crate::lint::LintLevels;
    use crate::PlanSet;

    /// A small plan set's IR, grown by `grow`, through the checks: the codes.
    fn codes_after(grow: impl FnOnce(&mut Ir)) -> Vec<&'static str> {
        let text =
            "controller A {\n    command GO\n    plan GO { *0 when new_command -> Done }\n}\n";
        let set = PlanSet::from_texts("limits", [("a.rcs", text)], None);
        let Some(mut ir) = crate::lower_unchecked(&set) else {
            return vec!["lowering failed"];
        };
        grow(&mut ir);
        let mut diags = Diagnostics::new();
        super::super::run(&ir, &LintLevels::default(), &set.sources, &mut diags);
        let mut codes: Vec<&str> = diags.into_vec().iter().map(|d| d.code.name()).collect();
        codes.dedup();
        codes
    }

    fn statuses(ir: &mut Ir, customs: usize) {
        let c = &mut ir.controllers[0];
        for i in 0..customs {
            c.statuses.push(StatusDef {
                name: format!("S{i}"),
                docs: Vec::new(),
                span: None,
            });
        }
    }

    #[test]
    fn custom_statuses_up_to_the_limit() {
        assert_eq!(
            codes_after(|ir| statuses(ir, MAX_CUSTOM_STATUSES + 1)),
            ["too_large"]
        );
        assert!(!codes_after(|ir| statuses(ir, MAX_CUSTOM_STATUSES)).contains(&"too_large"));
    }

    #[test]
    fn states_of_a_plan_up_to_the_limit() {
        let states = |n: usize| {
            move |ir: &mut Ir| {
                let p = &mut ir.controllers[0].plans[0];
                for i in p.states.len()..n {
                    p.states.push(State {
                        name: format!("S{i}"),
                        span: None,
                    });
                }
            }
        };
        assert_eq!(codes_after(states(MAX_COUNT + 1)), ["too_large"]);
        // Within the limit the other checks run (and report the states no
        // row reaches), but not this one.
        assert!(!codes_after(states(MAX_COUNT)).contains(&"too_large"));
    }
}
