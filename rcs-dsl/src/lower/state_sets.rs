//! Stage 2, the states of a row's `from` (LANGUAGE.md §8): one state, a
//! set `A | B | C`, or the states an `except` leaves out. Lowering a plan
//! (`lower::plans`) interns its states here, and resolves the `from` of a
//! row placed by `use NAME` against the plan's own states: a state that the
//! plan names only in shared rows' `from`s is not one of its states.

use super::expr::Cx;
use super::ByName;
use crate::ast;
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::{State, StateId};
use crate::source::Span;

/// The state `n` names in a plan, made one if it is not yet (its first
/// mention gives its span).
pub(super) fn intern(states: &mut Vec<State>, names: &mut ByName, n: &ast::Name) -> StateId {
    match names.first_or_insert(&n.text, states.len()) {
        Some(i) => {
            if states[i].span.is_none() {
                states[i].span = Some(n.span);
            }
            StateId(i as u32)
        }
        None => {
            states.push(State {
                name: n.text.to_string(),
                span: Some(n.span),
            });
            StateId(states.len() as u32 - 1)
        }
    }
}

/// The state names a `from` writes: one, a set's, or an `except` list's.
pub(super) fn from_names(from: &ast::From) -> &[ast::Name] {
    match from {
        ast::From::State(n) => std::slice::from_ref(n),
        ast::From::States(list, _) | ast::From::Except(_, list, _) => list,
        ast::From::DontCare(..) | ast::From::Implicit => &[],
    }
}

/// `Done` and `Error` end a plan: no row runs in them.
pub(super) fn is_terminal(n: &ast::Name) -> bool {
    n.text == "Done" || n.text == "Error"
}

/// A row number as written (`E7`, `*7`), saturated to the IR's width.
pub(super) fn row_number(n: u64) -> u32 {
    n.min(u32::MAX as u64) as u32
}

impl Cx<'_, '_> {
    /// `unreachable_row` for a row written to start in `Done` or `Error`.
    pub(super) fn terminal_from(&mut self, n: &ast::Name) {
        self.diags.push(
            Diagnostic::error(
                Code::UnreachableRow,
                format!("a row cannot start in `{}`", n.text),
                n.span,
                "terminal state",
            )
            .with_help(format!(
                "after `{}` the plan runs no rows until a new command arrives",
                n.text
            )),
        );
    }

    /// The states of a set or an `except` list, each once, in the order
    /// written. A name given twice is `duplicate_definition`, `Done` or
    /// `Error` in the list `unreachable_row`. In a row placed by `use`, a
    /// name that is not a state of the plan is left out (the row does not
    /// apply there); in the plan's own rows every name is one (the plan's
    /// states were interned from them first).
    pub(super) fn state_set(
        &mut self,
        list: &[ast::Name],
        r: &ast::Row,
        (states, names): (&mut Vec<State>, &mut ByName),
    ) -> Vec<StateId> {
        let except = matches!(r.from, ast::From::Except(..));
        let mut out = Vec::with_capacity(list.len());
        for (i, n) in list.iter().enumerate() {
            if let Some(first) = list[..i].iter().find(|m| m.text == n.text) {
                self.diags.push(
                    Diagnostic::error(
                        Code::DuplicateDefinition,
                        format!("state `{}` is named twice in one `from`", n.text),
                        n.span,
                        "named again",
                    )
                    .with_secondary(first.span, "first named here")
                    .with_help(format!("name `{}` once", n.text)),
                );
                continue;
            }
            if is_terminal(n) {
                if except {
                    self.terminal_except(n);
                } else {
                    self.terminal_from(n);
                }
                continue;
            }
            let id = if r.shared.is_some() {
                match names.get(&n.text) {
                    Some(i) => StateId(i as u32),
                    None => continue,
                }
            } else {
                intern(states, names, n)
            };
            out.push(id);
        }
        out
    }

    /// `unreachable_row` for `except Done` / `except Error`: no row runs
    /// there anyway, so the name leaves out nothing (and most likely the
    /// writer meant something else).
    fn terminal_except(&mut self, n: &ast::Name) {
        self.diags.push(
            Diagnostic::error(
                Code::UnreachableRow,
                format!("`except {}` leaves out a state no row runs in", n.text),
                n.span,
                "terminal state",
            )
            .with_help(format!(
                "remove `{}`: after it the plan runs no rows until a new command arrives",
                n.text
            )),
        );
    }

    /// `unreachable_row` for an `except` that leaves out all `count` states
    /// of the plan: the row applies nowhere.
    pub(super) fn except_everything(&mut self, list: &[ast::Name], span: Span, count: usize) {
        let what = match count {
            1 => "the plan's only state".to_string(),
            n => format!("all {n} states of the plan"),
        };
        self.diags.push(
            Diagnostic::error(
                Code::UnreachableRow,
                format!("this `except` leaves out {what}: the row applies in none"),
                span,
                "no state left",
            )
            .with_note(format!(
                "left out: {}",
                list.iter()
                    .map(|n| n.text.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
            .with_help("name the states the row applies in instead: `A | B`"),
        );
    }
}
