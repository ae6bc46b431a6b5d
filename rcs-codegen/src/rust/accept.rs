//! Back end, Rust: refusing a command (`command VERB(…) accept when COND`,
//! docs/semantics.md step 3a) in a generated controller — the `accept`
//! method that judges an arriving command, and the cycle code around `pre`
//! that puts everything back when it is refused. Controllers without
//! `accept when` get none of it, so their code is what it was.

use super::expr::Gen;
use super::names::Names;
use crate::ident::prefixed;
use proc_macro2::TokenStream;
use quote::quote;
use rcs_dsl::ir::*;

/// What a controller with refusals adds: a method, and the cycle's code
/// from the new-command check through `pre`.
pub(super) struct Refusal {
    pub method: TokenStream,
    pub cycle: TokenStream,
}

/// `None` when no verb of controller `ci` has `accept when`.
pub(super) fn refusal(
    ir: &Ir,
    names: &Names,
    ci: usize,
    pre_jobs: &TokenStream,
) -> Option<Refusal> {
    let c = &ir.controllers[ci];
    if c.commands.iter().all(|k| k.accept.is_none()) {
        return None;
    }
    let n = &names.ctrls[ci];
    let gen = Gen::new(ir, names, ci);
    let mut reads_subs = false;
    let arms: Vec<TokenStream> = c
        .commands
        .iter()
        .enumerate()
        .filter_map(|(i, k)| {
            let a = k.accept.as_ref()?;
            let v = &n.commands[i];
            let mut used: Vec<ParamId> = Vec::new();
            a.cond.visit(&mut |e| match e.kind {
                ExprKind::CmdParam(_, p) if !used.contains(&p) => used.push(p),
                ExprKind::Sub(..) => reads_subs = true,
                _ => {}
            });
            used.sort();
            let binds = used.iter().map(|p| {
                let field = &n.params[i][p.index()];
                let local = prefixed("cmd", field);
                quote!(#field: #local)
            });
            let cond = gen.expr(&a.cond).ts;
            Some(if k.params.is_empty() {
                quote!(Command::#v => #cond)
            } else {
                quote!(Command::#v { #(#binds,)* .. } => #cond)
            })
        })
        .collect();
    let subs = if reads_subs {
        quote!(let subs = self.data.subs;)
    } else {
        quote!()
    };
    let rest = if arms.len() < c.commands.len() {
        quote!(_ => true,)
    } else {
        quote!()
    };
    let method = quote! {
        /// Step 3a: whether the command that arrived this cycle is taken
        /// (its verb's `accept when` condition, judged after `pre`).
        fn accept(&mut self) -> bool {
            #subs
            match self.data.command { #(#arms,)* #rest }
        }
    };
    let cycle = quote! {
        // 3a. A command that may be refused: keep what a refusal puts back.
        let before = if self.bk.new_command() {
            let kept = (self.data.command, self.data.vars, self.data.writes);
            self.data.command = command.command;
            Some(kept)
        } else {
            None
        };
        #pre_jobs
        if let Some((command, vars, writes)) = before {
            if !self.accept() && !self.bk.index_range_hit() {
                // Refused: as if no command had arrived, `pre` included.
                self.bk.refuse();
                self.data.command = command;
                self.data.vars = vars;
                self.data.writes = writes;
                #pre_jobs
            }
        }
    };
    Some(Refusal { method, cycle })
}
