//! The page of a controller type (LANGUAGE.md §8): what the type is, its
//! parameters, and its instances, each linked to its own page (where its
//! plans, graphs and findings are, as for any controller).

use super::html::{docs, esc, page};
use super::{ctrl_page, root_of, SetDoc, Site};
use rcs_dsl::ir::{Controller, Ir};
use std::fmt::Write;

/// The page of the type named `ty`, relative to its set's folder.
pub(super) fn type_page_name(ty: &str) -> String {
    format!("type-{ty}.html")
}

/// Every controller type of the set with its instances, in order of the
/// first instance.
pub(super) fn types(ir: &Ir) -> Vec<(&str, Vec<&Controller>)> {
    let mut out: Vec<(&str, Vec<&Controller>)> = Vec::new();
    for c in &ir.controllers {
        let Some(inst) = &c.instance_of else { continue };
        match out.iter_mut().find(|(t, _)| *t == inst.ty) {
            Some((_, list)) => list.push(c),
            None => out.push((&inst.ty, vec![c])),
        }
    }
    out
}

/// The page of one type.
pub(super) fn type_page(site: &Site, set: &SetDoc, ty: &str, instances: &[&Controller]) -> String {
    let ir = set.ir;
    let root = root_of(site);
    let mut body = format!(
        "<nav><a href=\"{root}index.html\">{}</a> › controller type {}</nav>\n",
        esc(&ir.system),
        esc(ty)
    );
    let _ = writeln!(body, "<h1>Controller type <code>{}</code></h1>", esc(ty));
    if let Some(first) = instances.first() {
        body.push_str(&docs(&first.docs));
        let _ = writeln!(
            body,
            "<p>Written once; each instance below has its own command and status buffers, variables, hooks and place in the hierarchy and the schedule. Its plans are the same in every instance: see them on any instance's page.</p>"
        );
    }
    body.push_str("<table class=\"instances\">\n<tr><th>Instance</th><th>Parameters</th><th>Bindings</th><th>Supervisor</th></tr>\n");
    for c in instances {
        let Some(inst) = &c.instance_of else { continue };
        let args: Vec<String> = inst
            .args
            .iter()
            .map(|(n, v)| format!("{}: {}", esc(n), esc(v)))
            .collect();
        let binds: Vec<String> = inst
            .bindings
            .iter()
            .map(|(l, g)| format!("<code>{}</code> → <code>{}</code>", esc(l), esc(g)))
            .collect();
        let sup = c
            .supervisor
            .map(|s| {
                let o = ir.controller(s);
                format!("<a href=\"{}\">{}</a>", ctrl_page(o), esc(&o.name))
            })
            .unwrap_or_else(|| "the operator".into());
        let _ = writeln!(
            body,
            "<tr><td><a href=\"{}\">{}</a></td><td>{}</td><td>{}</td><td>{sup}</td></tr>",
            ctrl_page(c),
            esc(&c.name),
            args.join(", "),
            binds.join(", ")
        );
    }
    body.push_str("</table>\n");
    page(
        &format!("{} — controller type {ty}", ir.system),
        root,
        &body,
    )
}
