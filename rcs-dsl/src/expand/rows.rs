//! Stage 1b, expansion: shared rows (`rows NAME { … }` and `use NAME`,
//! LANGUAGE.md §8).
//!
//! `use NAME` in a plan is replaced by the block's rows, in their order; they
//! take the plan's next positions like rows written there, so every later
//! stage numbers, checks and draws them as the plan's own. Each placed row
//! remembers its block ([`SharedOrigin`]), and [`super::Origins`] records
//! where each block row landed, so that a finding on it can name them all.

use super::{Origins, Placement};
use crate::ast::{ControllerDef, EntryKind, Row, RowsDef, SharedOrigin};
use crate::diagnostic::{Code, Diagnostic, Diagnostics};

/// Place the rows of every `use` of `def` and remove the blocks.
pub(super) fn place(def: &mut ControllerDef, diags: &mut Diagnostics, origins: &mut Origins) {
    let mut blocks: Vec<RowsDef> = Vec::new();
    def.entries.retain_mut(|e| {
        let EntryKind::Rows(block) = &mut e.kind else {
            return true;
        };
        let block = std::mem::replace(
            block,
            RowsDef {
                name: block.name.clone(),
                rows: Vec::new(),
                uses: Vec::new(),
            },
        );
        if let Some(first) = blocks.iter().find(|b| b.name.text == block.name.text) {
            diags.push(
                Diagnostic::error(
                    Code::DuplicateDefinition,
                    format!("rows block `{}` is defined more than once", block.name.text),
                    block.name.span,
                    "a second block of this name",
                )
                .with_secondary(first.name.span, "first definition")
                .with_help("rename or remove one of them"),
            );
            return false;
        }
        check_block(&block, diags);
        blocks.push(block);
        false
    });
    let mut used = vec![false; blocks.len()];
    for entry in &mut def.entries {
        let EntryKind::Plan(plan) = &mut entry.kind else {
            continue;
        };
        if plan.uses.is_empty() {
            continue;
        }
        let title = std::iter::once(&plan.verb)
            .chain(&plan.more_verbs)
            .map(|v| v.text.as_str())
            .collect::<Vec<_>>()
            .join(" | ");
        let written = std::mem::take(&mut plan.rows);
        let uses = std::mem::take(&mut plan.uses);
        let mut rows = Vec::with_capacity(written.len() + uses.len() * 2);
        let mut next = uses.iter().peekable();
        let mut place_uses = |rows: &mut Vec<Row>, upto: usize| {
            while let Some(u) = next.next_if(|u| u.at <= upto) {
                let Some(b) = blocks.iter().position(|b| b.name.text == u.name.text) else {
                    diags.push(unknown_block(u, &blocks));
                    continue;
                };
                used[b] = true;
                for row in &blocks[b].rows {
                    origins.shared.push(Placement {
                        row: row.span,
                        block: blocks[b].name.text.to_string(),
                        controller: def.name.text.to_string(),
                        plan: title.clone(),
                        position: rows.len(),
                    });
                    let mut row = row.clone();
                    row.label = None;
                    row.shared = Some(Box::new(SharedOrigin {
                        block: blocks[b].name.clone(),
                        use_span: u.span,
                    }));
                    rows.push(row);
                }
            }
        };
        for (i, row) in written.into_iter().enumerate() {
            place_uses(&mut rows, i);
            rows.push(row);
        }
        place_uses(&mut rows, usize::MAX);
        plan.rows = rows;
    }
    for (block, used) in blocks.iter().zip(used) {
        if !used {
            origins
                .unused_blocks
                .push((def.name.text.to_string(), block.name.clone()));
        }
    }
}

fn unknown_block(u: &crate::ast::Use, blocks: &[RowsDef]) -> Diagnostic {
    let d = Diagnostic::error(
        Code::SharedRows,
        format!("no rows block named `{}`", u.name.text),
        u.name.span,
        "not a rows block of this controller",
    );
    match blocks {
        [] => d.with_help(format!(
            "declare the rows at controller level: `rows {} {{ … }}`",
            u.name.text
        )),
        _ => d.with_help(format!(
            "the blocks here are {}",
            blocks
                .iter()
                .map(|b| format!("`{}`", b.name.text))
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

/// A block holds unlabelled rows and no `use`.
fn check_block(block: &RowsDef, diags: &mut Diagnostics) {
    for row in &block.rows {
        if let Some((_, span)) = row.label {
            diags.push(
                Diagnostic::error(
                    Code::SharedRows,
                    format!("a row of rows block `{}` has a label", block.name.text),
                    span,
                    "label in a shared block",
                )
                .with_help("a shared row takes its number from where it is used (`E1` in one plan, `E4` in another): remove the label"),
            );
        }
    }
    for row in &block.rows {
        let numbered = match &row.from {
            crate::ast::From::DontCare(Some(n), span) => Some((*n, *span)),
            crate::ast::From::Except(Some(n), _, span) => Some((*n, *span)),
            _ => None,
        };
        if let Some((n, span)) = numbered {
            diags.push(
                Diagnostic::error(
                    Code::SharedRows,
                    format!(
                        "a row of rows block `{}` is numbered `*{n}`",
                        block.name.text
                    ),
                    span,
                    "numbered don't-care in a shared block",
                )
                .with_help("a shared row takes its number from where it is used: write `*`"),
            );
        }
    }
    for u in &block.uses {
        diags.push(
            Diagnostic::error(
                Code::SharedRows,
                format!("rows block `{}` uses another block", block.name.text),
                u.span,
                "`use` inside a block",
            )
            .with_help(format!(
                "blocks do not nest: write `use {}` in the plans, beside `use {}`",
                u.name.text, block.name.text
            )),
        );
    }
}
