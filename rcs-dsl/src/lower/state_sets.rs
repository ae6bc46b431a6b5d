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

#[cfg(test)]
mod tests {
    //! Rows placed by `use NAME` (marked here by hand, as `expand` marks
    //! them): their `from` names only the plan's own states.

    use crate::ast;
    use crate::diagnostic::Diagnostics;
    use crate::ir::{From, Ir, StateId};
    use crate::lint::LintLevels;
    use crate::PlanSet;

    const TEXT: &str = "buffer In { a: bool, b: bool }
controller C {
    reads i: In
    command GO
    error TIMEOUT
    plan GO {
        E0: *0 when new_command -> Running
        E1: Aborting when i.a -> Done
        E2: * except Aborting when i.b -> Error(TIMEOUT)
        E3: Running | Aborting when state_cycles > 9 -> Done
        E4: Running when i.a && !i.b -> Done
    }
}
";

    /// Lower and check `TEXT` with rows E1–E3 of plan GO marked as shared
    /// (or not): the IR and every diagnostic's code.
    fn lower(shared: bool) -> (Ir, Vec<String>) {
        let set = PlanSet::from_texts("t", [("t.rcs", TEXT)], None);
        let mut diags = Diagnostics::new();
        let mut parsed = crate::parse(&set, &mut diags).expect("parses");
        for item in &mut parsed.files[0].items {
            let ast::Item::Controller(c) = item else {
                continue;
            };
            for e in &mut c.entries {
                let ast::EntryKind::Plan(p) = &mut e.kind else {
                    continue;
                };
                for r in p.rows.iter_mut().skip(1).take(3).filter(|_| shared) {
                    r.shared = Some(Box::new(ast::SharedOrigin {
                        block: ast::Name {
                            text: "on_abort".into(),
                            span: r.span,
                        },
                        use_span: r.span,
                    }));
                }
            }
        }
        let ir = crate::lower_files(&set, parsed, &mut diags).expect("lowers");
        crate::checks::run(&ir, &LintLevels::default(), &set.sources, &mut diags);
        let codes = diags.iter().map(|d| d.code.name().to_string()).collect();
        (ir, codes)
    }

    #[test]
    fn a_state_named_only_in_shared_froms_is_not_a_state_of_the_plan() {
        let (ir, codes) = lower(true);
        let plan = &ir.controllers[0].plans[0];
        let names: Vec<&str> = plan.states.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["S0", "Running"]);
        let running = StateId(1);
        // Each pattern keeps only the plan's states; a row left with none
        // never applies.
        assert_eq!(plan.rows[1].from, From::States(vec![]));
        assert_eq!(plan.rows[2].from, From::Except(None, vec![]));
        assert_eq!(plan.rows[3].from, From::States(vec![running]));
        assert!(!plan.rows[1].applies_in(running) && !plan.rows[1].applies_in(StateId::S0));
        assert!(plan.rows[2].applies_in(running) && plan.rows[3].applies_in(running));
        assert!(codes.is_empty(), "no finding at all: {codes:?}");
    }

    #[test]
    fn the_same_rows_written_in_the_plan_make_the_state_its_own() {
        let (ir, codes) = lower(false);
        let plan = &ir.controllers[0].plans[0];
        let names: Vec<&str> = plan.states.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["S0", "Running", "Aborting"]);
        assert_eq!(
            plan.rows[3].from,
            From::States(vec![StateId(1), StateId(2)])
        );
        assert_eq!(codes, ["unreachable_state"]);
    }
}
