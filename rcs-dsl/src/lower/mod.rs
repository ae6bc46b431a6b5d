//! Stage 2: AST → IR. Resolves every name, checks every type, builds the
//! Global Memory buffer table, the hierarchy and the schedule. Reports
//! `duplicate_definition`, `unknown_*`, `type_mismatch`, `wrong_arguments`,
//! `assign_to_input`, `multiple_*`, `hierarchy_cycle`, `buffer_type_conflict`
//! and the manifest's name errors. Yields an IR only when it found no error.
//!
//! No cascades: a name that does not resolve is reported once, and the
//! expression it stood in gets an error type that fits everywhere.

pub(crate) mod consts;
mod declarations;
mod every_cycle;
mod expr;
mod headers;
mod index;
mod plans;
mod schedule;
mod state_sets;
mod time;
mod types;
mod verbs;
pub use expr::type_name;
use headers::{check_hierarchy_cycles, lower_controller_headers};
use schedule::lower_schedule;
use types::{check_buffer_recursion, lower_buffer_types, lower_enums};
pub(crate) use types::{primitive, resolve_type, resolve_type_in};

use crate::ast;
use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use crate::ir::*;
use crate::manifest::{Manifest, DEFAULT_PERIOD_NS};
use crate::source::{SourceMap, Span};
use petgraph::graph::{DiGraph, NodeIndex};
use std::collections::BTreeMap;
use std::sync::Mutex;

/// What a global name stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ItemRef {
    Enum(EnumId),
    BufferType(BufferTypeId),
    Controller(CtrlId),
}

/// The AST items in IR order, with the global namespace.
pub(crate) struct Globals<'a> {
    pub names: BTreeMap<&'a str, (ItemRef, Span)>,
    pub enums: Vec<&'a ast::EnumDef>,
    pub buffers: Vec<&'a ast::BufferDef>,
    pub controllers: Vec<&'a ast::ControllerDef>,
    /// File-level `const` definitions, first of each name.
    pub consts: Vec<&'a ast::ConstDef>,
    /// Every constant's value, once folded (right after the enums).
    pub consts_table: consts::ConstTable,
    /// Each controller's CPU period and whether the manifest gives it.
    pub periods: BTreeMap<String, (u64, bool)>,
    /// The controller whose declarations are being lowered, if any: the
    /// scope of constants in array lengths. Set only by the sequential
    /// passes; controller bodies, lowered in parallel, name their scope
    /// ([`resolve_type_in`]).
    pub scope: ScopeCell,
}

/// An `Option<usize>` that can be shared with the threads lowering
/// controller bodies (which only ever read other fields of [`Globals`]).
#[derive(Default)]
pub(crate) struct ScopeCell(std::sync::atomic::AtomicUsize);

impl ScopeCell {
    pub fn get(&self) -> Option<usize> {
        match self.0.load(std::sync::atomic::Ordering::Relaxed) {
            0 => None,
            n => Some(n - 1),
        }
    }

    pub fn set(&self, scope: Option<usize>) {
        let n = scope.map_or(0, |i| i + 1);
        self.0.store(n, std::sync::atomic::Ordering::Relaxed);
    }
}

pub(crate) const PRIMITIVES: [&str; 11] = [
    "bool", "i8", "i16", "i32", "i64", "u8", "u16", "u32", "u64", "f32", "f64",
];

/// One controller body to lower on a worker: the controller, its header,
/// and its plans' rows (taken by the worker that lowers them).
type BodyWork<'a> = (CtrlId, &'a ast::ControllerDef, Mutex<Vec<Vec<ast::Row>>>);

/// Takes every plan's rows out of the AST, per controller (by its span)
/// in the order of its plans. The rows are most of the AST; lowering a
/// controller's body consumes its rows, so they are freed, on the worker
/// that lowered them, as its IR is built rather than after the whole plan
/// set: the peak of memory — and the page faults of first touching it, a
/// sixth of `check`'s time on a large set — is the AST, not AST plus IR.
fn take_plan_rows(files: &mut [ast::File]) -> BTreeMap<Span, Vec<Vec<ast::Row>>> {
    let mut out = BTreeMap::new();
    for item in files.iter_mut().flat_map(|f| &mut f.items) {
        if let ast::Item::Controller(c) = item {
            let rows = c
                .entries
                .iter_mut()
                .filter_map(|e| match &mut e.kind {
                    ast::EntryKind::Plan(p) => Some(std::mem::take(&mut p.rows)),
                    _ => None,
                })
                .collect();
            out.insert(c.span, rows);
        }
    }
    out
}

/// Lower parsed files (already in path order) to the IR.
pub fn lower(
    mut files: Vec<ast::File>,
    parsed_on: &BTreeMap<crate::source::FileId, crate::parallel::Worker>,
    file_names: Vec<String>,
    manifest: &Manifest,
    system: &str,
    sources: &SourceMap,
    diags: &mut Diagnostics,
) -> Option<Ir> {
    let start = diags.len();
    let mut plan_rows = take_plan_rows(&mut files);
    let mut globals = collect_items(&files, diags);
    let mut ir = Ir {
        system: system.to_string(),
        files: file_names,
        limits: manifest.limits,
        enums: Vec::new(),
        buffer_types: Vec::new(),
        buffers: Vec::new(),
        controllers: Vec::new(),
        schedule: Vec::new(),
    };
    lower_enums(&globals, &mut ir, diags);
    globals.consts_table = consts::fold_all(&globals, diags);
    globals.periods = schedule::periods(manifest);
    lower_buffer_types(&globals, &mut ir, diags);
    check_buffer_recursion(&ir, diags);
    let ctrl_asts = lower_controller_headers(&globals, &mut ir, sources, diags);
    check_hierarchy_cycles(&ir, diags);
    let names = index::Index::new(&ir);
    // Controller bodies only read the declarations lowered so far, so they
    // are lowered in parallel; their plans and diagnostics are put back in
    // controller order.
    let ids: Vec<BodyWork> = ctrl_asts
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let rows = plan_rows.remove(&c.span).unwrap_or_default();
            (CtrlId(i as u32), *c, Mutex::new(rows))
        })
        .collect();
    let rows: usize = ids.iter().map(|(_, c, _)| c.entries.len()).sum();
    // Each body on the worker that parsed its file: lowering frees the
    // rows as it goes (see `take_plan_rows`), and freeing them on the
    // thread that allocated them is what the allocator does best (see
    // `parallel::map_pinned`).
    let workers: Vec<crate::parallel::Worker> = ids
        .iter()
        .map(|(_, c, _)| parsed_on.get(&c.span.file).copied().unwrap_or(0))
        .collect();
    let bodies = crate::parallel::map_pinned(&ids, &workers, rows >= 2048, |(id, c, rows)| {
        let rows = std::mem::take(&mut *rows.lock().unwrap_or_else(|e| e.into_inner()));
        let mut body = declarations::lower_controller_body(&globals, &names, &ir, *id, c, rows);
        time::fill_texts(&mut body.written_times, sources);
        // Each row's line, for generated comments: looked up here, on the
        // worker, rather than for the whole set on one thread afterwards.
        for row in body.plans.iter_mut().flat_map(|p| &mut p.rows) {
            row.line = sources
                .get(row.span.file)
                .line_col(row.span.start as usize)
                .0 as u32;
        }
        body
    });
    for ((id, _, _), mut body) in ids.iter().zip(bodies) {
        diags.extend(std::mem::take(&mut body.diags));
        body.apply(&mut ir.controllers[id.index()]);
    }
    ir.schedule = lower_schedule(&ir, manifest, diags);
    diags.sort_from(start, sources);
    if diags.has_errors() {
        None
    } else {
        Some(ir)
    }
}

/// Where each name of one scope was first declared, so that finding a name
/// stays O(log n) however many a file declares (a hostile one may declare
/// a million: a linear search per declaration would take hours). Names
/// up to 24 bytes are kept inline, without an allocation each: a plan set
/// makes one of these per plan (its states) and per command (its
/// parameters).
#[derive(Default)]
pub(super) struct ByName(BTreeMap<compact_str::CompactString, usize>);

impl ByName {
    /// The names of a finished scope, in declaration order (the first of
    /// two equal names wins).
    pub(super) fn of<'a>(names: impl Iterator<Item = &'a str>) -> ByName {
        let mut out = ByName::default();
        for (i, n) in names.enumerate() {
            out.first_or_insert(n, i);
        }
        out
    }

    /// The index `name` was first declared at.
    pub(super) fn get(&self, name: &str) -> Option<usize> {
        self.0.get(name).copied()
    }

    /// The index `name` was first declared at; else remember `index` for it.
    pub(super) fn first_or_insert(&mut self, name: &str, index: usize) -> Option<usize> {
        if let Some(&i) = self.0.get(name) {
            return Some(i);
        }
        self.0.insert(name.into(), index);
        None
    }

    /// Declare `name` as the `index`-th `what` of this scope: `false`, with
    /// a `duplicate_definition` against the first declaration's span, when
    /// the scope has it already.
    pub(super) fn claim(
        &mut self,
        what: &str,
        name: &ast::Name,
        index: usize,
        first_span: impl FnOnce(usize) -> Span,
        diags: &mut Diagnostics,
    ) -> bool {
        match self.first_or_insert(&name.text, index) {
            Some(first) => {
                diags.push(duplicate(what, &name.text, name.span, first_span(first)));
                false
            }
            None => true,
        }
    }
}

fn duplicate(what: &str, name: &str, span: Span, first: Span) -> Diagnostic {
    Diagnostic::error(
        Code::DuplicateDefinition,
        format!("{what} `{name}` is defined more than once"),
        span,
        format!("`{name}` redefined here"),
    )
    .with_secondary(first, format!("first definition of `{name}`"))
    .with_help("rename or remove one of them")
}

fn collect_items<'a>(files: &'a [ast::File], diags: &mut Diagnostics) -> Globals<'a> {
    let mut g = Globals {
        names: BTreeMap::new(),
        enums: Vec::new(),
        buffers: Vec::new(),
        controllers: Vec::new(),
        consts: Vec::new(),
        consts_table: consts::ConstTable::default(),
        periods: BTreeMap::new(),
        scope: ScopeCell::default(),
    };
    let mut const_names = ByName::default();
    for item in files.iter().flat_map(|f| &f.items) {
        if let Some(d) = item_name(item).and_then(consts::reserved) {
            diags.push(d);
        }
        let (name, r) = match item {
            ast::Item::Const(c) => {
                let n = g.consts.len();
                let consts = &g.consts;
                if const_names.claim("constant", &c.name, n, |k| consts[k].name.span, diags) {
                    g.consts.push(c);
                }
                continue;
            }
            ast::Item::Enum(e) => (&e.name, ItemRef::Enum(EnumId(g.enums.len() as u32))),
            ast::Item::Buffer(b) => (
                &b.name,
                ItemRef::BufferType(BufferTypeId(g.buffers.len() as u32)),
            ),
            ast::Item::Controller(c) => (
                &c.name,
                ItemRef::Controller(CtrlId(g.controllers.len() as u32)),
            ),
            // `expand` replaced types and instances with controllers.
            ast::Item::ControllerType(_) | ast::Item::Instance(_) => continue,
        };
        if PRIMITIVES.contains(&name.text.as_str()) && !matches!(r, ItemRef::Controller(_)) {
            diags.push(
                Diagnostic::error(
                    Code::DuplicateDefinition,
                    format!("`{}` is a built-in type", name.text),
                    name.span,
                    "cannot be redefined",
                )
                .with_help("choose another name"),
            );
            continue;
        }
        if let Some((_, first)) = g.names.get(name.text.as_str()) {
            diags.push(duplicate("item", &name.text, name.span, *first));
            continue;
        }
        g.names.insert(&name.text, (r, name.span));
        match item {
            ast::Item::Enum(e) => g.enums.push(e),
            ast::Item::Buffer(b) => g.buffers.push(b),
            ast::Item::Controller(c) => g.controllers.push(c),
            ast::Item::Const(_) | ast::Item::ControllerType(_) | ast::Item::Instance(_) => {}
        }
    }
    // Constants and items share no names (a controller's name is a value
    // in `X.status`, and one name for two things only confuses readers).
    for c in &g.consts {
        if let Some((_, first)) = g.names.get(c.name.text.as_str()) {
            diags.push(duplicate("name", &c.name.text, c.name.span, *first));
        }
    }
    g
}

/// The name an item declares, for the reserved-name check.
fn item_name(item: &ast::Item) -> Option<&ast::Name> {
    Some(match item {
        ast::Item::Enum(e) => &e.name,
        ast::Item::Buffer(b) => &b.name,
        ast::Item::Controller(c) => &c.name,
        ast::Item::Const(c) => &c.name,
        ast::Item::ControllerType(t) => &t.def.name,
        ast::Item::Instance(i) => &i.name,
    })
}
