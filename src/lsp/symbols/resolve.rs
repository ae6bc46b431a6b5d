//! The index's second pass: every use of a name, resolved in the scope
//! `lower` would look it up in (a job list's parameters, then the body's
//! values, subordinates, the set's consts, …). A use that is not
//! declared, or could mean two things, is left out.

use std::collections::HashMap;

use rcs_dsl::ast::{self, BinOp, EntryKind, ExprKind, Item, Job};
use rcs_dsl::source::{FileId, Span};

use super::declare::{Body, Globals, Scopes};
use super::{Index, Kind, SymbolId};

/// Where a name is being read: the body, the verb whose plan (or accept
/// condition) it is in, the job list whose parameters are in scope, and
/// for a shared block the plans that place it.
struct At<'s> {
    body: &'s Body,
    verbs: Vec<String>,
    job_list: Option<String>,
    /// The state tables a state name is looked up in (one plan's, or every
    /// plan placing a block).
    states: Vec<&'s HashMap<String, SymbolId>>,
}

struct Resolver<'s> {
    g: &'s Globals,
    /// Each symbol's kind, by id.
    kinds: Vec<Kind>,
    bodies: &'s [Body],
    uses: Vec<(Span, SymbolId)>,
}

pub fn resolve(index: &mut Index, scopes: &Scopes, files: &[(FileId, &str, ast::File)]) {
    let mut r = Resolver {
        g: &scopes.globals,
        kinds: index.symbols.iter().map(|s| s.kind).collect(),
        bodies: &scopes.bodies,
        uses: Vec::new(),
    };
    let mut body_ix = 0;
    for (_, _, file) in files {
        for item in &file.items {
            match item {
                Item::Controller(c) => {
                    r.body(c, body_ix);
                    body_ix += 1;
                }
                Item::ControllerType(t) => {
                    for p in &t.params {
                        r.ty(&p.ty);
                    }
                    r.body(&t.def, body_ix);
                    body_ix += 1;
                }
                Item::Instance(i) => r.instance(i),
                Item::Enum(_) => {}
                Item::Buffer(b) => b.fields.iter().for_each(|f| r.ty(&f.ty)),
                Item::Const(c) => {
                    r.ty(&c.ty);
                    r.global_expr(&c.value);
                }
            }
        }
    }
    index.uses.extend(r.uses);
}

impl<'s> Resolver<'s> {
    fn put(&mut self, span: Span, id: Option<SymbolId>) {
        if let Some(id) = id {
            self.uses.push((span, id));
        }
    }

    fn controller(&self, name: &str) -> Option<(SymbolId, Option<&'s Body>)> {
        self.g
            .controllers
            .get(name)
            .map(|&(id, b)| (id, b.and_then(|b| self.bodies.get(b))))
    }

    fn ty(&mut self, t: &ast::TypeExpr) {
        match t {
            ast::TypeExpr::Named(n) => {
                let id = self
                    .g
                    .enums
                    .get(n.text.as_str())
                    .or_else(|| self.g.buffer_types.get(n.text.as_str()))
                    .copied();
                self.put(n.span, id);
            }
            ast::TypeExpr::Array { elem, len_expr, .. } => {
                self.ty(elem);
                if let Some(e) = len_expr {
                    self.global_expr(e);
                }
            }
        }
    }

    fn instance(&mut self, i: &ast::InstanceDef) {
        let Some(&(ty, body)) = self.g.types.get(i.ty.text.as_str()) else {
            return;
        };
        self.put(i.ty.span, Some(ty));
        let body = &self.bodies[body];
        for (name, value) in &i.args {
            self.put(name.span, body.values.get(name.text.as_str()).copied());
            self.global_expr(value);
        }
        for (local, global) in &i.bindings {
            if let Some(&slot) = body.slots.get(local.text.as_str()) {
                self.put(local.span, Some(slot));
                let sub = self.controller(&global.text).map(|(id, _)| id);
                self.put(global.span, sub);
            } else {
                self.put(local.span, body.values.get(local.text.as_str()).copied());
                self.put(
                    global.span,
                    self.g.buffers.get(global.text.as_str()).copied(),
                );
            }
        }
    }

    /// A file-level expression: consts and qualified variants only.
    fn global_expr(&mut self, e: &ast::Expr) {
        e.walk(&mut |e| match &e.kind {
            ExprKind::Path(None, n) => {
                let id = self.g.consts.get(n.text.as_str()).copied();
                self.put(n.span, id);
            }
            ExprKind::Path(Some(q), n) => self.qualified(q, n),
            _ => {}
        });
    }

    fn qualified(&mut self, q: &ast::Name, n: &ast::Name) {
        if let Some(&e) = self.g.enums.get(q.text.as_str()) {
            self.put(q.span, Some(e));
            let v = self
                .g
                .variants
                .get(&(q.text.to_string(), n.text.to_string()))
                .copied();
            self.put(n.span, v);
        } else if let Some((c, body)) = self.controller(&q.text) {
            self.put(q.span, Some(c));
            self.put(
                n.span,
                body.and_then(|b| b.statuses.get(n.text.as_str()).copied()),
            );
        }
    }

    fn body(&mut self, c: &ast::ControllerDef, ix: usize) {
        let body = &self.bodies[ix];
        let mut plan_ix = 0;
        let plans_of_block = |name: &str| -> Vec<usize> {
            c.entries
                .iter()
                .filter_map(|e| match &e.kind {
                    EntryKind::Plan(p) => Some(p),
                    _ => None,
                })
                .enumerate()
                .filter(|(_, p)| p.uses.iter().any(|u| u.name.text == name))
                .map(|(i, _)| i)
                .collect()
        };
        let plain = At::of(body);
        for e in &c.entries {
            match &e.kind {
                EntryKind::Subordinates(names) => {
                    for n in names {
                        let id = if body.is_type {
                            body.slots.get(n.text.as_str()).copied()
                        } else {
                            self.controller(&n.text).map(|(id, _)| id)
                        };
                        self.put(n.span, id);
                    }
                }
                EntryKind::Reads(n, ty) | EntryKind::Writes(n, ty) => {
                    if !body.is_type {
                        self.put(n.span, self.g.buffers.get(n.text.as_str()).copied());
                    }
                    self.put(ty.span, self.g.buffer_types.get(ty.text.as_str()).copied());
                }
                EntryKind::Command {
                    name,
                    params,
                    accept,
                } => {
                    params.iter().for_each(|p| self.ty(&p.ty));
                    if let Some(a) = accept {
                        let at = At {
                            verbs: vec![name.text.to_string()],
                            ..At::of(body)
                        };
                        self.expr(&at, &a.cond);
                    }
                }
                EntryKind::Hook { params, ret, .. } => {
                    params.iter().for_each(|p| self.ty(&p.ty));
                    if let Some(t) = ret {
                        self.ty(t);
                    }
                }
                EntryKind::Var { ty, init, .. } | EntryKind::StatusField { ty, init, .. } => {
                    self.ty(ty);
                    if let Some(i) = init {
                        self.expr(&plain, i);
                    }
                }
                EntryKind::Const(k) => {
                    self.ty(&k.ty);
                    self.expr(&plain, &k.value);
                }
                EntryKind::EveryCycle(ec) => {
                    ec.jobs.iter().for_each(|j| self.job(&plain, j));
                }
                EntryKind::Jobs(j) => {
                    j.params.iter().for_each(|p| self.ty(&p.ty));
                    let at = At {
                        job_list: Some(j.name.text.to_string()),
                        ..At::of(body)
                    };
                    j.jobs.iter().for_each(|job| self.job(&at, job));
                }
                EntryKind::Rows(block) => {
                    let at = At {
                        states: plans_of_block(&block.name.text)
                            .into_iter()
                            .filter_map(|p| body.states.get(p))
                            .collect(),
                        ..At::of(body)
                    };
                    for row in &block.rows {
                        self.row(&at, row);
                    }
                }
                EntryKind::Plan(p) => {
                    let verbs: Vec<&ast::Name> =
                        std::iter::once(&p.verb).chain(&p.more_verbs).collect();
                    for v in &verbs {
                        self.put(v.span, body.verbs.get(v.text.as_str()).copied());
                    }
                    for u in &p.uses {
                        self.put(u.name.span, body.blocks.get(u.name.text.as_str()).copied());
                    }
                    let at = At {
                        verbs: verbs.iter().map(|v| v.text.to_string()).collect(),
                        states: body.states.get(plan_ix).into_iter().collect(),
                        ..At::of(body)
                    };
                    for row in &p.rows {
                        self.row(&at, row);
                    }
                    plan_ix += 1;
                }
                EntryKind::Level(..) | EntryKind::Status(_) | EntryKind::Error(_) => {}
            }
        }
    }

    fn state(&mut self, at: &At, n: &ast::Name) {
        for states in &at.states {
            if let Some(&id) = states.get(n.text.as_str()) {
                self.uses.push((n.span, id));
            }
        }
    }

    fn row(&mut self, at: &At, row: &ast::Row) {
        match &row.from {
            ast::From::State(n) => self.state(at, n),
            ast::From::States(ns, _) | ast::From::Except(_, ns, _) => {
                ns.iter().for_each(|n| self.state(at, n));
            }
            ast::From::DontCare(..) | ast::From::Implicit => {}
        }
        if let Some(c) = &row.cond {
            self.expr(at, c);
        }
        match &row.target {
            ast::Target::State(n) => self.state(at, n),
            ast::Target::Error(Some(code), _) => {
                self.put(code.span, at.body.errors.get(code.text.as_str()).copied());
            }
            ast::Target::Error(None, _) | ast::Target::Same(_) => {}
        }
        row.jobs.iter().for_each(|j| self.job(at, j));
    }

    fn job(&mut self, at: &At, job: &Job) {
        match job {
            Job::Send {
                sub, verb, args, ..
            } => {
                let body = self.sub(at, sub);
                let verb_id = body.and_then(|b| b.verbs.get(verb.text.as_str()).copied());
                self.put(verb.span, verb_id);
                for (name, value) in args {
                    let param = body.and_then(|b| {
                        b.params
                            .get(&(verb.text.to_string(), name.text.to_string()))
                            .copied()
                    });
                    self.put(name.span, param);
                    self.expr(at, value);
                }
            }
            Job::Forward { sub, .. } => {
                self.sub(at, sub);
            }
            Job::Report(name, _) => {
                self.put(name.span, at.body.statuses.get(name.text.as_str()).copied());
            }
            Job::ReportCode(_, code, _) => {
                self.put(code.span, at.body.errors.get(code.text.as_str()).copied());
            }
            Job::Assign { place, value, .. } => {
                self.expr(at, place);
                self.expr(at, value);
            }
            Job::Call(e) => self.expr(at, e),
        }
    }

    /// A subordinate named in a job: the controller (and its body, whose
    /// verbs a send names), or in a type the slot (bound per instance, so
    /// its verbs are not resolved).
    fn sub(&mut self, at: &At, n: &ast::Name) -> Option<&'s Body> {
        if at.body.is_type {
            self.put(n.span, at.body.slots.get(n.text.as_str()).copied());
            return None;
        }
        let (id, body) = self.controller(&n.text)?;
        self.uses.push((n.span, id));
        body
    }

    /// A bare name, in `lower`'s order: a job list's parameter, the body's
    /// values, a subordinate, the set's consts and buffers, a variant no
    /// other enum shares, this controller's error codes and status words.
    fn bare(&self, at: &At, n: &str) -> Option<SymbolId> {
        if let Some(list) = &at.job_list {
            if let Some(&id) = at.body.params.get(&(list.clone(), n.to_string())) {
                return Some(id);
            }
        }
        if let Some(&id) = at.body.values.get(n) {
            return Some(id);
        }
        if at.body.is_type {
            if let Some(&id) = at.body.slots.get(n) {
                return Some(id);
            }
        } else if at.body.buffer_type_of.contains_key(n) {
            return self.g.buffers.get(n).copied();
        } else if let Some((id, _)) = self.controller(n) {
            return Some(id);
        }
        if let Some(&id) = self.g.consts.get(n) {
            return Some(id);
        }
        if let Some([id]) = self.g.variants_named.get(n).map(Vec::as_slice) {
            return Some(*id);
        }
        at.body
            .errors
            .get(n)
            .or_else(|| at.body.statuses.get(n))
            .copied()
    }

    fn expr(&mut self, at: &At, e: &ast::Expr) {
        match &e.kind {
            ExprKind::Path(None, n) => {
                let id = self.bare(at, &n.text);
                self.put(n.span, id);
            }
            ExprKind::Path(Some(q), n) => self.qualified(q, n),
            ExprKind::CmdParam(p) => {
                let found: Vec<SymbolId> = at
                    .verbs
                    .iter()
                    .filter_map(|v| {
                        at.body
                            .params
                            .get(&(v.clone(), p.text.to_string()))
                            .copied()
                    })
                    .collect();
                if let [id] = found[..] {
                    self.put(p.span, Some(id));
                }
            }
            ExprKind::Call(name, args) => {
                let id = at
                    .body
                    .hooks
                    .get(name.text.as_str())
                    .or_else(|| at.body.job_lists.get(name.text.as_str()))
                    .copied();
                self.put(name.span, id);
                args.iter().for_each(|a| self.expr(at, a));
            }
            ExprKind::Field(base, f) => {
                self.expr(at, base);
                let id = self.field(at, base, &f.text);
                self.put(f.span, id);
            }
            ExprKind::Binary(op, ops) => {
                let [l, r] = &**ops;
                let compared = matches!(op, BinOp::Eq | BinOp::Ne);
                if !(compared && self.compared_with_sub(at, l, r)) {
                    self.expr(at, r);
                }
                if !(compared && self.compared_with_sub(at, r, l)) {
                    self.expr(at, l);
                }
            }
            ExprKind::Index(a, b) => {
                self.expr(at, a);
                self.expr(at, b);
            }
            ExprKind::Unary(_, b) | ExprKind::Paren(b) => self.expr(at, b),
            ExprKind::Cast(b, ty) => {
                self.expr(at, b);
                self.put(ty.span, self.g.enums.get(ty.text.as_str()).copied());
            }
            _ => {}
        }
    }

    /// `base.f`: a field of a buffer named by this body, or a status field
    /// of a subordinate.
    fn field(&self, at: &At, base: &ast::Expr, f: &str) -> Option<SymbolId> {
        let ExprKind::Path(None, b) = &base.kind else {
            return None;
        };
        if let Some(ty) = at.body.buffer_type_of.get(b.text.as_str()) {
            return self.g.fields.get(&(ty.clone(), f.to_string())).copied();
        }
        if at.body.is_type {
            return None;
        }
        let (_, body) = self.controller(&b.text)?;
        // A supervisor reads a subordinate's status fields, not its vars.
        body?
            .values
            .get(f)
            .copied()
            .filter(|&id| self.kinds.get(id) == Some(&Kind::StatusField))
    }

    /// `X.status == WORD` / `X.error_code == CODE`: a bare name compared
    /// with a subordinate's status or error code is one of X's. True when
    /// `other` was resolved so (and must not be looked up as a bare name).
    fn compared_with_sub(&mut self, at: &At, side: &ast::Expr, other: &ast::Expr) -> bool {
        let (ExprKind::Field(base, prop), ExprKind::Path(None, word)) = (&side.kind, &other.kind)
        else {
            return false;
        };
        let ExprKind::Path(None, x) = &base.kind else {
            return false;
        };
        if at.body.is_type {
            return false;
        }
        let Some((_, Some(body))) = self.controller(&x.text) else {
            return false;
        };
        let id = match prop.text.as_str() {
            "status" => body.statuses.get(word.text.as_str()),
            "error_code" => body.errors.get(word.text.as_str()),
            _ => return false,
        };
        // A built-in word (`DONE`, `REFUSED`) has no declaration: nothing.
        self.put(word.span, id.copied());
        true
    }
}

impl<'s> At<'s> {
    /// In `body`, outside any plan, accept condition or job list.
    fn of(body: &'s Body) -> At<'s> {
        At {
            body,
            verbs: Vec::new(),
            job_list: None,
            states: Vec::new(),
        }
    }
}
