//! The index's first pass: every declaration of the set, into the scope
//! `lower` looks it up in — the set's global names, and per controller
//! (or controller type) body its verbs, parameters, hooks, job lists, row
//! blocks, values, status words, error codes and each plan's states.

use std::collections::HashMap;

use rcs_dsl::ast::{self, EntryKind, Item};
use rcs_dsl::source::{FileId, Span};

use super::{Index, Kind, Symbol, SymbolId};

/// Names visible everywhere in the set.
#[derive(Default)]
pub struct Globals {
    /// A controller (plain or an instance) and its body.
    pub controllers: HashMap<String, (SymbolId, Option<usize>)>,
    /// A controller type and its body.
    pub types: HashMap<String, (SymbolId, usize)>,
    pub buffer_types: HashMap<String, SymbolId>,
    /// (buffer type, field).
    pub fields: HashMap<(String, String), SymbolId>,
    pub enums: HashMap<String, SymbolId>,
    /// (enum, variant).
    pub variants: HashMap<(String, String), SymbolId>,
    /// A variant by its name alone, for a bare variant (`state == Idle`).
    pub variants_named: HashMap<String, Vec<SymbolId>>,
    pub consts: HashMap<String, SymbolId>,
    /// Global Memory buffers named by plain controllers' `reads`/`writes`.
    pub buffers: HashMap<String, SymbolId>,
}

/// One controller's (or controller type's) own names.
#[derive(Default)]
pub struct Body {
    pub is_type: bool,
    pub verbs: HashMap<String, SymbolId>,
    /// (verb, hook or job list, parameter).
    pub params: HashMap<(String, String), SymbolId>,
    pub hooks: HashMap<String, SymbolId>,
    pub job_lists: HashMap<String, SymbolId>,
    pub blocks: HashMap<String, SymbolId>,
    /// Vars, status fields, consts, type parameters, and a type's local
    /// buffer names.
    pub values: HashMap<String, SymbolId>,
    /// A `reads`/`writes` name and its buffer type's name.
    pub buffer_type_of: HashMap<String, String>,
    pub statuses: HashMap<String, SymbolId>,
    pub errors: HashMap<String, SymbolId>,
    /// A type's subordinate slots.
    pub slots: HashMap<String, SymbolId>,
    /// Per plan (by its place among the body's plans), its states.
    pub states: Vec<HashMap<String, SymbolId>>,
}

pub struct Scopes {
    pub globals: Globals,
    pub bodies: Vec<Body>,
}

struct Declarer<'d, 't> {
    index: &'d mut Index,
    texts: &'d dyn Fn(FileId) -> &'t str,
}

impl Declarer<'_, '_> {
    fn add(
        &mut self,
        name: &ast::Name,
        kind: Kind,
        parent: Option<SymbolId>,
        whole: Span,
        docs: &[String],
    ) -> SymbolId {
        let signature = first_line((self.texts)(whole.file), whole);
        self.index.symbols.push(Symbol {
            name: name.text.to_string(),
            kind,
            def: name.span,
            parent,
            signature,
            docs: docs.to_vec(),
        });
        self.index.symbols.len() - 1
    }
}

/// The declaration's first line as written (after its docs), up to a `{`
/// that opens a body.
fn first_line(text: &str, span: Span) -> String {
    let start = (span.start as usize).min(text.len());
    let end = (span.end as usize).clamp(start, text.len());
    let part = text.get(start..end).unwrap_or("");
    // The entry's span starts at its doc comment and attributes.
    let line = part
        .lines()
        .find(|l| {
            let l = l.trim_start();
            !l.is_empty() && !l.starts_with("//") && !l.starts_with("#[")
        })
        .unwrap_or("");
    let line = match line.find('{') {
        Some(i) if line[i..].trim() == "{" || !line.contains('}') => &line[..i],
        _ => line,
    };
    line.trim().to_string()
}

fn span_of(a: Span, b: Span) -> Span {
    Span {
        file: a.file,
        start: a.start.min(b.start),
        end: a.end.max(b.end),
    }
}

/// Declare every name of `files`.
pub fn declare<'t>(index: &mut Index, files: &[(FileId, &'t str, ast::File)]) -> Scopes {
    let texts = |id: FileId| -> &'t str {
        files
            .iter()
            .find(|(f, _, _)| *f == id)
            .map_or("", |(_, t, _)| *t)
    };
    let mut d = Declarer {
        index,
        texts: &texts,
    };
    let mut g = Globals::default();
    let mut bodies = Vec::new();
    // Types, enums, buffer types, consts and plain controllers first:
    // instances name a type that may come later in the set.
    for (_, _, file) in files {
        for item in &file.items {
            match item {
                Item::Enum(e) => {
                    let id = d.add(&e.name, Kind::Enum, None, e.span, &e.outer.docs);
                    g.enums.insert(e.name.text.to_string(), id);
                    for (docs, v) in &e.variants {
                        let vid = d.add(v, Kind::Variant, Some(id), v.span, docs);
                        g.variants
                            .insert((e.name.text.to_string(), v.text.to_string()), vid);
                        g.variants_named
                            .entry(v.text.to_string())
                            .or_default()
                            .push(vid);
                    }
                }
                Item::Buffer(b) => {
                    let id = d.add(&b.name, Kind::BufferType, None, b.span, &b.outer.docs);
                    g.buffer_types.insert(b.name.text.to_string(), id);
                    for f in &b.fields {
                        let whole = span_of(f.name.span, f.ty.span());
                        let fid = d.add(&f.name, Kind::Field, Some(id), whole, &f.docs);
                        g.fields
                            .insert((b.name.text.to_string(), f.name.text.to_string()), fid);
                    }
                }
                Item::Const(c) => {
                    let id = d.add(&c.name, Kind::Const, None, c.span, &[]);
                    g.consts.entry(c.name.text.to_string()).or_insert(id);
                }
                Item::Controller(c) => {
                    let id = d.add(&c.name, Kind::Controller, None, c.span, &c.outer.docs);
                    let body = declare_body(&mut d, &mut g, c, id, false, &[]);
                    bodies.push(body);
                    g.controllers
                        .entry(c.name.text.to_string())
                        .or_insert((id, Some(bodies.len() - 1)));
                }
                Item::ControllerType(t) => {
                    let c = &t.def;
                    let id = d.add(&c.name, Kind::ControllerType, None, c.span, &c.outer.docs);
                    let body = declare_body(&mut d, &mut g, c, id, true, &t.params);
                    bodies.push(body);
                    g.types
                        .entry(c.name.text.to_string())
                        .or_insert((id, bodies.len() - 1));
                }
                Item::Instance(_) => {}
            }
        }
    }
    for (_, _, file) in files {
        for item in &file.items {
            if let Item::Instance(i) = item {
                let id = d.add(&i.name, Kind::Controller, None, i.span, &i.outer.docs);
                let body = g.types.get(i.ty.text.as_str()).map(|&(_, b)| b);
                g.controllers
                    .entry(i.name.text.to_string())
                    .or_insert((id, body));
            }
        }
    }
    Scopes { globals: g, bodies }
}

fn declare_body(
    d: &mut Declarer<'_, '_>,
    g: &mut Globals,
    c: &ast::ControllerDef,
    owner: SymbolId,
    is_type: bool,
    type_params: &[ast::Param],
) -> Body {
    let mut b = Body {
        is_type,
        ..Body::default()
    };
    for p in type_params {
        let whole = span_of(p.name.span, p.ty.span());
        let id = d.add(&p.name, Kind::TypeParam, Some(owner), whole, &p.docs);
        b.values.insert(p.name.text.to_string(), id);
    }
    for e in &c.entries {
        let docs = &e.outer.docs;
        match &e.kind {
            EntryKind::Subordinates(names) if is_type => {
                for n in names {
                    let id = d.add(n, Kind::SubordinateSlot, Some(owner), e.span, docs);
                    b.slots.insert(n.text.to_string(), id);
                }
            }
            EntryKind::Reads(n, ty) | EntryKind::Writes(n, ty) => {
                b.buffer_type_of
                    .insert(n.text.to_string(), ty.text.to_string());
                if is_type {
                    let id = d.add(n, Kind::Buffer, Some(owner), e.span, docs);
                    b.values.insert(n.text.to_string(), id);
                } else if !g.buffers.contains_key(n.text.as_str()) {
                    // A Global Memory buffer is one buffer by its name,
                    // declared where it is first named.
                    let id = d.add(n, Kind::Buffer, None, e.span, docs);
                    g.buffers.insert(n.text.to_string(), id);
                }
            }
            EntryKind::Command { name, params, .. } => {
                let id = d.add(name, Kind::Verb, Some(owner), e.span, docs);
                b.verbs.insert(name.text.to_string(), id);
                declare_params(d, &mut b, params, &name.text, id);
            }
            EntryKind::Hook { name, params, .. } => {
                let id = d.add(name, Kind::Hook, Some(owner), e.span, docs);
                b.hooks.insert(name.text.to_string(), id);
                declare_params(d, &mut b, params, &name.text, id);
            }
            EntryKind::Jobs(j) => {
                let id = d.add(&j.name, Kind::JobList, Some(owner), e.span, docs);
                b.job_lists.insert(j.name.text.to_string(), id);
                declare_params(d, &mut b, &j.params, &j.name.text, id);
            }
            EntryKind::Rows(r) => {
                let id = d.add(&r.name, Kind::RowBlock, Some(owner), e.span, docs);
                b.blocks.insert(r.name.text.to_string(), id);
            }
            EntryKind::Var { name, .. } => {
                let id = d.add(name, Kind::Var, Some(owner), e.span, docs);
                b.values.insert(name.text.to_string(), id);
            }
            EntryKind::StatusField { name, .. } => {
                let id = d.add(name, Kind::StatusField, Some(owner), e.span, docs);
                b.values.insert(name.text.to_string(), id);
            }
            EntryKind::Const(k) => {
                let id = d.add(&k.name, Kind::Const, Some(owner), k.span, docs);
                b.values.insert(k.name.text.to_string(), id);
            }
            EntryKind::Status(names) => {
                for n in names {
                    let id = d.add(n, Kind::Status, Some(owner), e.span, docs);
                    b.statuses.insert(n.text.to_string(), id);
                }
            }
            EntryKind::Error(names) => {
                for n in names {
                    let id = d.add(n, Kind::ErrorCode, Some(owner), e.span, docs);
                    b.errors.insert(n.text.to_string(), id);
                }
            }
            _ => {}
        }
    }
    let blocks: HashMap<&str, &ast::RowsDef> = c
        .entries
        .iter()
        .filter_map(|e| match &e.kind {
            EntryKind::Rows(r) => Some((r.name.text.as_str(), r)),
            _ => None,
        })
        .collect();
    for e in &c.entries {
        if let EntryKind::Plan(p) = &e.kind {
            let states = declare_states(d, p, &blocks, owner);
            b.states.push(states);
        }
    }
    b
}

fn declare_params(
    d: &mut Declarer<'_, '_>,
    b: &mut Body,
    params: &[ast::Param],
    of: &str,
    parent: SymbolId,
) {
    for p in params {
        let whole = span_of(p.name.span, p.ty.span());
        let id = d.add(&p.name, Kind::Param, Some(parent), whole, &p.docs);
        b.params
            .insert((of.to_string(), p.name.text.to_string()), id);
    }
}

/// A plan's states, each declared where the plan first names it (its own
/// rows and, at each `use`, the block's rows in place). A name only in a
/// block's `from` is not a state of the plan (LANGUAGE.md §8), so a
/// block's `from` declares nothing.
fn declare_states(
    d: &mut Declarer<'_, '_>,
    p: &ast::PlanDef,
    blocks: &HashMap<&str, &ast::RowsDef>,
    owner: SymbolId,
) -> HashMap<String, SymbolId> {
    let mut states: HashMap<String, SymbolId> = HashMap::new();
    let plan = p.verb.text.to_string();
    let mut name = |d: &mut Declarer<'_, '_>, n: &ast::Name| {
        if n.text == "Done" || states.contains_key(n.text.as_str()) {
            return;
        }
        d.index.symbols.push(Symbol {
            name: n.text.to_string(),
            kind: Kind::State,
            def: n.span,
            parent: Some(owner),
            signature: format!("state {} of plan {plan}", n.text),
            docs: Vec::new(),
        });
        states.insert(n.text.to_string(), d.index.symbols.len() - 1);
    };
    let mut rows: Vec<(&ast::Row, bool)> = Vec::new();
    for (at, r) in p.rows.iter().enumerate() {
        for u in p.uses.iter().filter(|u| u.at == at) {
            if let Some(block) = blocks.get(u.name.text.as_str()) {
                rows.extend(block.rows.iter().map(|r| (r, true)));
            }
        }
        rows.push((r, false));
    }
    for u in p.uses.iter().filter(|u| u.at >= p.rows.len()) {
        if let Some(block) = blocks.get(u.name.text.as_str()) {
            rows.extend(block.rows.iter().map(|r| (r, true)));
        }
    }
    for (r, shared) in rows {
        if !shared {
            match &r.from {
                ast::From::State(n) => name(d, n),
                ast::From::States(ns, _) | ast::From::Except(_, ns, _) => {
                    ns.iter().for_each(|n| name(d, n));
                }
                ast::From::DontCare(..) | ast::From::Implicit => {}
            }
        }
        if let ast::Target::State(n) = &r.target {
            name(d, n);
        }
    }
    states
}
