//! Stage 2, lowering: enums and buffer types, and the resolution of a
//! written type (`u8`, `[f64; N]`, a buffer or enum name) to an IR type.

use super::*;

pub(super) fn lower_enums(g: &Globals, ir: &mut Ir, diags: &mut Diagnostics) {
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
            // `error`: one of this controller's error codes (§8).
            if n.text == "error" {
                return match scope {
                    Some(ci) => Some(Type::ErrorCode(crate::ir::CtrlId(ci as u32))),
                    None => {
                        diags.push(
                            Diagnostic::error(
                                Code::TypeMismatch,
                                "the type `error` outside a controller".to_string(),
                                n.span,
                                "whose error codes?",
                            )
                            .with_help("`error` holds one of a controller's error codes: give it to a var, a status field, a hook or a job-list parameter of that controller; a buffer field can be an integer or an enum"),
                        );
                        None
                    }
                };
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
                        .with_help(if n.text == "duration" {
                            "`duration` is the type of constants only (`const T: duration = 50ms`), compared with a time: `state_time > T`; a var counts cycles instead (`u32`)".to_string()
                        } else { format!(
                            "declare it with `enum {0} {{ … }}` or `buffer {0} {{ … }}`, or use one of {1}",
                            n.text,
                            PRIMITIVES.join(", ")
                        ) })
                        .suggest(
                            &n.text,
                            PRIMITIVES.into_iter().chain(g.names.iter().filter_map(|(k, (r, _))| {
                                (!matches!(r, ItemRef::Controller(_))).then_some(*k)
                            })),
                        ),
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

pub(super) fn lower_buffer_types(g: &Globals, ir: &mut Ir, diags: &mut Diagnostics) {
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
pub(super) fn check_buffer_recursion(ir: &Ir, diags: &mut Diagnostics) {
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
