//! One plan → one method of the generated `Controller`: bind the command
//! parameters the rows read, dispatch on the state, then try that state's
//! rows merged with the don't-care rows in precedence order.

use super::controller::paragraph;
use super::expr::{rust_type, CachedCall, Code, Gen};
use super::names::Names;
use super::Comments;
use crate::ident::prefixed;
use proc_macro2::TokenStream;
use quote::quote;
use rcs_dsl::ir::*;
use rcs_dsl::pretty::Printer;

/// Whether the leftmost conjunct of a condition is `new_command`: such a
/// row can only match in S0, so other states' arms leave it out without
/// skipping any hook call it would have made.
fn starts_with_new_command(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::NewCommand => true,
        ExprKind::Binary(rcs_dsl::ast::BinOp::And, operands) => {
            starts_with_new_command(&operands[0])
        }
        _ => false,
    }
}

/// Whether a plan reads a subordinate's status.
pub(super) fn uses_subs(p: &Plan) -> bool {
    let mut used = false;
    for r in &p.rows {
        r.visit_exprs(&mut |e| used |= matches!(e.kind, ExprKind::Sub(..)));
    }
    used
}

/// The parameters of the plan's command that its rows read: all of them
/// when a row forwards the command (`X <- cmd`).
pub(super) fn used_params(c: &Controller, p: &Plan) -> Vec<ParamId> {
    let forwards = p
        .rows
        .iter()
        .any(|r| r.jobs.iter().any(|j| matches!(j, Job::Forward { .. })));
    if forwards {
        let n = c.commands[p.verb.index()].params.len();
        return (0..n as u32).map(ParamId).collect();
    }
    let mut used = Vec::new();
    for r in &p.rows {
        r.visit_exprs(&mut |e| {
            if let ExprKind::CmdParam(_, pid) = e.kind {
                if !used.contains(&pid) {
                    used.push(pid);
                }
            }
        });
    }
    used
}

/// One plan as a method: bind the used parameters, dispatch on the state,
/// then try that state's rows merged with the don't-care rows in
/// precedence order; `otherwise` closes every chain.
pub(super) fn plan_fn(
    ir: &Ir,
    names: &Names,
    ci: usize,
    pi: usize,
    p: &Plan,
    comments: &mut Comments,
) -> TokenStream {
    let c = &ir.controllers[ci];
    let n = &names.ctrls[ci];
    let pn = &n.plans[pi];
    let func = &pn.func;
    let cmd = &c.commands[p.verb.index()];
    let used = used_params(c, p);
    let args: Vec<TokenStream> = cmd
        .params
        .iter()
        .enumerate()
        .filter(|(i, _)| used.contains(&ParamId(*i as u32)))
        .map(|(i, param)| {
            let local = prefixed("cmd", &n.params[p.verb.index()][i]);
            let ty = rust_type(names, &param.ty);
            quote!(#local: #ty)
        })
        .collect();
    let gen = Gen::new(ir, names, ci);
    // Each distinct hook call of the conditions runs at most once per
    // cycle, on first use: its result waits in a local for the next row.
    let cached = CachedCall::collect(
        names,
        ci,
        p.rows.iter().filter_map(|r| match &r.cond {
            Condition::When(e) => Some(e),
            Condition::Otherwise => None,
        }),
    );
    let cond_gen = Gen {
        cached: &cached,
        ..gen
    };
    let cache_locals = cached.iter().map(|k| {
        let local = &k.local;
        let ty = rust_type(names, &c.hooks[k.hook.index()].ret);
        quote!(let mut #local: Option<#ty> = None;)
    });
    let printer = Printer::new(ir, c, Some(p));
    let subs_param = if uses_subs(p) {
        quote!(subs: Subs,)
    } else {
        quote!()
    };
    let state_ty = &pn.state_ty;
    // Relative to the plan set's root: outputs never carry absolute paths.
    let file = &ir.files[p.header.file.0 as usize];

    let row_code = |r: &Row, comments: &mut Comments| -> (Option<(Code, bool)>, TokenStream) {
        let text = format!(
            "{}: {} when {} -> {}   [{file}:{}]",
            printer.label(r),
            printer.from(r),
            printer.condition(r),
            printer.target(r),
            r.line
        );
        // The row's doc comment, then the row as written.
        let doc_markers: Vec<TokenStream> =
            r.docs.iter().map(|l| comments.marker(l.clone())).collect();
        let marker = comments.marker(text);
        let jobs = gen.jobs(&r.jobs);
        let pos = r.position as u16;
        let target = match r.to {
            Target::State(s) => {
                let v = &pn.states[s.index()];
                quote!(rt::Target::State(#state_ty::#v.raw()))
            }
            Target::Same => quote!(rt::Target::Same),
            Target::Done => quote!(rt::Target::Done),
            Target::Error(None) => quote!(rt::Target::Error(error::NONE)),
            Target::Error(Some(e)) => {
                let id = &n.error_consts[e.index()];
                quote!(rt::Target::Error(error::#id))
            }
            Target::ErrorOf(v) => {
                let id = &n.vars[v.index()];
                quote!(rt::Target::Error(self.data.vars.#id))
            }
        };
        let body = quote! {
            #(#doc_markers)*
            #marker
            #jobs
            self.bk.fire(#pos, #target);
        };
        let cond = match &r.cond {
            Condition::When(e) if e.indexes_by_value() => {
                Some((super::index::guarded_condition(cond_gen.expr(e)), true))
            }
            Condition::When(e) => Some((cond_gen.expr(e), false)),
            Condition::Otherwise => None,
        };
        (cond, body)
    };

    // The rows of one arm as an if / else-if chain, `otherwise` last.
    let chain = |rows: &[&Row], comments: &mut Comments| -> TokenStream {
        let mut parts: Vec<(Option<(Code, bool)>, TokenStream)> =
            rows.iter().map(|r| row_code(r, comments)).collect();
        let otherwise = p.otherwise().map(|r| row_code(r, comments).1);
        // Build from the end: else-branch first. The flag says whether the
        // tail is an `if` expression, which may follow `else` directly.
        // After a condition that met an index out of range, no later row
        // (nor `otherwise`) is tried: the cycle ends the plan with INDEX_RANGE.
        let indexes: Vec<bool> = parts
            .iter()
            .map(|(c, _)| c.as_ref().is_some_and(|(_, i)| *i))
            .collect();
        let mut tail: Option<(TokenStream, bool)> = otherwise.map(|t| {
            if indexes.contains(&true) {
                (quote!(if !self.bk.index_range_hit() { #t }), true)
            } else {
                (t, false)
            }
        });
        while let Some((cond, body)) = parts.pop() {
            let (cond, _) = cond.expect("only otherwise has no condition");
            let cond = if indexes[..parts.len()].contains(&true) {
                super::index::after_index(cond)
            } else {
                cond
            };
            let ts = &cond.ts;
            tail = Some(if cond.has_block {
                // A hoisted hook call cannot stand in an `if` condition.
                let rest = tail.map(|(t, _)| quote!(else { #t })).unwrap_or_default();
                (
                    quote!({ let matched = #ts; if matched { #body } #rest }),
                    false,
                )
            } else {
                let code = match tail {
                    None => quote!(if #ts { #body }),
                    Some((t, true)) => quote!(if #ts { #body } else #t),
                    Some((t, false)) => quote!(if #ts { #body } else { #t }),
                };
                (code, true)
            });
        }
        tail.map(|(t, _)| t).unwrap_or_default()
    };

    let ordinary: Vec<&Row> = p.rows.iter().filter(|r| !r.is_otherwise()).collect();
    let dont_care_only: Vec<&Row> = ordinary
        .iter()
        .copied()
        .filter(|r| r.is_dont_care())
        .collect();
    // States with rows of their own (alone or in a set), and the states an
    // `except` leaves out, get an arm; every other state (S0 too, unless it
    // has one) shares the don't-care arm, where each `*` and `except` row
    // applies. An arm holds the rows that apply in its state, in position
    // order, so the first match is the interpreter's.
    let mut arm_states: Vec<StateId> = Vec::new();
    for r in &ordinary {
        let named = match &r.from {
            From::DontCare(_) => &[][..],
            From::State(s) => std::slice::from_ref(s),
            From::States(set) | From::Except(_, set) => set,
        };
        for s in named {
            if !arm_states.contains(s) {
                arm_states.push(*s);
            }
        }
    }
    arm_states.sort();
    let arms: Vec<(StateId, TokenStream)> = arm_states
        .iter()
        .map(|s| {
            let rows: Vec<&Row> = ordinary
                .iter()
                .copied()
                .filter(|r| match r.from {
                    From::State(x) => x == *s,
                    // Outside S0 a row whose condition starts with
                    // `new_command` cannot match and calls no hook: left out.
                    _ => {
                        let entry_only =
                            matches!(&r.cond, Condition::When(e) if starts_with_new_command(e));
                        r.applies_in(*s) && (*s == StateId::S0 || !entry_only)
                    }
                })
                .collect();
            (*s, chain(&rows, comments))
        })
        .collect();
    let default_arm = chain(&dont_care_only, comments);
    let body = if arms.is_empty() {
        default_arm
    } else if arms.len() == 1 && default_arm.is_empty() {
        let (s, code) = &arms[0];
        let v = &pn.states[s.index()];
        quote!(if self.bk.state() == #state_ty::#v.raw() { #code })
    } else {
        let pats = arms.iter().map(|(s, _)| {
            let v = &pn.states[s.index()];
            quote!(Some(#state_ty::#v))
        });
        let codes = arms.iter().map(|(_, c)| c);
        quote! {
            match #state_ty::from_raw(self.bk.state()) {
                #(#pats => { #codes })*
                _ => { #default_arm }
            }
        }
    };
    let rows_word = if p.rows.len() == 1 { "row" } else { "rows" };
    let doc = format!(
        " Plan `{}` ({} {rows_word}).",
        c.plan_title(p),
        p.rows.len()
    );
    let plan_docs = paragraph(&p.docs);
    quote! {
        #[doc = #doc] #plan_docs
        fn #func(&mut self, #subs_param #(#args),*) {
            #(#cache_locals)*
            #body
        }
    }
}
