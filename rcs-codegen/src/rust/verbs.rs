//! Generated Rust for `X <- cmd` (`Job::Forward`): send the running
//! command on to a subordinate, its arguments as received. The plan
//! function binds every parameter of a plan that forwards (see
//! `plan::used_params`); a plan shared by several verbs picks the
//! subordinate's command by the running verb's number.

use super::expr::Gen;
use crate::ident::prefixed;
use proc_macro2::{Literal, TokenStream};
use quote::quote;
use rcs_dsl::ir::{CommandId, CtrlId};

impl Gen<'_> {
    /// The send for each `(ours, theirs)` pair; one verb needs no `match`.
    pub(super) fn forward(&self, sub: CtrlId, commands: &[(CommandId, CommandId)]) -> TokenStream {
        // The plan function's locals are named after its first verb's
        // parameters, which every verb of the plan shares.
        let Some(&(first, _)) = commands.first() else {
            return quote!();
        };
        let sends: Vec<TokenStream> = commands
            .iter()
            .map(|&(_, theirs)| {
                let vals: Vec<TokenStream> = self.cn().params[first.index()]
                    .iter()
                    .map(|p| {
                        let local = prefixed("cmd", p);
                        quote!(#local)
                    })
                    .collect();
                self.send(sub, theirs, &vals)
            })
            .collect();
        match sends.split_last() {
            Some((only, [])) => only.clone(),
            Some((last, rest)) => {
                let verbs = commands
                    .iter()
                    .take(rest.len())
                    .map(|(ours, _)| Literal::u16_unsuffixed(ours.0 as u16));
                quote! {
                    match self.bk.verb() {
                        #(#verbs => { #rest })*
                        _ => { #last }
                    }
                }
            }
            None => quote!(),
        }
    }
}
