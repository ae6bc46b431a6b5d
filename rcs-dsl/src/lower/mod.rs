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
mod index;
mod plans;
mod verbs;
pub use expr::type_name;

use crate::ast;
use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use crate::ir::*;
use crate::manifest::{Manifest, DEFAULT_PERIOD_NS};
use crate::source::{SourceMap, Span};
use petgraph::graph::{DiGraph, NodeIndex};
use std::collections::BTreeMap;

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

/// Lower parsed files (already in path order) to the IR.
pub fn lower(
    files: &[ast::File],
    file_names: Vec<String>,
    manifest: &Manifest,
    system: &str,
    sources: &SourceMap,
    diags: &mut Diagnostics,
) -> Option<Ir> {
    let start = diags.len();
    let mut globals = collect_items(files, diags);
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
    lower_buffer_types(&globals, &mut ir, diags);
    check_buffer_recursion(&ir, diags);
    let ctrl_asts = lower_controller_headers(&globals, &mut ir, sources, diags);
    check_hierarchy_cycles(&ir, diags);
    let names = index::Index::new(&ir);
    // Controller bodies only read the declarations lowered so far, so they
    // are lowered in parallel; their plans and diagnostics are put back in
    // controller order.
    let ids: Vec<(CtrlId, &ast::ControllerDef)> = ctrl_asts
        .iter()
        .enumerate()
        .map(|(i, c)| (CtrlId(i as u32), *c))
        .collect();
    let rows: usize = ids.iter().map(|(_, c)| c.entries.len()).sum();
    let bodies = crate::parallel::map_ordered(&ids, rows >= 2048, |&(id, c)| {
        declarations::lower_controller_body(&globals, &names, &ir, id, c)
    });
    for ((id, _), mut body) in ids.iter().zip(bodies) {
        diags.extend(std::mem::take(&mut body.diags));
        body.apply(&mut ir.controllers[id.index()]);
    }
    ir.schedule = lower_schedule(&ir, manifest, diags);
    for c in &mut ir.controllers {
        for row in c.plans.iter_mut().flat_map(|p| &mut p.rows) {
            row.line = sources
                .get(row.span.file)
                .line_col(row.span.start as usize)
                .0 as u32;
        }
    }
    diags.sort_from(start, sources);
    if diags.has_errors() {
        None
    } else {
        Some(ir)
    }
}

/// Where each name of one scope was first declared, so that finding a name
/// stays O(log n) however many a file declares (a hostile one may declare
/// a million: a linear search per declaration would take hours).
#[derive(Default)]
pub(super) struct ByName(BTreeMap<String, usize>);

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
        self.0.insert(name.to_string(), index);
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
            ast::Item::Const(_) => {}
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
    })
}

fn lower_enums(g: &Globals, ir: &mut Ir, diags: &mut Diagnostics) {
    for e in &g.enums {
        let mut variants: Vec<Variant> = Vec::new();
        let mut names = ByName::default();
        for (docs, v) in &e.variants {
            if let Some(d) = consts::reserved(v) {
                diags.push(d);
            }
            if !names.claim("variant", v, variants.len(), |k| variants[k].span, diags) {
                continue;
            }
            variants.push(Variant {
                name: v.text.to_string(),
                docs: docs.clone(),
                span: v.span,
            });
        }
        if variants.is_empty() {
            diags.push(
                Diagnostic::error(
                    Code::Syntax,
                    format!("enum `{}` has no variants", e.name.text),
                    e.name.span,
                    "empty enum",
                )
                .with_help("an enum needs at least one variant; the first is its zero value"),
            );
        }
        ir.enums.push(EnumDef {
            name: e.name.text.to_string(),
            docs: e.outer.docs.clone(),
            variants,
            span: e.span,
            name_span: e.name.span,
        });
    }
}

/// Resolve a written type. `None` after reporting `unknown_name`.
pub(crate) fn resolve_type(
    g: &Globals,
    t: &ast::TypeExpr,
    diags: &mut Diagnostics,
) -> Option<Type> {
    resolve_type_in(g, g.scope.get(), t, diags)
}

/// [`resolve_type`] with array lengths folded in the constants of
/// controller `scope` (or the file's, for `None`).
pub(crate) fn resolve_type_in(
    g: &Globals,
    scope: Option<usize>,
    t: &ast::TypeExpr,
    diags: &mut Diagnostics,
) -> Option<Type> {
    match t {
        ast::TypeExpr::Array {
            elem,
            len,
            span,
            len_expr,
        } => {
            let elem = resolve_type_in(g, scope, elem, diags)?;
            if let Some(e) = len_expr {
                let n = consts::array_len(g, scope, e, diags)?;
                return Some(Type::Array(Box::new(elem), n as u32));
            }
            if *len == 0 || *len > 65_536 {
                diags.push(
                    Diagnostic::error(
                        Code::TypeMismatch,
                        format!("array length {len} is out of range"),
                        *span,
                        "length must be 1 to 65536",
                    )
                    .with_help("Global Memory buffers are fixed-size plain data"),
                );
                return None;
            }
            Some(Type::Array(Box::new(elem), *len as u32))
        }
        ast::TypeExpr::Named(n) => {
            if let Some(t) = primitive(&n.text) {
                return Some(t);
            }
            match g.names.get(n.text.as_str()) {
                Some((ItemRef::Enum(id), _)) => Some(Type::Enum(*id)),
                Some((ItemRef::BufferType(id), _)) => Some(Type::Buffer(*id)),
                Some((ItemRef::Controller(_), _)) => {
                    diags.push(Diagnostic::error(
                        Code::TypeMismatch,
                        format!("`{}` is a controller, not a type", n.text),
                        n.span,
                        "expected a type",
                    ));
                    None
                }
                None => {
                    diags.push(
                        Diagnostic::error(
                            Code::UnknownName,
                            format!("unknown type `{}`", n.text),
                            n.span,
                            "not declared",
                        )
                        .with_help(format!(
                            "declare it with `enum {0} {{ … }}` or `buffer {0} {{ … }}`, or use one of {1}",
                            n.text,
                            PRIMITIVES.join(", ")
                        )),
                    );
                    None
                }
            }
        }
    }
}

pub(crate) fn primitive(name: &str) -> Option<Type> {
    Some(match name {
        "bool" => Type::Bool,
        "i8" => Type::Int(IntTy::I8),
        "i16" => Type::Int(IntTy::I16),
        "i32" => Type::Int(IntTy::I32),
        "i64" => Type::Int(IntTy::I64),
        "u8" => Type::Int(IntTy::U8),
        "u16" => Type::Int(IntTy::U16),
        "u32" => Type::Int(IntTy::U32),
        "u64" => Type::Int(IntTy::U64),
        "f32" => Type::Float(FloatTy::F32),
        "f64" => Type::Float(FloatTy::F64),
        _ => return None,
    })
}

fn lower_buffer_types(g: &Globals, ir: &mut Ir, diags: &mut Diagnostics) {
    for b in &g.buffers {
        let mut fields: Vec<FieldDef> = Vec::new();
        let mut names = ByName::default();
        for f in &b.fields {
            if !names.claim("field", &f.name, fields.len(), |k| fields[k].span, diags) {
                continue;
            }
            // An unresolved field type is reported; the field is kept (as
            // `Unit`, which its uses read as "already reported") so that they
            // cascade neither into unknown-field errors nor type mismatches.
            let ty = resolve_type(g, &f.ty, diags).unwrap_or(Type::Unit);
            fields.push(FieldDef {
                name: f.name.text.to_string(),
                docs: f.docs.clone(),
                ty,
                span: f.name.span,
            });
        }
        ir.buffer_types.push(BufferType {
            name: b.name.text.to_string(),
            docs: b.outer.docs.clone(),
            fields,
            span: b.span,
            name_span: b.name.span,
        });
    }
}

/// A buffer that contains itself (directly or through others) has no size.
fn check_buffer_recursion(ir: &Ir, diags: &mut Diagnostics) {
    let mut graph = DiGraph::<(), ()>::new();
    for _ in &ir.buffer_types {
        graph.add_node(());
    }
    fn inner(t: &Type) -> Option<BufferTypeId> {
        match t {
            Type::Buffer(b) => Some(*b),
            Type::Array(e, _) => inner(e),
            _ => None,
        }
    }
    for (i, b) in ir.buffer_types.iter().enumerate() {
        for f in &b.fields {
            if let Some(t) = inner(&f.ty) {
                graph.add_edge(NodeIndex::new(i), NodeIndex::new(t.index()), ());
            }
        }
    }
    for scc in petgraph::algo::kosaraju_scc(&graph) {
        let cyclic = scc.len() > 1 || graph.contains_edge(scc[0], scc[0]);
        if cyclic {
            let first = scc.iter().map(|n| n.index()).min().expect("non-empty");
            let b = &ir.buffer_types[first];
            diags.push(
                Diagnostic::error(
                    Code::TypeMismatch,
                    format!("buffer `{}` contains itself", b.name),
                    b.name_span,
                    "recursive buffer type",
                )
                .with_help(
                    "Global Memory buffers have a fixed size; remove the cycle of nested buffers",
                ),
            );
        }
    }
}

/// First pass over controllers: names, hierarchy and Global Memory, so that
/// plans can refer to any controller's commands and statuses.
fn lower_controller_headers<'a>(
    g: &Globals<'a>,
    ir: &mut Ir,
    sources: &SourceMap,
    diags: &mut Diagnostics,
) -> Vec<&'a ast::ControllerDef> {
    // Shells first, so subordinates can be resolved in any order.
    for c in &g.controllers {
        ir.controllers.push(Controller {
            name: c.name.text.to_string(),
            title: c.title.clone(),
            docs: c.outer.docs.clone(),
            level: None,
            supervisor: None,
            subordinates: Vec::new(),
            reads: Vec::new(),
            writes: Vec::new(),
            commands: Vec::new(),
            statuses: StatusId::BUILTIN
                .iter()
                .map(|n| StatusDef {
                    name: n.to_string(),
                    docs: Vec::new(),
                    span: None,
                })
                .collect(),
            errors: Vec::new(),
            vars: Vec::new(),
            hooks: Vec::new(),
            plans: Vec::new(),
            lints: c.outer.lints.iter().map(|(l, _)| *l).collect(),
            span: c.span,
            name_span: c.name.span,
            subordinate_spans: Vec::new(),
            subordinates_lists: Vec::new(),
            buffer_spans: Vec::new(),
            buffer_docs: Vec::new(),
            pre: None,
            post: None,
        });
    }
    // Where each controller was named as a subordinate, for multiple_supervisors.
    let mut supervised_at: Vec<Option<Span>> = vec![None; g.controllers.len()];
    let mut buffer_decl: Vec<(Span, Option<Span>)> = Vec::new(); // (first decl, writer decl)
    let mut buffer_names = ByName::default();
    for (i, c) in g.controllers.iter().enumerate() {
        let id = CtrlId(i as u32);
        let mut level_seen: Option<Span> = None;
        // The buffers this controller declared so far (`reads` or `writes`).
        let mut own_buffers: std::collections::BTreeSet<BufferId> = Default::default();
        for e in &c.entries {
            match &e.kind {
                ast::EntryKind::Level(n, _) => {
                    if let Some(first) = level_seen {
                        diags.push(
                            Diagnostic::error(
                                Code::DuplicateDefinition,
                                format!("controller `{}` gives its `level` twice", c.name.text),
                                e.span,
                                "second `level`",
                            )
                            .with_secondary(first, "first `level` here")
                            .with_help("keep one `level` line"),
                        );
                        continue;
                    }
                    level_seen = Some(e.span);
                    ir.controllers[i].level = Some((*n).min(u32::MAX as u64) as u32);
                }
                ast::EntryKind::Subordinates(names) => {
                    let list = names[0].span.to(names[names.len() - 1].span);
                    ir.controllers[i].subordinates_lists.push(list);
                    for n in names {
                        let sub = match g.names.get(n.text.as_str()) {
                            Some((ItemRef::Controller(s), _)) => *s,
                            _ => {
                                diags.push(
                                    Diagnostic::error(
                                        Code::UnknownSubordinate,
                                        format!("no controller named `{}`", n.text),
                                        n.span,
                                        "not a controller",
                                    )
                                    .with_help(
                                        "subordinates are controllers declared in this plan set",
                                    ),
                                );
                                continue;
                            }
                        };
                        if ir.controllers[i].subordinates.contains(&sub) {
                            let first = sub_span(c, &n.text).unwrap_or(n.span);
                            diags.push(duplicate("subordinate", &n.text, n.span, first));
                            continue;
                        }
                        if sub == id {
                            diags.push(
                                Diagnostic::error(
                                    Code::HierarchyCycle,
                                    format!(
                                        "controller `{}` lists itself as a subordinate",
                                        n.text
                                    ),
                                    n.span,
                                    "a controller cannot command itself",
                                )
                                .with_help("remove it from `subordinates`"),
                            );
                            continue;
                        }
                        if let Some(prev) = ir.controllers[sub.index()].supervisor {
                            // Report on the later naming in (file path, line) order.
                            let here = n.span;
                            let there = supervised_at[sub.index()].expect("set with supervisor");
                            let (later, earlier, later_sup, earlier_sup) =
                                if sources.order_key(here) >= sources.order_key(there) {
                                    (here, there, id, prev)
                                } else {
                                    (there, here, prev, id)
                                };
                            diags.push(
                                Diagnostic::error(
                                    Code::MultipleSupervisors,
                                    format!(
                                        "controller `{}` has two supervisors, `{}` and `{}`",
                                        n.text,
                                        ir.controllers[earlier_sup.index()].name,
                                        ir.controllers[later_sup.index()].name
                                    ),
                                    later,
                                    "second supervisor names it here",
                                )
                                .with_secondary(earlier, "first supervisor names it here")
                                .with_help("each controller has one supervisor (§3.5); move the command path through one of them"),
                            );
                            // Still a subordinate here, so that this plan's
                            // commands and status reads do not cascade.
                            ir.controllers[i].subordinates.push(sub);
                            ir.controllers[i].subordinate_spans.push(n.span);
                            continue;
                        }
                        ir.controllers[sub.index()].supervisor = Some(id);
                        supervised_at[sub.index()] = Some(n.span);
                        ir.controllers[i].subordinates.push(sub);
                        ir.controllers[i].subordinate_spans.push(n.span);
                    }
                }
                ast::EntryKind::Reads(name, ty) | ast::EntryKind::Writes(name, ty) => {
                    let writes = matches!(e.kind, ast::EntryKind::Writes(..));
                    let bty = match resolve_type(g, &ast::TypeExpr::Named(ty.clone()), diags) {
                        Some(Type::Buffer(b)) => Some(b),
                        Some(_) => {
                            diags.push(
                                Diagnostic::error(
                                    Code::TypeMismatch,
                                    format!("`{}` is not a buffer type", ty.text),
                                    ty.span,
                                    "expected a `buffer` declared in this plan set",
                                )
                                .with_help(
                                    "Global Memory holds buffers; wrap the value in a `buffer`",
                                ),
                            );
                            None
                        }
                        None => None,
                    };
                    let Some(bty) = bty else { continue };
                    let existing = buffer_names.first_or_insert(&name.text, ir.buffers.len());
                    let bid = match existing {
                        Some(b) if ir.buffers[b].ty == bty => BufferId(b as u32),
                        found => {
                            if let Some(b) = found {
                                let (first, _) = buffer_decl[b];
                                diags.push(
                                    Diagnostic::error(
                                        Code::BufferTypeConflict,
                                        format!(
                                            "buffer `{}` is declared as `{}` here but as `{}` before",
                                            name.text,
                                            ty.text,
                                            ir.buffer_types[ir.buffers[b].ty.index()].name
                                        ),
                                        ty.span,
                                        "conflicting type",
                                    )
                                    .with_secondary(first, "first declared here")
                                    .with_help("a Global Memory buffer has one type across the plan set"),
                                );
                            }
                            // A new buffer. After a type conflict it is a
                            // stand-in: inside this controller the buffer has
                            // the type it declares, which keeps its uses from
                            // cascading (no IR is produced anyway).
                            ir.buffers.push(Buffer {
                                name: name.text.to_string(),
                                ty: bty,
                                writer: None,
                                readers: Vec::new(),
                            });
                            buffer_decl.push((name.span, None));
                            BufferId(ir.buffers.len() as u32 - 1)
                        }
                    };
                    let ctrl = &mut ir.controllers[i];
                    if !own_buffers.insert(bid) {
                        // This controller's own earlier declaration.
                        let first = ctrl
                            .buffer_spans
                            .iter()
                            .find(|(b, _)| *b == bid)
                            .map_or(buffer_decl[bid.index()].0, |(_, s)| *s);
                        diags.push(duplicate("buffer", &name.text, name.span, first));
                        continue;
                    }
                    if writes {
                        if let Some(w) = ir.buffers[bid.index()].writer {
                            let first = buffer_decl[bid.index()].1.expect("writer has a span");
                            diags.push(
                                Diagnostic::error(
                                    Code::MultipleWriters,
                                    format!(
                                        "buffer `{}` is written by `{}` and by `{}`",
                                        name.text, ir.controllers[w.index()].name, c.name.text
                                    ),
                                    name.span,
                                    "second writer",
                                )
                                .with_secondary(first, "first writer")
                                .with_help("Global Memory has one writer per buffer (§3.8.5); let the other controller `reads` it"),
                            );
                            // Still writable here, so that its uses do not cascade.
                            ir.controllers[i].writes.push(bid);
                            ir.controllers[i].buffer_spans.push((bid, name.span));
                            continue;
                        }
                        ir.buffers[bid.index()].writer = Some(id);
                        buffer_decl[bid.index()].1 = Some(name.span);
                        ir.controllers[i].writes.push(bid);
                    } else {
                        ir.buffers[bid.index()].readers.push(id);
                        ir.controllers[i].reads.push(bid);
                    }
                    ir.controllers[i].buffer_spans.push((bid, name.span));
                    if !e.outer.docs.is_empty() {
                        ir.controllers[i]
                            .buffer_docs
                            .push((bid, e.outer.docs.clone()));
                    }
                }
                _ => {}
            }
        }
    }
    declarations::lower_declarations(g, ir, diags);
    g.controllers.clone()
}

fn sub_span(c: &ast::ControllerDef, name: &str) -> Option<Span> {
    c.entries.iter().find_map(|e| match &e.kind {
        ast::EntryKind::Subordinates(ns) => ns.iter().find(|n| n.text == name).map(|n| n.span),
        _ => None,
    })
}

/// With one supervisor each, a cycle is a ring of controllers each above the
/// next. Kosaraju rather than Tarjan: petgraph's Tarjan recurses per node,
/// and a long chain of controllers must not exhaust the stack.
fn check_hierarchy_cycles(ir: &Ir, diags: &mut Diagnostics) {
    let mut graph = DiGraph::<(), ()>::new();
    for _ in &ir.controllers {
        graph.add_node(());
    }
    for (i, c) in ir.controllers.iter().enumerate() {
        for s in &c.subordinates {
            graph.add_edge(NodeIndex::new(i), NodeIndex::new(s.index()), ());
        }
    }
    for scc in petgraph::algo::kosaraju_scc(&graph) {
        if scc.len() < 2 {
            continue;
        }
        let mut members: Vec<u32> = scc.iter().map(|n| n.index() as u32).collect();
        members.sort_unstable();
        let names: Vec<&str> = members
            .iter()
            .map(|m| ir.controllers[*m as usize].name.as_str())
            .collect();
        let first = &ir.controllers[members[0] as usize];
        let mut d = Diagnostic::error(
            Code::HierarchyCycle,
            format!(
                "controllers {} command each other in a cycle",
                names
                    .iter()
                    .map(|n| format!("`{n}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            first.name_span,
            "this controller is above itself",
        )
        .with_help("the hierarchy is a tree (§3.5): remove one `subordinates` entry of the cycle");
        for m in &members[1..] {
            let c = &ir.controllers[*m as usize];
            d = d.with_secondary(c.name_span, "part of the cycle");
        }
        diags.push(d);
    }
}

/// The executives: the manifest's `schedule`, or one CPU running every
/// controller top-down (pre-order from each root, in declaration order).
fn lower_schedule(ir: &Ir, m: &Manifest, diags: &mut Diagnostics) -> Vec<Cpu> {
    let Some(specs) = &m.schedule else {
        let mut order = Vec::new();
        let mut seen = vec![false; ir.controllers.len()];
        for (i, c) in ir.controllers.iter().enumerate() {
            if c.supervisor.is_none() {
                preorder(ir, CtrlId(i as u32), &mut order, &mut seen);
            }
        }
        // Controllers caught in a cycle have no root; keep them in declaration order.
        for (i, s) in seen.iter().enumerate() {
            if !s {
                order.push(CtrlId(i as u32));
            }
        }
        return vec![Cpu {
            name: "main".to_string(),
            period_ns: DEFAULT_PERIOD_NS,
            order,
            process: None,
            inputs: Vec::new(),
        }];
    };
    let mut placed: Vec<Option<Span>> = vec![None; ir.controllers.len()];
    let mut cpus = Vec::new();
    for spec in specs {
        let mut order = Vec::new();
        for (name, span) in &spec.order {
            match ir.controller_by_name(name) {
                None => diags.push(
                    Diagnostic::error(
                        Code::Manifest,
                        format!("`schedule` names `{name}`, which is not a controller"),
                        *span,
                        "unknown controller",
                    )
                    .with_help(format!(
                        "the controllers are: {}",
                        ir.controllers
                            .iter()
                            .map(|c| c.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )),
                ),
                Some(id) => {
                    if let Some(first) = placed[id.index()] {
                        diags.push(
                            Diagnostic::error(
                                Code::Manifest,
                                format!("controller `{name}` is scheduled twice"),
                                *span,
                                "scheduled again here",
                            )
                            .with_secondary(first, "first scheduled here")
                            .with_help("every controller runs exactly once per cycle, on one CPU"),
                        );
                    } else {
                        placed[id.index()] = Some(*span);
                        order.push(id);
                    }
                }
            }
        }
        cpus.push(Cpu {
            name: spec.name.clone(),
            period_ns: spec.period_ns,
            order,
            process: spec.process.as_ref().map(|p| p.0.clone()),
            inputs: Vec::new(),
        });
    }
    let missing: Vec<&str> = ir
        .controllers
        .iter()
        .zip(&placed)
        .filter(|(_, p)| p.is_none())
        .map(|(c, _)| c.name.as_str())
        .collect();
    if !missing.is_empty() {
        let span = m
            .schedule_span
            .or_else(|| specs.first().map(|s| s.span))
            .expect("a schedule has a span");
        diags.push(
            Diagnostic::error(
                Code::Manifest,
                format!(
                    "the schedule leaves out {}",
                    missing
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                span,
                "not every controller is scheduled",
            )
            .with_help("list every controller exactly once across all CPUs' `order`"),
        );
    }
    crate::placement::lower_inputs(ir, specs, &mut cpus, diags);
    cpus
}

/// Pre-order walk, iterative so that a deep hierarchy cannot exhaust the stack.
fn preorder(ir: &Ir, root: CtrlId, out: &mut Vec<CtrlId>, seen: &mut [bool]) {
    let mut stack = vec![root];
    while let Some(id) = stack.pop() {
        if std::mem::replace(&mut seen[id.index()], true) {
            continue;
        }
        out.push(id);
        stack.extend(ir.controllers[id.index()].subordinates.iter().rev());
    }
}
