//! A rule plan of the IR: its states and its rows in precedence order, each
//! row's `from` pattern, condition and target, with what is asked of them
//! (which states a row applies in, its name). What a row does is in
//! `job`.

use super::{visit_job_exprs, CommandId, ErrorId, Expr, Job, StateId, VarId};
use crate::lint::LintOverride;
use crate::source::Span;
use serde::Serialize;

/// One rule plan: the state table of one command verb.
#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    pub verb: CommandId,
    pub docs: Vec<String>,
    /// States in order of first mention; `states[0]` is `S0`.
    pub states: Vec<State>,
    /// Rows in precedence order; `rows[i].position == i`.
    pub rows: Vec<Row>,
    pub lints: Vec<LintOverride>,
    /// `plan VERB`.
    pub header: Span,
    pub span: Span,
    /// Every verb of the plan in header order (`plan A | B`); `verbs[0] ==
    /// verb`. The verbs share their parameters (names, types, order), so
    /// `CmdParam(verb, p)` reads parameter `p` of whichever verb is running.
    /// Left out of `rcsc ir` for a plan of one verb (it is `[verb]`).
    #[serde(skip_serializing_if = "one_verb")]
    pub verbs: Vec<CommandId>,
}

fn one_verb(verbs: &[CommandId]) -> bool {
    verbs.len() == 1
}

impl Plan {
    /// The `otherwise` row, if the plan has one (the last row once checked).
    pub fn otherwise(&self) -> Option<&Row> {
        self.rows.iter().find(|r| r.is_otherwise())
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct State {
    pub name: String,
    /// First mention; `None` for an `S0` that is never written.
    pub span: Option<Span>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// 0-based precedence position.
    pub position: u32,
    /// `EN` as written.
    pub label: Option<u32>,
    pub docs: Vec<String>,
    pub from: From,
    /// `Condition::Otherwise` fires only when no other row matched.
    pub cond: Condition,
    /// The row tests `new_command` as a top-level conjunct: an entry row.
    pub is_entry: bool,
    pub to: Target,
    pub jobs: Vec<Job>,
    /// 1-based line of the row in its file, for generated comments.
    pub line: u32,
    pub span: Span,
    pub from_span: Span,
    pub cond_span: Span,
    pub to_span: Span,
    pub label_span: Option<Span>,
    /// The `rows` block this row was placed from by `use` (LANGUAGE.md
    /// §8); its spans are the block's row.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shared: Option<SharedRow>,
}

/// Where a row placed by `use NAME` came from.
#[derive(Clone, Debug, Serialize)]
pub struct SharedRow {
    /// The block's name.
    pub block: String,
    /// The `use NAME` line in this plan.
    pub use_span: Span,
}

impl Row {
    pub fn is_otherwise(&self) -> bool {
        matches!(self.cond, Condition::Otherwise)
    }

    /// Written with `*` (`*N`, or `*N except A | B`): the row has its own
    /// dashed `*N` node in graphs, answers to `*N` in scenarios, and is
    /// tried in every state's arm of the generated code. An `except` row
    /// is one, but it does not apply in the states it leaves out: ask
    /// [`Row::applies_in`] whether a row applies in a state.
    pub fn is_dont_care(&self) -> bool {
        matches!(self.from, From::DontCare(_) | From::Except(..))
    }

    /// Whether the row's `from` covers `state` (its condition aside).
    pub fn applies_in(&self, state: StateId) -> bool {
        self.from.applies_in(state)
    }

    /// The states of `plan` the row's `from` covers (see
    /// [`From::states_covered`]).
    pub fn states_covered<'p>(&'p self, plan: &Plan) -> impl Iterator<Item = StateId> + 'p {
        self.from.states_covered(plan.states.len())
    }

    /// The row's name everywhere — tables, graphs, diagnostics, coverage,
    /// scenarios: `E` and its position, whether or not it is labelled.
    pub fn display_name(&self) -> String {
        format!("E{}", self.position)
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum From {
    /// `*` / `*N` (with N as written, if any), or an `otherwise` without `*`.
    DontCare(Option<u32>),
    State(StateId),
    /// `A | B | C` (LANGUAGE.md §8): the row applies in each, in the order
    /// written. Empty for a shared row none of whose states belongs to the
    /// plan: it never applies.
    States(Vec<StateId>),
    /// `*N except A | B`: every state but those (N as written, if any).
    Except(Option<u32>, Vec<StateId>),
}

impl From {
    /// Whether the pattern covers `state`.
    pub fn applies_in(&self, state: StateId) -> bool {
        match self {
            From::DontCare(_) => true,
            From::State(s) => *s == state,
            From::States(set) => set.contains(&state),
            From::Except(_, out) => !out.contains(&state),
        }
    }

    /// The states, of a plan with `states` states, the pattern covers: a
    /// state or a set's in the order written (without walking the plan's
    /// other states), `*` and `except` in state order.
    pub fn states_covered(&self, states: usize) -> impl Iterator<Item = StateId> + '_ {
        let (listed, all_but): (&[StateId], Option<&[StateId]>) = match self {
            From::State(s) => (std::slice::from_ref(s), None),
            From::States(set) => (set, None),
            From::DontCare(_) => (&[], Some(&[])),
            From::Except(_, out) => (&[], Some(out)),
        };
        let rest = all_but.into_iter().flat_map(move |out| {
            (0..states as u32)
                .map(StateId)
                .filter(move |s| !out.contains(s))
        });
        listed.iter().copied().chain(rest)
    }

    /// Whether the pattern names `state` itself (`S1`, or `S1` in a set):
    /// the rows a state's own list shows; a `*` row names none.
    pub fn names(&self, state: StateId) -> bool {
        match self {
            From::State(s) => *s == state,
            From::States(set) => set.contains(&state),
            From::DontCare(_) | From::Except(..) => false,
        }
    }

    /// The state a row is judged in when one state must stand for all it
    /// covers: `S0` if covered (a new command may arrive only there, so
    /// it assumes least), else the first covered, else `None`.
    pub fn representative(&self, states: usize) -> Option<StateId> {
        if self.applies_in(StateId::S0) {
            return Some(StateId::S0);
        }
        self.states_covered(states).next()
    }
}

#[derive(Clone, Debug, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Condition {
    When(Expr),
    Otherwise,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    State(StateId),
    Same,
    Done,
    Error(Option<ErrorId>),
    /// `-> Error(v)`: the code held by var (or status field) `v`, of type
    /// `error`.
    ErrorOf(VarId),
}

impl Row {
    /// Every expression of the row: its condition, then its jobs' in order.
    pub fn visit_exprs<'a>(&'a self, f: &mut dyn FnMut(&'a Expr)) {
        if let Condition::When(c) = &self.cond {
            c.visit(f);
        }
        visit_job_exprs(&self.jobs, f);
    }
}
