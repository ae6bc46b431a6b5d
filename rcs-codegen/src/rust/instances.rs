//! Controller types in the generated Rust (LANGUAGE.md §8): the instances
//! of one type share one module — one `Hooks` trait, one `Controller` —
//! and each instance is a value of it, told apart by an [`Instance`]
//! record of its names in Global Memory and its parameters.
//!
//! `expand` gave every instance its own controller in the IR, with the
//! type's const parameters folded into its expressions. Here the
//! instances of a type are compared, node by node: they may differ only
//! where a parameter's value was folded in (a literal), in the names of
//! their buffers and subordinates, and in which controllers those are.
//! Each literal that differs becomes a *slot*, a field of the type's
//! `Params` that each instance fills in. Instances that differ in any
//! other way (a parameter used as an array length gives them different
//! types; subordinates that are not instances of one type have different
//! commands) keep a module each, as a controller written out does.
//!
//! [`Instance`]: the generated `Instance` struct of a type module.

use super::names::{Names, SlotNames};
use proc_macro2::{Ident, TokenStream};
use quote::quote;
use rcs_dsl::ir::*;
use std::collections::BTreeMap;

/// The instances of one type that share a module.
pub(crate) struct Group {
    /// The type's name, as written.
    pub ty: String,
    /// The controllers, in IR order; the first is the template the module
    /// is generated from.
    pub members: Vec<usize>,
    /// The literals that differ between members: the template's
    /// expression (by address) → slot index.
    pub slot_of: BTreeMap<usize, usize>,
    pub slots: Vec<Slot>,
}

/// One field of the type's `Params`.
pub(crate) struct Slot {
    pub ty: Type,
    /// Its value in each member, in member order.
    pub values: Vec<ExprKind>,
}

/// The groups of a plan set, each with two or more members whose code can
/// be shared; `group_of[c]` is the group of controller `c`.
pub(crate) struct Sharing {
    pub groups: Vec<Group>,
    pub group_of: Vec<Option<usize>>,
}

impl Sharing {
    pub fn of(ir: &Ir) -> Sharing {
        let mut by_type: Vec<(String, Vec<usize>)> = Vec::new();
        for (ci, c) in ir.controllers.iter().enumerate() {
            let Some(inst) = &c.instance_of else { continue };
            match by_type.iter_mut().find(|(t, _)| *t == inst.ty) {
                Some((_, m)) => m.push(ci),
                None => by_type.push((inst.ty.clone(), vec![ci])),
            }
        }
        let mut groups: Vec<Group> = Vec::new();
        // A group's subordinates must be shared alike, so groups are
        // settled in rounds until none drops out.
        let mut candidates: Vec<(String, Vec<usize>)> =
            by_type.into_iter().filter(|(_, m)| m.len() >= 2).collect();
        loop {
            let mut group_of = vec![None; ir.controllers.len()];
            for (g, (_, members)) in candidates.iter().enumerate() {
                for &m in members {
                    group_of[m] = Some(g);
                }
            }
            let before = candidates.len();
            groups.clear();
            let mut kept = Vec::new();
            for (ty, members) in &candidates {
                if let Some(g) = compare(ir, ty, members, &group_of) {
                    groups.push(g);
                    kept.push((ty.clone(), members.clone()));
                }
            }
            candidates = kept;
            if candidates.len() == before {
                break;
            }
        }
        let mut group_of = vec![None; ir.controllers.len()];
        for (g, group) in groups.iter().enumerate() {
            for &m in &group.members {
                group_of[m] = Some(g);
            }
        }
        Sharing { groups, group_of }
    }
}

/// The group of `members` if they can share one module.
fn compare(ir: &Ir, ty: &str, members: &[usize], group_of: &[Option<usize>]) -> Option<Group> {
    let template = &ir.controllers[members[0]];
    let mut slots = Slots::default();
    for (k, &m) in members.iter().enumerate().skip(1) {
        let other = &ir.controllers[m];
        let mut cmp = Cmp {
            ir,
            a: template,
            b: other,
            member: k,
            members: members.len(),
            group_of,
            slots: &mut slots,
        };
        if !cmp.controller() {
            return None;
        }
    }
    // Slots whose values agree in every member are no slots (a literal
    // that only looked different to one comparison cannot happen, but a
    // slot must differ somewhere to be worth a field).
    let mut slot_of = BTreeMap::new();
    let mut out: Vec<Slot> = Vec::new();
    let Slots { mut by_addr, order } = slots;
    for addr in order {
        let Some((ty, values)) = by_addr.remove(&addr) else {
            continue;
        };
        let values: Vec<ExprKind> = values
            .into_iter()
            .map(|v| v.expect("every member compared"))
            .collect();
        let i = match out.iter().position(|s| s.ty == ty && s.values == values) {
            Some(i) => i,
            None => {
                out.push(Slot { ty, values });
                out.len() - 1
            }
        };
        slot_of.insert(addr, i);
    }
    let mut group = Group {
        ty: ty.to_string(),
        members: members.to_vec(),
        slot_of,
        slots: out,
    };
    prune(&mut group);
    Some(group)
}

#[derive(Default)]
struct Slots {
    /// Template expression address → (type, value per member).
    by_addr: BTreeMap<usize, (Type, Vec<Option<ExprKind>>)>,
    /// The addresses in the order the comparison first met them: the
    /// template's structure order, so that slots are numbered the same on
    /// every run (addresses are not).
    order: Vec<usize>,
}

struct Cmp<'a> {
    ir: &'a Ir,
    a: &'a Controller,
    b: &'a Controller,
    member: usize,
    members: usize,
    group_of: &'a [Option<usize>],
    slots: &'a mut Slots,
}

impl Cmp<'_> {
    fn controller(&mut self) -> bool {
        let (a, b) = (self.a, self.b);
        if a.subordinates.len() != b.subordinates.len()
            || a.reads.len() != b.reads.len()
            || a.writes.len() != b.writes.len()
        {
            return false;
        }
        // Subordinates at one position: the same group (so one command type).
        for (x, y) in a.subordinates.iter().zip(&b.subordinates) {
            match (self.group_of[x.index()], self.group_of[y.index()]) {
                (Some(g), Some(h)) if g == h => {}
                _ => return false,
            }
        }
        let buffers_alike = |x: &[BufferId], y: &[BufferId]| {
            x.iter()
                .zip(y)
                .all(|(p, q)| self.ir.buffers[p.index()].ty == self.ir.buffers[q.index()].ty)
        };
        if !buffers_alike(&a.reads, &b.reads) || !buffers_alike(&a.writes, &b.writes) {
            return false;
        }
        let same_names = |x: &[String], y: &[String]| x == y;
        let cmd_names = |c: &Controller| {
            c.commands
                .iter()
                .map(|k| k.name.clone())
                .collect::<Vec<_>>()
        };
        if !same_names(&cmd_names(a), &cmd_names(b))
            || a.statuses.len() != b.statuses.len()
            || a.errors.len() != b.errors.len()
            || a.vars.len() != b.vars.len()
            || a.hooks.len() != b.hooks.len()
            || a.plans.len() != b.plans.len()
            || a.pre.is_some() != b.pre.is_some()
            || a.post.is_some() != b.post.is_some()
        {
            return false;
        }
        for (x, y) in a.commands.iter().zip(&b.commands) {
            if x.plan != y.plan || !self.params(&x.params, &y.params) {
                return false;
            }
        }
        for (x, y) in a.vars.iter().zip(&b.vars) {
            if x.name != y.name || x.status_field != y.status_field || !self.ty(&x.ty, &y.ty) {
                return false;
            }
            match (&x.init, &y.init) {
                (Some(p), Some(q)) if self.expr(p, q) => {}
                (None, None) => {}
                _ => return false,
            }
        }
        for (x, y) in a.hooks.iter().zip(&b.hooks) {
            if x.name != y.name || !self.ty(&x.ret, &y.ret) || !self.params(&x.params, &y.params) {
                return false;
            }
        }
        for (x, y) in a.pre.iter().chain(&a.post).zip(b.pre.iter().chain(&b.post)) {
            if !self.jobs(&x.jobs, &y.jobs) {
                return false;
            }
        }
        for (x, y) in a.plans.iter().zip(&b.plans) {
            if x.states.len() != y.states.len()
                || x.rows.len() != y.rows.len()
                || x.verbs != y.verbs
            {
                return false;
            }
            for (r, s) in x.rows.iter().zip(&y.rows) {
                if r.from != s.from || r.to != s.to || r.is_entry != s.is_entry {
                    return false;
                }
                let conds = match (&r.cond, &s.cond) {
                    (Condition::When(p), Condition::When(q)) => self.expr(p, q),
                    (Condition::Otherwise, Condition::Otherwise) => true,
                    _ => false,
                };
                if !conds || !self.jobs(&r.jobs, &s.jobs) {
                    return false;
                }
            }
        }
        true
    }

    fn params(&self, x: &[Param], y: &[Param]) -> bool {
        x.len() == y.len() && x.iter().zip(y).all(|(p, q)| self.ty(&p.ty, &q.ty))
    }

    /// Types alike, a subordinate's status type by position.
    fn ty(&self, x: &Type, y: &Type) -> bool {
        match (x, y) {
            (Type::Status(p), Type::Status(q)) => self.sub_pos(*p) == self.sub_pos_b(*q),
            (Type::Array(p, n), Type::Array(q, m)) => n == m && self.ty(p, q),
            _ => x == y,
        }
    }

    fn sub_pos(&self, c: CtrlId) -> Option<usize> {
        if self
            .ir
            .controllers
            .get(c.index())
            .map(|x| std::ptr::eq(x, self.a))
            == Some(true)
        {
            return Some(usize::MAX); // the controller itself
        }
        self.a.subordinate_index(c)
    }

    fn sub_pos_b(&self, c: CtrlId) -> Option<usize> {
        if self
            .ir
            .controllers
            .get(c.index())
            .map(|x| std::ptr::eq(x, self.b))
            == Some(true)
        {
            return Some(usize::MAX);
        }
        self.b.subordinate_index(c)
    }

    fn buffer_pos(c: &Controller, b: BufferId) -> Option<(bool, usize)> {
        if let Some(i) = c.reads.iter().position(|x| *x == b) {
            return Some((false, i));
        }
        c.writes.iter().position(|x| *x == b).map(|i| (true, i))
    }

    fn jobs(&mut self, x: &[Job], y: &[Job]) -> bool {
        x.len() == y.len() && x.iter().zip(y).all(|(p, q)| self.job(p, q))
    }

    fn job(&mut self, x: &Job, y: &Job) -> bool {
        match (x, y) {
            (
                Job::Assign {
                    place: p,
                    op: o,
                    value: v,
                    ..
                },
                Job::Assign {
                    place: q,
                    op: r,
                    value: w,
                    ..
                },
            ) => {
                let roots = match (p.root, q.root) {
                    (PlaceRoot::Var(i), PlaceRoot::Var(j)) => i == j,
                    (PlaceRoot::Buffer(i), PlaceRoot::Buffer(j)) => {
                        Self::buffer_pos(self.a, i).is_some()
                            && Self::buffer_pos(self.a, i) == Self::buffer_pos(self.b, j)
                    }
                    _ => false,
                };
                roots
                    && o == r
                    && p.path == q.path
                    && self.ty(&p.ty, &q.ty)
                    && p.indices.len() == q.indices.len()
                    && p.indices
                        .iter()
                        .zip(&q.indices)
                        .all(|(i, j)| self.expr(i, j))
                    && self.expr(v, w)
            }
            (
                Job::Send {
                    sub: s,
                    command: c,
                    args: a,
                    ..
                },
                Job::Send {
                    sub: t,
                    command: d,
                    args: b,
                    ..
                },
            ) => {
                self.sub_pos(*s).is_some()
                    && self.sub_pos(*s) == self.sub_pos_b(*t)
                    && c == d
                    && a.len() == b.len()
                    && a.iter().zip(b).all(|(p, q)| self.expr(p, q))
            }
            (
                Job::Forward {
                    sub: s,
                    commands: c,
                    ..
                },
                Job::Forward {
                    sub: t,
                    commands: d,
                    ..
                },
            ) => self.sub_pos(*s).is_some() && self.sub_pos(*s) == self.sub_pos_b(*t) && c == d,
            (
                Job::Report {
                    status: s,
                    error: e,
                    error_of: v,
                    ..
                },
                Job::Report {
                    status: t,
                    error: f,
                    error_of: w,
                    ..
                },
            ) => s == t && e == f && v == w,
            (Job::Call(p), Job::Call(q)) => self.expr(p, q),
            _ => false,
        }
    }

    fn expr(&mut self, x: &Expr, y: &Expr) -> bool {
        if !self.ty(&x.ty, &y.ty) {
            return false;
        }
        use ExprKind as K;
        match (&x.kind, &y.kind) {
            (K::Int(_), K::Int(_))
            | (K::Float(_), K::Float(_))
            | (K::Bool(_), K::Bool(_))
            | (K::Variant(..), K::Variant(..)) => {
                self.literal(x, y);
                true
            }
            (K::Status(s), K::Status(t)) => s == t,
            (K::NewCommand, K::NewCommand)
            | (K::StateCycles, K::StateCycles)
            | (K::PlanCycles, K::PlanCycles) => true,
            (K::CmdParam(c, p), K::CmdParam(d, q)) => c == d && p == q,
            (K::CurrentParam(a), K::CurrentParam(b)) => a == b,
            (K::Var(i), K::Var(j)) => i == j,
            (K::Buffer(i), K::Buffer(j)) | (K::BufferStale(i), K::BufferStale(j)) => {
                Self::buffer_pos(self.a, *i).is_some()
                    && Self::buffer_pos(self.a, *i) == Self::buffer_pos(self.b, *j)
            }
            (K::Field(p, i), K::Field(q, j)) | (K::Index(p, i), K::Index(q, j)) => {
                i == j && self.expr(p, q)
            }
            (K::Call(h, a), K::Call(k, b)) => {
                h == k && a.len() == b.len() && a.iter().zip(b).all(|(p, q)| self.expr(p, q))
            }
            (K::Sub(c, p), K::Sub(d, q)) => {
                p == q && self.sub_pos(*c).is_some() && self.sub_pos(*c) == self.sub_pos_b(*d)
            }
            (K::SubField(c, v), K::SubField(d, w)) => {
                v == w && self.sub_pos(*c).is_some() && self.sub_pos(*c) == self.sub_pos_b(*d)
            }
            (K::Unary(o, p), K::Unary(r, q)) => o == r && self.expr(p, q),
            (K::Binary(o, p), K::Binary(r, q)) => {
                o == r && self.expr(&p[0], &q[0]) && self.expr(&p[1], &q[1])
            }
            // The generator folds a cast of a literal (`station as u16`), so
            // the cast is the slot, with the folded values.
            (K::Cast(_), K::Cast(_)) if folded(x).is_some() && folded(y).is_some() => {
                self.record(x, folded(x), folded(y));
                true
            }
            (K::Cast(p), K::Cast(q)) => self.expr(p, q),
            (K::Builtin(f, a), K::Builtin(g, b)) => {
                f == g && a.len() == b.len() && a.iter().zip(b).all(|(p, q)| self.expr(p, q))
            }
            (K::IndexBy(p, i), K::IndexBy(q, j)) => self.expr(p, q) && self.expr(i, j),
            _ => false,
        }
    }

    /// Record a literal of the template (`x`) and this member's (`y`).
    fn literal(&mut self, x: &Expr, y: &Expr) {
        self.record(x, Some(x.kind.clone()), Some(y.kind.clone()));
    }

    fn record(&mut self, x: &Expr, xv: Option<ExprKind>, yv: Option<ExprKind>) {
        let addr = x as *const Expr as usize;
        let members = self.members;
        if !self.slots.by_addr.contains_key(&addr) {
            self.slots.order.push(addr);
        }
        let entry = self
            .slots
            .by_addr
            .entry(addr)
            .or_insert_with(|| (x.ty.clone(), vec![None; members]));
        entry.1[0] = xv;
        entry.1[self.member] = yv;
    }
}

/// A cast of a literal, folded as the generator and the interpreter do.
fn folded(e: &Expr) -> Option<ExprKind> {
    use rcs_dsl::interp::{float_to_int, wrap};
    let ExprKind::Cast(inner) = &e.kind else {
        return None;
    };
    Some(match (&inner.kind, &e.ty) {
        (ExprKind::Int(v), Type::Int(it)) => ExprKind::Int(wrap(*v, *it)),
        (ExprKind::Int(v), Type::Float(_)) => ExprKind::Float(*v as f64),
        (ExprKind::Float(v), Type::Float(_)) => ExprKind::Float(*v),
        (ExprKind::Float(v), Type::Int(it)) => ExprKind::Int(float_to_int(*v, *it)),
        _ => return None,
    })
}

/// Drop the literals that are the same in every member: they stay
/// literals in the shared code.
fn prune(group: &mut Group) {
    let keep: Vec<bool> = group
        .slots
        .iter()
        .map(|s| s.values.iter().any(|v| *v != s.values[0]))
        .collect();
    let mut new_index = Vec::with_capacity(keep.len());
    let mut n = 0;
    for k in &keep {
        new_index.push(n);
        if *k {
            n += 1;
        }
    }
    group.slot_of.retain(|_, i| keep[*i]);
    for i in group.slot_of.values_mut() {
        *i = new_index[*i];
    }
    let mut k = keep.iter();
    group
        .slots
        .retain(|_| *k.next().expect("one flag per slot"));
}

/// The shared modules' names (`station` for type `Station`), distinct
/// from every controller's module.
pub(crate) fn type_modules(names: &Names, sharing: &Sharing) -> Vec<Ident> {
    let taken: Vec<String> = names
        .ctrls
        .iter()
        .map(|c| c.module.to_string().trim_start_matches("r#").to_string())
        .chain(["types", "rt", "new_driver"].map(String::from))
        .collect();
    let taken: Vec<&str> = taken.iter().map(String::as_str).collect();
    crate::ident::distinct(
        sharing.groups.iter().map(|g| g.ty.as_str()),
        crate::ident::snake,
        &taken,
    )
    .iter()
    .map(|s| crate::ident::ident(s))
    .collect()
}

/// The names a type's module is generated with, from its first member
/// `ci`: fields named after the type's own names for its buffers and
/// subordinates (not the first instance's bindings), the type's module for
/// itself and its subordinates' types' modules, and the literal slots.
pub(crate) fn type_names(
    ir: &Ir,
    names: &Names,
    sharing: &Sharing,
    modules: &[Ident],
    ci: usize,
    slots: Option<TokenStream>,
) -> Names {
    let mut out = names.clone();
    let c = &ir.controllers[ci];
    let g = sharing.group_of[ci].expect("a member");
    let local = |global: &str| -> String {
        c.instance_of
            .as_ref()
            .and_then(|i| i.bindings.iter().find(|(_, gl)| gl == global))
            .map_or(global.to_string(), |(l, _)| l.clone())
    };
    let own: Vec<BufferId> = c.reads.iter().chain(&c.writes).copied().collect();
    let buffer_locals: Vec<String> = own
        .iter()
        .map(|b| local(&ir.buffers[b.index()].name))
        .collect();
    let fields = crate::ident::distinct(
        buffer_locals.iter().map(String::as_str),
        crate::ident::snake,
        &[],
    );
    for (b, f) in own.iter().zip(fields) {
        out.ctrls[ci].buffers[b.index()] = Some(crate::ident::ident(&f));
    }
    let sub_locals: Vec<String> = c
        .subordinates
        .iter()
        .map(|s| local(&ir.controllers[s.index()].name))
        .collect();
    out.ctrls[ci].subs = crate::ident::distinct(
        sub_locals.iter().map(String::as_str),
        crate::ident::snake,
        &[],
    )
    .iter()
    .map(|s| crate::ident::ident(s))
    .collect();
    if let Some(prefix) = slots {
        out.ctrls[ci].module = modules[g].clone();
        for s in &c.subordinates {
            if let Some(h) = sharing.group_of[s.index()] {
                out.ctrls[s.index()].module = modules[h].clone();
            }
        }
        out.slots = Some(SlotNames {
            slot_of: sharing.groups[g].slot_of.clone(),
            prefix,
        });
    }
    out
}

/// The module of instance `ci`: the type's module re-exported, its name,
/// its `INSTANCE`, `new`, and (for tests) its driver.
pub(crate) fn instance_module(
    ir: &Ir,
    names: &Names,
    sharing: &Sharing,
    modules: &[Ident],
    ci: usize,
    driver: bool,
) -> TokenStream {
    let c = &ir.controllers[ci];
    let g = sharing.group_of[ci].expect("a member");
    let group = &sharing.groups[g];
    let member = group
        .members
        .iter()
        .position(|m| *m == ci)
        .expect("a member");
    let ty_module = &modules[g];
    let module = &names.ctrls[ci].module;
    let name = c.name.as_str();
    let reads = c.reads.iter().map(|b| ir.buffers[b.index()].name.as_str());
    let writes = c.writes.iter().map(|b| ir.buffers[b.index()].name.as_str());
    let subs = c
        .subordinates
        .iter()
        .map(|s| ir.controllers[s.index()].name.as_str());
    let plain = Names {
        slots: None,
        ..names.clone()
    };
    let gen = super::expr::Gen::new(ir, &plain, ci);
    let fields: Vec<Ident> = (0..group.slots.len()).map(SlotNames::field).collect();
    let values = group.slots.iter().map(|s| {
        let e = Expr {
            kind: s.values[member].clone(),
            ty: s.ty.clone(),
            span: c.span,
        };
        gen.expr(&e).ts
    });
    let docs = if c.docs.is_empty() {
        let d = format!(" `{name}`: an instance of controller type `{}`.", group.ty);
        quote!(#[doc = #d])
    } else {
        super::controller::docs(&c.docs)
    };
    let new_doc = format!(
        " Connect `{name}` to Global Memory (its type's `Controller::new` with [`INSTANCE`])."
    );
    let driver = if driver {
        let local = type_names(ir, names, sharing, modules, ci, None);
        super::driver::driver_parts(ir, &local, ci, super::driver::DriverPart::Instance)
    } else {
        quote!()
    };
    quote! {
        #docs
        pub mod #module {
            use ::rcs_runtime as rt;
            pub use super::#ty_module::*;

            /// The controller's name in Global Memory and in traces.
            pub const NAME: &str = #name;

            /// This instance's names in Global Memory and its parameters.
            pub const INSTANCE: Instance = Instance {
                name: NAME,
                reads: [#(#reads),*],
                writes: [#(#writes),*],
                subs: [#(#subs),*],
                params: Params { #(#fields: #values),* },
            };

            #[doc = #new_doc]
            pub fn new<H: Hooks>(gm: &rt::GlobalMemory, hooks: H) -> Result<Controller<H>, rt::SetupError> {
                Controller::new(gm, INSTANCE, hooks)
            }

            #driver
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Sharing;

    fn sharing(text: &str) -> (rcs_dsl::ir::Ir, Sharing) {
        let set = rcs_dsl::PlanSet::from_texts("t", [("t.rcs", text)], None);
        let checked = rcs_dsl::check(&set, &rcs_dsl::Options::default());
        let ir = checked
            .ir
            .unwrap_or_else(|| panic!("{:?}", checked.diagnostics));
        let s = Sharing::of(&ir);
        (ir, s)
    }

    const MODULE: &str = "buffer Io { on: bool }
controller type M(k: u8, n: u8) {
    reads io: Io
    command GO
    var xs: [u8; n]
    var last: u8 = k
    plan GO {
        E0: *0 when new_command -> S1 { last = k + 1 }
        E1: S1 when io.on && last > k -> Done { xs[0] = k }
    }
}
";

    #[test]
    fn instances_differing_in_literals_share_with_one_slot_per_value_list() {
        let (_, s) = sharing(&format!(
            "{MODULE}controller A = M(k: 1, n: 2) {{ io: a }}\ncontroller B = M(k: 2, n: 2) {{ io: b }}\ncontroller C = M(k: 1, n: 2) {{ io: c }}\n"
        ));
        assert_eq!(s.groups.len(), 1);
        let g = &s.groups[0];
        assert_eq!(g.members, [0, 1, 2]);
        // `k` (1, 2, 1) is one field, read at each of its four uses; the
        // `1` of `k + 1` and the array length `n` are the same everywhere
        // and stay literals.
        assert_eq!(g.slots.len(), 1);
        assert_eq!(g.slots[0].values, [1, 2, 1].map(rcs_dsl::ir::ExprKind::Int));
        assert_eq!(g.slot_of.len(), 4, "every use of `k` is a slot");
    }

    #[test]
    fn slots_are_numbered_in_the_order_the_plans_use_them() {
        let text = "controller type T(a: u8, b: u16, c: u32) {
    command GO
    var x: u32 = c
    var y: u16 = 0
    var z: u8 = 0
    plan GO {
        E0: *0 when new_command -> S1 { y = b }
        E1: S1 when true -> Done { z = a }
    }
}
controller P = T(a: 1, b: 2, c: 3)
controller Q = T(a: 4, b: 5, c: 6)
";
        let (_, s) = sharing(text);
        let kinds: Vec<String> = s.groups[0]
            .slots
            .iter()
            .map(|slot| format!("{:?}", slot.values))
            .collect();
        // vars first (c), then the plan's rows in order (b, then a).
        assert_eq!(
            kinds,
            ["[Int(3), Int(6)]", "[Int(2), Int(5)]", "[Int(1), Int(4)]"]
        );
    }

    #[test]
    fn a_parameter_used_as_an_array_length_keeps_a_module_per_instance() {
        let (_, s) = sharing(&format!(
            "{MODULE}controller A = M(k: 1, n: 2) {{ io: a }}\ncontroller B = M(k: 1, n: 3) {{ io: b }}\n"
        ));
        assert!(s.groups.is_empty());
        assert!(s.group_of.iter().all(Option::is_none));
    }

    #[test]
    fn supervisors_over_different_types_keep_a_module_each() {
        let text = "controller type Leaf() {
    command GO
    plan GO { *0 when new_command -> Done }
}
controller type Other() {
    command GO
    plan GO { *0 when new_command -> Done }
}
controller type Sup() {
    subordinates X
    command RUN
    plan RUN {
        E0: *0 when new_command -> S1 { X <- GO }
        E1: S1 when X.done -> Done
    }
}
controller L1 = Leaf()
controller L2 = Leaf()
controller O1 = Other()
controller S1 = Sup() { X: L1 }
controller S2 = Sup() { X: O1 }
controller S3 = Sup() { X: L2 }
";
        let (ir, s) = sharing(text);
        let name = |c: usize| ir.controllers[c].name.as_str();
        let groups: Vec<Vec<&str>> = s
            .groups
            .iter()
            .map(|g| g.members.iter().map(|m| name(*m)).collect())
            .collect();
        // `Other` has one instance; `Sup`'s instances command different
        // types, so they do not share.
        assert_eq!(groups, [vec!["L1", "L2"]]);
    }
}
