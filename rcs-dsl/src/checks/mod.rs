//! Stage 3: checks over the IR. Each rule is its own `check_*` function that
//! reads the IR and pushes findings into one [`Sink`]; none changes the IR.
//! Hard errors go in as they are; lints pass through the lint levels in
//! force at their place (manifest, flags, then attributes).

mod graph;
mod handshake;
mod hang;
mod hierarchy;
mod limits;
mod loops;
pub(crate) mod names;
mod plan;
mod usage;

use crate::analysis::PlanAnalysis;
use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::ir::{Controller, Ir, Plan};
use crate::lint::{Lint, LintLevels};
use crate::source::SourceMap;

/// Where findings go: errors straight through, lints through their levels.
pub(crate) struct Sink<'a> {
    levels: &'a LintLevels,
    diags: &'a mut Diagnostics,
}

impl Sink<'_> {
    pub fn error(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    /// A lint finding inside `ctrl` (and `plan`, if any); attributes there apply.
    pub fn lint(&mut self, ctrl: Option<&Controller>, plan: Option<&Plan>, d: Diagnostic) {
        let crate::diagnostic::Code::Lint(lint) = d.code else {
            unreachable!("Sink::lint takes lint findings only")
        };
        let mut scopes: Vec<&[(Lint, crate::lint::Level)]> = Vec::new();
        if let Some(c) = ctrl {
            scopes.push(&c.lints);
        }
        if let Some(p) = plan {
            scopes.push(&p.lints);
        }
        let level = self.levels.at(lint, &scopes);
        // Say where the level came from: the innermost attribute naming the
        // lint, else the plan set's settings, else the default.
        let by_attribute =
            |lints: &[(Lint, crate::lint::Level)]| lints.iter().any(|(l, _)| *l == lint);
        let source = match (ctrl, plan) {
            (Some(c), Some(p)) if by_attribute(&p.lints) => {
                Source::Attribute(format!("plan `{}`", c.commands[p.verb.index()].name))
            }
            (Some(c), _) if by_attribute(&c.lints) => {
                Source::Attribute(format!("controller `{}`", c.name))
            }
            _ if self.levels.get(lint) != lint.default_level() => Source::PlanSet,
            _ => Source::Default,
        };
        let Some(mut d) = d.at_level(level, matches!(source, Source::Default)) else {
            return;
        };
        let attr = format!("`#[{}({})]`", level.name(), lint.name());
        let note = match source {
            Source::Default => None,
            Source::Attribute(on) => Some(format!("{attr} set by an attribute on {on}")),
            Source::PlanSet => Some(format!(
                "level `{}` set for the plan set (`lints:` in `rcs.yaml`, or a command-line flag)",
                level.name()
            )),
        };
        if let (Some(note), Some(last)) = (note, d.notes.last_mut()) {
            *last = note;
        }
        self.diags.push(d);
    }
}

/// Where a lint's level at a place comes from, for the note that says so.
enum Source {
    Default,
    /// An attribute on the named controller or plan.
    Attribute(String),
    /// The manifest's `lints:` or a command-line flag.
    PlanSet,
}

/// Run every check over a lowered plan set.
pub fn run(ir: &Ir, levels: &LintLevels, sources: &SourceMap, diags: &mut Diagnostics) {
    let start = diags.len();
    let mut sink = Sink { levels, diags };
    if limits::check_limits(ir, &mut sink) {
        diags.sort_from(start, sources);
        return;
    }
    plan::check_missing_plans(ir, &mut sink);
    names::check_case_collisions(ir, &mut sink);
    // The analysis of every plan's conditions and its graph first: the
    // checks of a plan ask its own, the handshake checks their
    // subordinates'.
    let (conditions, graphs) = analyse_plans(ir);
    for (ci, c) in ir.controllers.iter().enumerate() {
        for (pi, p) in c.plans.iter().enumerate() {
            let (conditions, analysis) = (&conditions[ci][pi], &graphs[ci][pi]);
            plan::check_row_numbers(c, p, &mut sink);
            plan::check_otherwise(p, &mut sink);
            plan::check_entry(p, &mut sink);
            plan::check_double_commands(ir, p, &mut sink);
            plan::check_rule_of_ten(ir, c, p, &mut sink);
            plan::check_unreachable_rows(p, analysis, &mut sink);
            let bound = hang::entry_bound_rows(p, analysis, conditions);
            hang::check_entry_bound_rows(p, &bound, conditions, &mut sink);
            let bound: Vec<usize> = bound.iter().map(|b| b.row).collect();
            plan::check_shadowed_rows(c, p, analysis, conditions, &bound, &mut sink);
            graph::check_unreachable_states(c, p, analysis, &mut sink);
            graph::check_dead_ends(c, p, analysis, &mut sink);
            graph::check_no_done(ir, c, p, analysis, &mut sink);
            hang::check_incomplete_states(c, p, conditions, analysis, &mut sink);
            loops::check_livelocks(c, p, conditions, &mut sink);
            loops::check_command_storms(ir, c, p, conditions, &mut sink);
        }
    }
    let plans = handshake::Plans { conditions, graphs };
    handshake::check_unhandled_error(ir, &plans, &mut sink);
    handshake::check_status_never_reported(ir, &plans, &mut sink);
    hierarchy::check_span_of_control(ir, &mut sink);
    hierarchy::check_level_order(ir, &mut sink);
    usage::check_float_equality(ir, &mut sink);
    usage::check_unused(ir, &mut sink);
    diags.sort_from(start, sources);
}

/// Per controller, per plan: the analysis of its conditions, and its graph.
type Analysed<'ir> = (Vec<Vec<PlanAnalysis<'ir>>>, Vec<Vec<graph::Analysis>>);

/// The analysis of every plan and its graph (which asks the analysis most
/// of the questions the checks need, and remembers the proofs), on as many
/// threads as the machine has: plans are independent, and this is most of
/// the time of the checks. Results come back in controller order, so the
/// findings do not depend on the threads.
fn analyse_plans(ir: &Ir) -> Analysed<'_> {
    fn analyse<'ir>(
        ir: &'ir Ir,
        c: &'ir Controller,
    ) -> (Vec<PlanAnalysis<'ir>>, Vec<graph::Analysis>) {
        let conditions: Vec<PlanAnalysis> = c
            .plans
            .iter()
            .map(|p| PlanAnalysis::new(ir, c, p))
            .collect();
        let graphs = c
            .plans
            .iter()
            .zip(&conditions)
            .map(|(p, a)| graph::analyse(p, a))
            .collect();
        (conditions, graphs)
    }
    let plans: usize = ir.controllers.iter().map(|c| c.plans.len()).sum();
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(ir.controllers.len());
    // Below a few dozen plans a thread costs more than it saves.
    let per_controller: Vec<_> = if threads < 2 || plans < 64 {
        ir.controllers.iter().map(|c| analyse(ir, c)).collect()
    } else {
        let chunk = ir.controllers.len().div_ceil(threads);
        std::thread::scope(|scope| {
            let handles: Vec<_> = ir
                .controllers
                .chunks(chunk)
                .map(|part| {
                    scope.spawn(move || part.iter().map(|c| analyse(ir, c)).collect::<Vec<_>>())
                })
                .collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
                .collect()
        })
    };
    per_controller.into_iter().unzip()
}
