//! Stage 1b, expansion: controller types and instances (LANGUAGE.md §8).
//!
//! `controller NAME = T(c: value) { local: global }` becomes a plain
//! controller: T's body (its job lists and shared rows already expanded),
//! each const parameter a controller constant with the instance's value,
//! and each `reads`/`writes` buffer and subordinate of T renamed to what
//! the instance binds it to, in its declaration and wherever T's rows,
//! jobs and initialisers name it. Every later stage sees ordinary
//! controllers; the controller remembers its type ([`InstanceOf`]) for the
//! code generator, the docs and the attribution of findings.

use super::{Origins, TypeOrigin};
use crate::ast::{
    ConstDef, ControllerDef, ControllerTypeDef, Entry, EntryKind, Expr, ExprKind, File,
    InstanceDef, InstanceOf, Item, Job, Name, Outer,
};
use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use std::collections::BTreeMap;

/// Replace every instance with its controller and remove the types.
pub(super) fn instantiate(files: &mut [File], diags: &mut Diagnostics, origins: &mut Origins) {
    let mut types: BTreeMap<String, ControllerTypeDef> = BTreeMap::new();
    let mut other_items: BTreeMap<String, crate::source::Span> = BTreeMap::new();
    // Types refused as duplicates: their instances are not reported again.
    let mut refused: Vec<String> = Vec::new();
    for item in files.iter().flat_map(|f| &f.items) {
        match item {
            Item::Enum(e) => other_items
                .entry(e.name.text.to_string())
                .or_insert(e.name.span),
            Item::Buffer(b) => other_items
                .entry(b.name.text.to_string())
                .or_insert(b.name.span),
            Item::Controller(c) => other_items
                .entry(c.name.text.to_string())
                .or_insert(c.name.span),
            Item::Instance(i) => other_items
                .entry(i.name.text.to_string())
                .or_insert(i.name.span),
            _ => continue,
        };
    }
    for file in files.iter_mut() {
        file.items.retain_mut(|item| {
            let Item::ControllerType(t) = item else {
                return true;
            };
            let name = &t.def.name;
            let first = types
                .get(name.text.as_str())
                .map(|f| f.def.name.span)
                .or_else(|| other_items.get(name.text.as_str()).copied());
            match first {
                Some(first) => {
                    refused.push(name.text.to_string());
                    diags.push(
                        Diagnostic::error(
                            Code::DuplicateDefinition,
                            format!("item `{}` is defined more than once", name.text),
                            name.span,
                            format!("`{}` redefined here", name.text),
                        )
                        .with_secondary(first, format!("first definition of `{}`", name.text))
                        .with_help("rename or remove one of them"),
                    )
                }
                None => {
                    let t = std::mem::replace(
                        t,
                        ControllerTypeDef {
                            def: t.def.clone(),
                            params: Vec::new(),
                        },
                    );
                    types.insert(t.def.name.text.to_string(), t);
                }
            }
            false
        });
    }
    for ty in types.values() {
        origins.types.push(TypeOrigin {
            name: ty.def.name.text.to_string(),
            span: ty.def.span,
            instances: Vec::new(),
        });
    }
    for file in files.iter_mut() {
        for item in &mut file.items {
            let Item::Instance(inst) = item else { continue };
            let Some(ty) = types.get(inst.ty.text.as_str()) else {
                if !refused.contains(&inst.ty.text.to_string()) {
                    diags.push(unknown_type(inst, &types, &other_items));
                }
                // Leave nothing behind: the name is still declared, so
                // that uses of it are not reported again.
                *item = Item::Controller(placeholder(inst));
                continue;
            };
            if let Some(o) = origins
                .types
                .iter_mut()
                .find(|o| o.name == ty.def.name.text)
            {
                o.instances.push(inst.name.text.to_string());
            }
            *item = Item::Controller(instance(inst, ty, diags));
        }
    }
}

fn unknown_type(
    inst: &InstanceDef,
    types: &BTreeMap<String, ControllerTypeDef>,
    others: &BTreeMap<String, crate::source::Span>,
) -> Diagnostic {
    let name = &inst.ty.text;
    let d = Diagnostic::error(
        Code::Instance,
        format!("no controller type named `{name}`"),
        inst.ty.span,
        "not a controller type",
    );
    if others.contains_key(name.as_str()) {
        return d.with_help(format!(
            "`{name}` is not a type: write its body as `controller type {name}(…) {{ … }}` to make instances of it"
        ));
    }
    match types.keys().map(|k| format!("`{k}`")).collect::<Vec<_>>() {
        v if v.is_empty() => d.with_help(format!(
            "declare it with `controller type {name}(…) {{ … }}`"
        )),
        v => d.with_help(format!("the controller types here are {}", v.join(", "))),
    }
}

/// An empty controller standing for an instance whose type is unknown.
fn placeholder(inst: &InstanceDef) -> ControllerDef {
    ControllerDef {
        outer: Outer::default(),
        name: inst.name.clone(),
        title: None,
        entries: Vec::new(),
        span: inst.span,
        instance: None,
    }
}

/// The controller an instance stands for.
fn instance(inst: &InstanceDef, ty: &ControllerTypeDef, diags: &mut Diagnostics) -> ControllerDef {
    let type_name = &ty.def.name.text;
    // Const parameters: each given exactly once.
    let mut args: Vec<(Name, Expr)> = Vec::with_capacity(ty.params.len());
    for (i, (n, e)) in inst.args.iter().enumerate() {
        if inst.args[..i].iter().any(|(m, _)| m.text == n.text) {
            diags.push(
                Diagnostic::error(
                    Code::WrongArguments,
                    format!("parameter `{}` is given twice", n.text),
                    n.span,
                    "given again",
                )
                .with_help("give each parameter once"),
            );
        } else if !ty.params.iter().any(|p| p.name.text == n.text) {
            diags.push(
                Diagnostic::error(
                    Code::WrongArguments,
                    format!(
                        "controller type `{type_name}` has no parameter `{}`",
                        n.text
                    ),
                    n.span,
                    "not a parameter of the type",
                )
                .with_secondary(ty.def.name.span, "the type")
                .with_help(params_help(ty)),
            );
        } else {
            args.push((n.clone(), e.clone()));
        }
    }
    let mut consts = Vec::with_capacity(ty.params.len());
    let mut ordered_args = Vec::with_capacity(ty.params.len());
    for p in &ty.params {
        match args.iter().find(|(n, _)| n.text == p.name.text) {
            Some((n, e)) => {
                ordered_args.push((n.clone(), e.clone()));
                consts.push(Entry {
                    outer: Outer {
                        docs: p.docs.clone(),
                        lints: Vec::new(),
                    },
                    kind: EntryKind::Const(ConstDef {
                        name: p.name.clone(),
                        ty: p.ty.clone(),
                        value: e.clone(),
                        span: n.span.to(e.span),
                    }),
                    span: n.span.to(e.span),
                });
            }
            None => diags.push(
                Diagnostic::error(
                    Code::WrongArguments,
                    format!(
                        "instance `{}` gives no value for parameter `{}` of `{type_name}`",
                        inst.name.text, p.name.text
                    ),
                    inst.ty.span,
                    format!("`{}` missing", p.name.text),
                )
                .with_secondary(p.name.span, "the parameter")
                .with_help(format!("write `{}({}: …)`", type_name, p.name.text)),
            ),
        }
    }
    // Bindings: every buffer and subordinate of the type, once each.
    let bindable: Vec<(&Name, &'static str)> = ty
        .def
        .entries
        .iter()
        .flat_map(|e| match &e.kind {
            EntryKind::Reads(n, _) => vec![(n, "reads buffer")],
            EntryKind::Writes(n, _) => vec![(n, "writes buffer")],
            EntryKind::Subordinates(ns) => ns.iter().map(|n| (n, "subordinate")).collect(),
            _ => Vec::new(),
        })
        .collect();
    let mut renames: BTreeMap<String, Name> = BTreeMap::new();
    for (i, (local, global)) in inst.bindings.iter().enumerate() {
        if inst.bindings[..i].iter().any(|(m, _)| m.text == local.text) {
            diags.push(
                Diagnostic::error(
                    Code::Instance,
                    format!("`{}` is bound twice", local.text),
                    local.span,
                    "bound again",
                )
                .with_help("bind each buffer and subordinate of the type once"),
            );
        } else if !bindable.iter().any(|(n, _)| n.text == local.text) {
            diags.push(
                Diagnostic::error(
                    Code::Instance,
                    format!(
                        "controller type `{type_name}` has no `reads`/`writes` buffer or subordinate named `{}`",
                        local.text
                    ),
                    local.span,
                    "nothing to bind",
                )
                .with_secondary(ty.def.name.span, "the type")
                .with_help(bindings_help(&bindable)),
            );
        } else {
            renames.insert(local.text.to_string(), global.clone());
        }
    }
    for (n, what) in &bindable {
        if !renames.contains_key(n.text.as_str()) {
            diags.push(
                Diagnostic::error(
                    Code::Instance,
                    format!(
                        "instance `{}` does not bind {what} `{}` of `{type_name}`",
                        inst.name.text, n.text
                    ),
                    inst.name.span,
                    format!("`{}` unbound", n.text),
                )
                .with_secondary(n.span, format!("the {what}"))
                .with_help(format!(
                    "name what it is in this instance: `controller {} = {type_name}(…) {{ {}: … }}`",
                    inst.name.text, n.text
                )),
            );
        }
    }
    let mut entries = consts;
    entries.extend(ty.def.entries.iter().cloned().map(|mut e| {
        rename_entry(&mut e.kind, &renames);
        e
    }));
    let outer = Outer {
        docs: if inst.outer.docs.is_empty() {
            ty.def.outer.docs.clone()
        } else {
            inst.outer.docs.clone()
        },
        lints: ty
            .def
            .outer
            .lints
            .iter()
            .chain(&inst.outer.lints)
            .cloned()
            .collect(),
    };
    ControllerDef {
        outer,
        name: inst.name.clone(),
        title: inst.title.clone().or_else(|| ty.def.title.clone()),
        entries,
        span: inst.span,
        instance: Some(Box::new(InstanceOf {
            ty: ty.def.name.clone(),
            type_span: ty.def.span,
            span: inst.span,
            args: ordered_args,
            bindings: inst.bindings.clone(),
        })),
    }
}

fn params_help(ty: &ControllerTypeDef) -> String {
    match ty.params.as_slice() {
        [] => format!("`{}` takes no parameters", ty.def.name.text),
        ps => format!(
            "its parameters are {}",
            ps.iter()
                .map(|p| format!("`{}`", p.name.text))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

fn bindings_help(bindable: &[(&Name, &str)]) -> String {
    match bindable {
        [] => "the type has no buffers or subordinates to bind".to_string(),
        b => format!(
            "it binds {}",
            b.iter()
                .map(|(n, what)| format!("{what} `{}`", n.text))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Rename bound names in one entry of the type.
fn rename_entry(kind: &mut EntryKind, renames: &BTreeMap<String, Name>) {
    let rn = |n: &mut Name| {
        if let Some(g) = renames.get(n.text.as_str()) {
            n.text = g.text.clone();
        }
    };
    match kind {
        EntryKind::Reads(n, _) | EntryKind::Writes(n, _) => rn(n),
        EntryKind::Subordinates(ns) => ns.iter_mut().for_each(rn),
        EntryKind::Var { init, .. } | EntryKind::StatusField { init, .. } => {
            if let Some(e) = init {
                rename_expr(e, renames);
            }
        }
        EntryKind::Const(c) => rename_expr(&mut c.value, renames),
        EntryKind::Command {
            accept: Some(a), ..
        } => rename_expr(&mut a.cond, renames),
        EntryKind::Plan(p) => {
            for row in &mut p.rows {
                if let Some(c) = &mut row.cond {
                    rename_expr(c, renames);
                }
                row.jobs.iter_mut().for_each(|j| rename_job(j, renames));
            }
        }
        EntryKind::EveryCycle(b) => b.jobs.iter_mut().for_each(|j| rename_job(j, renames)),
        _ => {}
    }
}

fn rename_job(job: &mut Job, renames: &BTreeMap<String, Name>) {
    let rn = |n: &mut Name| {
        if let Some(g) = renames.get(n.text.as_str()) {
            n.text = g.text.clone();
        }
    };
    match job {
        Job::Send { sub, args, .. } => {
            rn(sub);
            args.iter_mut().for_each(|(_, e)| rename_expr(e, renames));
        }
        Job::Forward { sub, .. } => rn(sub),
        Job::Assign { place, value, .. } => {
            rename_expr(place, renames);
            rename_expr(value, renames);
        }
        Job::Call(e) => rename_expr(e, renames),
        Job::Report(..) | Job::ReportCode(..) => {}
    }
}

fn rename_expr(e: &mut Expr, renames: &BTreeMap<String, Name>) {
    e.walk_mut(&mut |x| {
        if let ExprKind::Path(None, n) = &mut x.kind {
            if let Some(g) = renames.get(n.text.as_str()) {
                n.text = g.text.clone();
            }
        }
        true
    });
}
