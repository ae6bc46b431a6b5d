//! Stage 1b, between parsing and lowering: LANGUAGE.md §8's "write each
//! thing once", turned into what every later stage already understands.
//!
//! ```text
//! ast::File ──jobs::inline──▶ ──rows::place──▶ ──types::instantiate──▶ ast::File
//! ```
//!
//! - job lists (`jobs NAME(p) { … }`) are written into each row, `pre` and
//!   `post` that calls them ([`jobs`]);
//! - shared rows (`rows NAME { … }`) are placed where plans `use` them
//!   ([`rows`]);
//! - each instance of a controller type becomes a plain controller
//!   ([`types`]).
//!
//! Lists and blocks are expanded inside a type's body before it is
//! instantiated, so a mistake in them is reported once. State sets
//! (`A | B`, `* except A`) need no expansion: a row keeps its set and
//! lowering resolves it.
//!
//! The output has no job list, rows block, `use`, type or instance left.
//! [`Origins`] remembers where expanded things came from, so that a finding
//! on a shared row or inside a type is shown once, at the text the user
//! wrote, naming every place it landed ([`attribute`]).

mod jobs;
mod rows;
mod types;

use crate::ast::{File, Item};
use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::source::Span;

/// Where expanded rows and controllers came from.
#[derive(Clone, Debug, Default)]
pub(crate) struct Origins {
    /// Every row placed by a `use`, in placement order.
    pub shared: Vec<Placement>,
    /// Every controller type and its instances.
    pub types: Vec<TypeOrigin>,
    /// Rows blocks no plan uses: (controller or type, block name).
    pub unused_blocks: Vec<(String, crate::ast::Name)>,
}

/// One row of a rows block placed in one plan.
#[derive(Clone, Debug)]
pub(crate) struct Placement {
    /// The row in the block.
    pub row: Span,
    pub block: String,
    /// The controller (or type) whose plan uses the block.
    pub controller: String,
    /// The plan's title (`START`, `GOTO | JOG`).
    pub plan: String,
    /// The row's position in the plan (`E{position}`).
    pub position: usize,
}

#[derive(Clone, Debug)]
pub(crate) struct TypeOrigin {
    pub name: String,
    /// The whole `controller type … { … }`.
    pub span: Span,
    pub instances: Vec<String>,
}

/// Expand every §8 construct of `files` (see the module docs).
pub(crate) fn expand(files: &mut [File], diags: &mut Diagnostics) -> Origins {
    let mut origins = Origins::default();
    for item in files.iter_mut().flat_map(|f| &mut f.items) {
        let def = match item {
            Item::Controller(c) => c,
            Item::ControllerType(t) => &mut t.def,
            _ => continue,
        };
        jobs::inline(def, diags);
        rows::place(def, diags, &mut origins);
    }
    types::instantiate(files, diags, &mut origins);
    origins
}

/// Drop a finding identical to one kept before it at the same place
/// (findings come sorted by place, so the twins are neighbours).
fn once_each(diags: Vec<Diagnostic>) -> Vec<Diagnostic> {
    let mut out: Vec<Diagnostic> = Vec::with_capacity(diags.len());
    for d in diags {
        let p = d.primary_span();
        let twin = out
            .iter()
            .rev()
            .take_while(|o| o.primary_span() == p)
            .any(|o| *o == d);
        if !twin {
            out.push(d);
        }
    }
    out
}

fn inside(inner: Span, outer: Span) -> bool {
    inner.file == outer.file && outer.start <= inner.start && inner.end <= outer.end
}

/// Show each finding on expanded text once, where it was written: a
/// finding in a job list is inlined with it at every call, identically,
/// and kept once; a finding inside a controller type is reported once for
/// all instances that have it (naming them), and a finding on a shared
/// row names every plan and position the row landed at.
pub(crate) fn attribute(diags: Vec<Diagnostic>, origins: &Origins) -> Vec<Diagnostic> {
    if origins.shared.is_empty() && origins.types.iter().all(|t| t.instances.is_empty()) {
        return once_each(diags);
    }
    let mut out: Vec<Diagnostic> = Vec::with_capacity(diags.len());
    // (index in `out`, how many were merged into it, the type) per kept finding in a type.
    let mut in_type: Vec<(usize, usize, usize)> = Vec::new();
    for d in diags {
        let p = d.primary_span();
        let ty = origins
            .types
            .iter()
            .position(|t| !t.instances.is_empty() && inside(p, t.span));
        if let Some(t) = ty {
            let same = in_type.iter_mut().find(|(k, _, tt)| {
                *tt == t
                    && out[*k].code == d.code
                    && out[*k].severity == d.severity
                    && out[*k].primary_span() == p
            });
            if let Some((_, n, _)) = same {
                *n += 1;
                continue;
            }
            in_type.push((out.len(), 1, t));
        }
        out.push(d);
    }
    for (k, n, t) in in_type {
        let t = &origins.types[t];
        let named: Vec<&String> = t
            .instances
            .iter()
            .filter(|i| mentions(&out[k], i))
            .collect();
        let note = if n >= t.instances.len() {
            format!(
                "in every instance of `{}` ({})",
                t.name,
                t.instances.join(", ")
            )
        } else if !named.is_empty() {
            format!(
                "in instance{} {} of `{}`",
                if named.len() == 1 { "" } else { "s" },
                named
                    .iter()
                    .map(|i| format!("`{i}`"))
                    .collect::<Vec<_>>()
                    .join(", "),
                t.name
            )
        } else {
            format!(
                "in {n} of the {} instances of `{}` ({})",
                t.instances.len(),
                t.name,
                t.instances.join(", ")
            )
        };
        out[k].notes.push(note);
    }
    // Shared rows: one finding per block row and code.
    let mut kept: Vec<Diagnostic> = Vec::with_capacity(out.len());
    for d in out {
        let p = d.primary_span();
        let landed: Vec<&Placement> = origins.shared.iter().filter(|s| inside(p, s.row)).collect();
        if landed.is_empty() {
            kept.push(d);
            continue;
        }
        if kept
            .iter()
            .any(|k| k.code == d.code && k.severity == d.severity && k.primary_span() == p)
        {
            continue;
        }
        let mut d = d;
        let places: Vec<String> = landed
            .iter()
            .map(|s| format!("{}.{} E{}", s.controller, s.plan, s.position))
            .collect();
        d.notes.push(format!(
            "this row of `rows {}` lands at {}",
            landed[0].block,
            places.join(", ")
        ));
        kept.push(d);
    }
    once_each(kept)
}

/// Whether a finding's text names `instance`.
fn mentions(d: &Diagnostic, instance: &str) -> bool {
    let quoted = format!("`{instance}`");
    let dotted = format!("`{instance}.");
    std::iter::once(&d.message)
        .chain(d.labels.iter().map(|l| &l.message))
        .chain(&d.notes)
        .any(|t| t.contains(&quoted) || t.contains(&dotted))
}
