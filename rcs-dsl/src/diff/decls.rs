//! The declarations of a plan set as one-line signatures, compared by name:
//! what [`super::ItemChange`] lists beside the plans.

use super::ItemChange;
use crate::ir::{Controller, Ir, Param, StatusId};
use crate::pretty::Printer;
use crate::type_name;

type Items = Vec<(String, String)>;

/// `kind` items of both sides by name: removed or changed in the old
/// order, then added in the new order.
fn compare(kind: &'static str, old: Items, new: Items, out: &mut Vec<ItemChange>) {
    for (name, sig) in &old {
        match new.iter().find(|(n, _)| n == name) {
            Some((_, n)) if n == sig => {}
            found => out.push(ItemChange {
                kind,
                name: name.clone(),
                old: Some(sig.clone()),
                new: found.map(|(_, n)| n.clone()),
            }),
        }
    }
    for (name, sig) in new {
        if !old.iter().any(|(n, _)| *n == name) {
            out.push(ItemChange {
                kind,
                name,
                old: None,
                new: Some(sig),
            });
        }
    }
}

fn params(ir: &Ir, ps: &[Param]) -> String {
    let ps: Vec<String> = ps
        .iter()
        .map(|p| format!("{}: {}", p.name, type_name(ir, &p.ty)))
        .collect();
    ps.join(", ")
}

/// Enums, buffer types, buffers and executives.
pub(super) fn system_items(old: &Ir, new: &Ir) -> Vec<ItemChange> {
    let mut out = Vec::new();
    let enums = |ir: &Ir| -> Items {
        ir.enums
            .iter()
            .map(|e| {
                let vs: Vec<&str> = e.variants.iter().map(|v| v.name.as_str()).collect();
                (
                    e.name.clone(),
                    format!("enum {} {{ {} }}", e.name, vs.join(", ")),
                )
            })
            .collect()
    };
    compare("enum", enums(old), enums(new), &mut out);
    let types = |ir: &Ir| -> Items {
        ir.buffer_types
            .iter()
            .map(|b| {
                let fs: Vec<String> = b
                    .fields
                    .iter()
                    .map(|f| format!("{}: {}", f.name, type_name(ir, &f.ty)))
                    .collect();
                (
                    b.name.clone(),
                    format!("buffer {} {{ {} }}", b.name, fs.join(", ")),
                )
            })
            .collect()
    };
    compare("buffer type", types(old), types(new), &mut out);
    let buffers = |ir: &Ir| -> Items {
        ir.buffers
            .iter()
            .map(|b| {
                let writer = b
                    .writer
                    .map_or("external".to_string(), |w| ir.controller(w).name.clone());
                let ty = &ir.buffer_types[b.ty.index()].name;
                (
                    b.name.clone(),
                    format!("{}: {ty}, written by {writer}", b.name),
                )
            })
            .collect()
    };
    compare("buffer", buffers(old), buffers(new), &mut out);
    let cpus = |ir: &Ir| -> Items {
        ir.schedule
            .iter()
            .map(|c| {
                let order: Vec<&str> = c
                    .order
                    .iter()
                    .map(|id| ir.controller(*id).name.as_str())
                    .collect();
                let sig = format!(
                    "cpu {} every {} ns: {}",
                    c.name,
                    c.period_ns,
                    order.join(", ")
                );
                (c.name.clone(), sig)
            })
            .collect()
    };
    compare("cpu", cpus(old), cpus(new), &mut out);
    out
}

/// A controller's declarations, compared with its namesake's.
pub(super) fn controller_items(
    old_ir: &Ir,
    old: &Controller,
    new_ir: &Ir,
    new: &Controller,
) -> Vec<ItemChange> {
    let mut out = Vec::new();
    type Of = fn(&Ir, &Controller) -> Items;
    let kinds: [(&'static str, Of); 9] = [
        ("command", |ir, c| {
            c.commands
                .iter()
                .map(|x| {
                    let mut sig = format!("command {}({})", x.name, params(ir, &x.params));
                    if let Some(a) = &x.accept {
                        let p = crate::pretty::Printer::new(ir, c, None);
                        sig.push_str(&format!(" accept when {}", p.expr(&a.cond)));
                    }
                    (x.name.clone(), sig)
                })
                .collect()
        }),
        ("status", |_, c| {
            c.statuses
                .iter()
                .skip(StatusId::BUILTIN.len())
                .map(|s| (s.name.clone(), format!("status {}", s.name)))
                .collect()
        }),
        ("error", |_, c| {
            c.errors
                .iter()
                .map(|e| (e.name.clone(), format!("error {}", e.name)))
                .collect()
        }),
        ("var", |ir, c| {
            let p = Printer::new(ir, c, None);
            c.vars
                .iter()
                .map(|v| {
                    let mut sig = format!("var {}: {}", v.name, type_name(ir, &v.ty));
                    if let Some(init) = &v.init {
                        sig.push_str(&format!(" = {}", p.expr(init)));
                    }
                    (v.name.clone(), sig)
                })
                .collect()
        }),
        ("hook", |ir, c| {
            c.hooks
                .iter()
                .map(|h| {
                    let mut sig = format!("hook {}({})", h.name, params(ir, &h.params));
                    if h.ret != crate::ir::Type::Unit {
                        sig.push_str(&format!(" -> {}", type_name(ir, &h.ret)));
                    }
                    (h.name.clone(), sig)
                })
                .collect()
        }),
        ("reads", |ir, c| buffer_list(ir, &c.reads, "reads")),
        ("writes", |ir, c| buffer_list(ir, &c.writes, "writes")),
        ("subordinate", |ir, c| {
            c.subordinates
                .iter()
                .map(|s| {
                    let name = ir.controller(*s).name.clone();
                    (name.clone(), format!("subordinate {name}"))
                })
                .collect()
        }),
        ("level", |_, c| {
            c.level
                .map(|l| ("level".to_string(), format!("level {l}")))
                .into_iter()
                .collect()
        }),
    ];
    for (kind, of) in kinds {
        compare(kind, of(old_ir, old), of(new_ir, new), &mut out);
    }
    out
}

fn buffer_list(ir: &Ir, ids: &[crate::ir::BufferId], verb: &str) -> Items {
    ids.iter()
        .map(|b| {
            let buf = &ir.buffers[b.index()];
            let ty = &ir.buffer_types[buf.ty.index()].name;
            (buf.name.clone(), format!("{verb} {}: {ty}", buf.name))
        })
        .collect()
}
