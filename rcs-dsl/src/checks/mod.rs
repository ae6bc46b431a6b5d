//! Stage 3: checks over the IR. Each rule is its own `check_*` function that
//! reads the IR and pushes findings into one [`Sink`]; none changes the IR.
//! Hard errors go in as they are; lints pass through the lint levels in
//! force at their place (manifest, flags, then attributes).

mod graph;
mod handshake;
mod hang;
mod hierarchy;
mod index;
mod limits;
mod loops;
pub(crate) mod names;
mod plan;
mod report;
mod time;
mod typo;
mod usage;
mod value;

use crate::analysis::PlanAnalysis;
use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::ir::{Controller, CtrlId, Ir, Plan};
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

    /// A note under a lint's code inside `ctrl`: shown unless the lint is
    /// allowed there, and never more than a note (it states a fact).
    pub fn note(&mut self, ctrl: &Controller, lint: Lint, d: Diagnostic) {
        if self.levels.at(lint, &[&ctrl.lints]) != crate::lint::Level::Allow {
            self.diags.push(d);
        }
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
                Source::Attribute(format!("plan `{}`", c.plan_title(p)))
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
    // The analysis of every plan's conditions and its graph, and the
    // checks of each plan, controller by controller on worker threads.
    let plans: usize = ir.controllers.iter().map(|c| c.plans.len()).sum();
    let many = plans >= PARALLEL_PLANS;
    let ids: Vec<CtrlId> = (0..ir.controllers.len() as u32).map(CtrlId).collect();
    let analysed =
        crate::parallel::map_ordered(&ids, many, |ci| analyse_controller(ir, *ci, levels));
    let mut summaries = Vec::with_capacity(analysed.len());
    let mut uses = Vec::with_capacity(analysed.len());
    let mut kept = Vec::with_capacity(analysed.len());
    for a in analysed {
        sink.diags.extend(a.diags);
        summaries.push(a.summary);
        uses.push(a.uses);
        kept.push(std::sync::Mutex::new(a.kept));
    }
    usage::check_unused_declarations(ir, &uses, &mut sink);
    // Then, again on the worker threads, the handshake checks of each
    // controller, over its own analyses and its subordinates' summaries;
    // each controller's analyses are freed where they were last used.
    let found = crate::parallel::map_ordered(&ids, many, |ci| {
        let taken = kept[ci.index()]
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take();
        let mut diags = Diagnostics::new();
        let mut sink = Sink {
            levels,
            diags: &mut diags,
        };
        if let Some((conditions, graphs)) = taken {
            let sup = handshake::Supervisor {
                ir,
                id: *ci,
                conditions: &conditions,
                graphs: &graphs,
                summaries: &summaries,
            };
            handshake::check_unhandled_error(&sup, &mut sink);
            handshake::check_stale_subordinate_status(&sup, &mut sink);
            handshake::check_command_overwritten(&sup, &mut sink);
            handshake::check_always_rejected(&sup, &mut sink);
        }
        handshake::check_status_never_reported(ir, *ci, &summaries, &mut sink);
        diags
    });
    let handshake_start = sink.diags.len();
    for d in found {
        sink.diags.extend(d);
    }
    // The handshake findings' runs, again with the subordinates running
    // their own plans: whole-subtree system runs, replayed.
    let keep = handshake::add_system_runs(ir, sink.diags.since_mut(handshake_start));
    sink.diags.keep_from(handshake_start, &keep);
    hierarchy::check_span_of_control(ir, &mut sink);
    hierarchy::check_level_order(ir, &mut sink);
    diags.sort_from(start, sources);
}

/// Per plan of a controller: the analysis of its conditions and its graph.
type Kept<'ir> = (Vec<PlanAnalysis<'ir>>, Vec<graph::Analysis>);

/// Below a few dozen plans a thread costs more than it saves.
const PARALLEL_PLANS: usize = 64;

/// One controller's analyses and what its checks found.
struct Analysed<'ir> {
    /// Per plan: the analysis of its conditions and its graph, kept for
    /// the handshake checks of a supervisor only.
    kept: Option<Kept<'ir>>,
    /// What its supervisor's handshake checks need of its plans.
    summary: handshake::Summary,
    /// What its rows use of declarations outside it.
    uses: usage::Uses,
    diags: Diagnostics,
}

/// One controller's plans: analysed, then checked one by one; then the
/// checks of how the controller uses its own declarations, which need
/// nothing from other controllers.
fn analyse_controller<'ir>(ir: &'ir Ir, ci: CtrlId, levels: &LintLevels) -> Analysed<'ir> {
    let c = &ir.controllers[ci.index()];
    let conditions: Vec<PlanAnalysis> = c
        .plans
        .iter()
        .map(|p| PlanAnalysis::new(ir, c, p))
        .collect();
    let graphs: Vec<graph::Analysis> = c
        .plans
        .iter()
        .zip(&conditions)
        .map(|(p, a)| graph::analyse(p, a))
        .collect();
    let mut diags = Diagnostics::new();
    let mut sink = Sink {
        levels,
        diags: &mut diags,
    };
    // Where an index can fall outside its array: the `index_range` lint's
    // findings, and for a supervisor a way this controller can fail.
    let out_of_range: Vec<Vec<crate::analysis::index_range::OutOfRange>> =
        conditions.iter().map(|a| a.out_of_range()).collect();
    for (((p, conditions), analysis), out) in c
        .plans
        .iter()
        .zip(&conditions)
        .zip(&graphs)
        .zip(&out_of_range)
    {
        check_plan(ir, c, p, conditions, analysis, out, &mut sink);
    }
    value::check_values(ir, c, &conditions, &mut sink);
    usage::check_float_equality(c, &mut sink);
    time::check_timer_resolution(ir, ci, &mut sink);
    let uses = usage::check_unused_in_controller(ir, ci, &mut sink);
    let sites: Vec<Vec<crate::source::Span>> = out_of_range
        .iter()
        .zip(&conditions)
        .map(|(out, a)| out.iter().map(|o| a.index_sites()[o.site].span).collect())
        .collect();
    let summary = handshake::Summary::of(ir, c, &conditions, &graphs, &sites);
    // Only the handshake checks read the analyses again, and only those of
    // a controller with subordinates: the others' analyses (most
    // controllers of a hierarchy are leaves) are freed here, on the thread
    // that built them and while they are still in cache. On the
    // 1,000-controller benchmark set the handshake pass, which freed them
    // all, went from 35 to 12 ms, and this pass did not grow.
    let kept = (!c.subordinates.is_empty()).then_some((conditions, graphs));
    Analysed {
        kept,
        summary,
        uses,
        diags,
    }
}

/// The checks of one plan, over its analysis and graph.
fn check_plan(
    ir: &Ir,
    c: &Controller,
    p: &Plan,
    conditions: &PlanAnalysis,
    analysis: &graph::Analysis,
    out_of_range: &[crate::analysis::index_range::OutOfRange],
    sink: &mut Sink,
) {
    plan::check_row_numbers(c, p, sink);
    plan::check_otherwise(p, sink);
    plan::check_entry(p, sink);
    plan::check_double_commands(ir, p, sink);
    plan::check_rule_of_ten(ir, c, p, sink);
    plan::check_unreachable_rows(p, analysis, sink);
    let bound = hang::entry_bound_rows(p, analysis, conditions);
    hang::check_entry_bound_rows(p, &bound, conditions, sink);
    let bound: Vec<usize> = bound.iter().map(|b| b.row).collect();
    // Shadowing asks about every pair of rows in every state.
    if conditions.analysed() {
        plan::check_shadowed_rows(c, p, analysis, conditions, &bound, sink);
    }
    graph::check_unreachable_states(c, p, analysis, sink);
    graph::check_dead_ends(c, p, analysis, sink);
    graph::check_no_done(ir, c, p, analysis, sink);
    typo::check_state_typos(c, p, sink);
    hang::check_incomplete_states(c, p, conditions, analysis, sink);
    loops::check_livelocks(ir, c, p, conditions, sink);
    loops::check_command_storms(ir, c, p, conditions, sink);
    index::check_index_range(ir, c, p, conditions, out_of_range, sink);
}
