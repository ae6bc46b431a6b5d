//! Stage 2, lowering: controller headers — each controller's shell, its
//! subordinates and Global Memory buffers, before any plan is lowered — and
//! the check that the hierarchy has no cycle.

use super::*;

/// First pass over controllers: names, hierarchy and Global Memory, so that
/// plans can refer to any controller's commands and statuses.
pub(super) fn lower_controller_headers<'a>(
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
            written_times: Vec::new(),
            instance_of: c.instance.as_ref().map(|i| crate::ir::InstanceOf {
                ty: i.ty.text.to_string(),
                type_span: i.type_span,
                span: i.span,
                args: i
                    .args
                    .iter()
                    .map(|(n, e)| {
                        let text = &sources.get(e.span.file).text[e.span.range()];
                        (n.text.to_string(), text.to_string())
                    })
                    .collect(),
                bindings: i
                    .bindings
                    .iter()
                    .map(|(l, g)| (l.text.to_string(), g.text.to_string()))
                    .collect(),
            }),
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
                                    )
                                    .suggest(
                                        &n.text,
                                        g.names.iter().filter_map(|(k, (r, _))| {
                                            matches!(r, ItemRef::Controller(_)).then_some(*k)
                                        }),
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

pub(super) fn sub_span(c: &ast::ControllerDef, name: &str) -> Option<Span> {
    c.entries.iter().find_map(|e| match &e.kind {
        ast::EntryKind::Subordinates(ns) => ns.iter().find(|n| n.text == name).map(|n| n.span),
        _ => None,
    })
}

/// With one supervisor each, a cycle is a ring of controllers each above the
/// next. Kosaraju rather than Tarjan: petgraph's Tarjan recurses per node,
/// and a long chain of controllers must not exhaust the stack.
pub(super) fn check_hierarchy_cycles(ir: &Ir, diags: &mut Diagnostics) {
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
