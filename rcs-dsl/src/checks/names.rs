//! Stage 3 check of the names that become output file names
//! (`case_collision`). `rcsc build` writes `tables/<CTRL>.md` and
//! `graphs/<CTRL>/` per controller and `graphs/<CTRL>/<VERB>.dot` per verb
//! with a plan; on a case-insensitive file system (macOS and Windows by
//! default) `PR` and `Pr`, or `GO` and `Go` of one controller, are one
//! file. Only those names are checked: the generated Rust names need no
//! check, since the code generator makes every scope's names distinct
//! (`pr`, `pr_2`). Plan sets sharing an output folder (`<system>/`) are
//! checked when they are loaded ([`crate::load::load_paths`]).

use super::Sink;
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::Ir;
use std::collections::BTreeMap;

/// A name and what goes with it (where it is declared, whose it is).
type Named<'a, T> = (&'a str, T);

/// Each name equal up to case to an earlier one but not equal to it,
/// paired with the earlier one (pure).
pub(crate) fn case_pairs<'a, T: Copy>(
    names: impl IntoIterator<Item = Named<'a, T>>,
) -> Vec<(Named<'a, T>, Named<'a, T>)> {
    let mut first: BTreeMap<String, Named<'a, T>> = BTreeMap::new();
    let mut out = Vec::new();
    for (name, with) in names {
        match first.get(&name.to_lowercase()) {
            Some(&(earlier, earlier_with)) if earlier != name => {
                out.push(((earlier, earlier_with), (name, with)));
            }
            Some(_) => {}
            None => {
                first.insert(name.to_lowercase(), (name, with));
            }
        }
    }
    out
}

const NOTE: &str = "case-insensitive file systems (macOS and Windows by default) see one file";

pub(crate) fn check_case_collisions(ir: &Ir, sink: &mut Sink) {
    let controllers = ir
        .controllers
        .iter()
        .map(|c| (c.name.as_str(), c.name_span));
    for ((a, a_span), (b, b_span)) in case_pairs(controllers) {
        sink.error(
            Diagnostic::error(
                Code::CaseCollision,
                format!("controllers `{a}` and `{b}` differ only in case"),
                b_span,
                format!("`{a}` but for case"),
            )
            .with_secondary(a_span, format!("`{a}` declared here"))
            .with_note(format!(
                "`rcsc build` writes `tables/{a}.md` and `tables/{b}.md`, `graphs/{a}/` and \
                 `graphs/{b}/`: {NOTE}"
            ))
            .with_help("rename one of the controllers"),
        );
    }
    for c in &ir.controllers {
        let verbs = c
            .commands
            .iter()
            .enumerate()
            // A plan's graph is filed under its first verb (`plan A | B`).
            .filter(|(i, cmd)| {
                cmd.plan
                    .is_some_and(|p| c.plans[p.index()].verb.index() == *i)
            })
            .map(|(_, cmd)| (cmd.name.as_str(), cmd.span));
        for ((a, a_span), (b, b_span)) in case_pairs(verbs) {
            let ctrl = &c.name;
            sink.error(
                Diagnostic::error(
                    Code::CaseCollision,
                    format!("verbs `{a}` and `{b}` of `{ctrl}` differ only in case"),
                    b_span,
                    format!("`{a}` but for case"),
                )
                .with_secondary(a_span, format!("`{a}` declared here"))
                .with_note(format!(
                    "`rcsc build` writes their state graphs to `graphs/{ctrl}/{a}.dot` and \
                     `graphs/{ctrl}/{b}.dot`: {NOTE}"
                ))
                .with_help("rename one of the verbs"),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_names_equal_up_to_case_but_not_equal_pair() {
        let got = case_pairs([("PR", 0), ("TB", 1), ("Pr", 2), ("PR", 3), ("pr", 4)]);
        assert_eq!(got, [(("PR", 0), ("Pr", 2)), (("PR", 0), ("pr", 4))]);
    }
}
