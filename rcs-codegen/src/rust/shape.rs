//! Back end, Rust: what a controller's module is wired to — [`Shape`],
//! what differs between a controller's own module and the module a
//! controller type shares among its instances (`NAME` or the instance's
//! parameters, the name in Global Memory), and [`Wiring`], its buffers and
//! subordinates in declaration order, which the controller and its
//! scenario driver both build on.

use super::controller::TypeModule;
use super::expr::rust_type;
use super::names::Names;
use crate::ident::prefixed;
use proc_macro2::{Ident, TokenStream};
use quote::quote;
use rcs_dsl::ir::*;

/// What differs between a controller's own module and a type's shared one.
pub(super) struct Shape {
    /// `NAME`, or the `Instance` and `Params` structs.
    pub(super) head: TokenStream,
    /// The visibility of `hooks` and `data` (an instance's driver, in the
    /// instance's module, reaches them).
    pub(super) vis: TokenStream,
    pub(super) inst_field: TokenStream,
    pub(super) inst_param: TokenStream,
    pub(super) inst_init: TokenStream,
    /// The name in `new`, and in methods.
    pub(super) gm_name: TokenStream,
    pub(super) self_name: TokenStream,
    pub(super) data_init: TokenStream,
}

pub(super) fn shape(
    names: &Names,
    c: &Controller,
    name: &str,
    shared: Option<&TypeModule>,
    vars_for_instance: bool,
) -> Shape {
    let Some(t) = shared else {
        return Shape {
            head: quote! {
                /// The controller's name in Global Memory and in traces.
                pub const NAME: &str = #name;
            },
            vis: quote!(),
            inst_field: quote!(),
            inst_param: quote!(),
            inst_init: quote!(),
            gm_name: quote!(NAME),
            self_name: quote!(NAME),
            data_init: quote!(Data::default()),
        };
    };
    let (r, w, s) = (
        proc_macro2::Literal::usize_unsuffixed(c.reads.len()),
        proc_macro2::Literal::usize_unsuffixed(c.writes.len()),
        proc_macro2::Literal::usize_unsuffixed(c.subordinates.len()),
    );
    let fields: Vec<Ident> = (0..t.group.slots.len())
        .map(super::names::SlotNames::field)
        .collect();
    let tys: Vec<TokenStream> = t
        .group
        .slots
        .iter()
        .map(|s| rust_type(names, &s.ty))
        .collect();
    let params_doc = format!(
        " The values the instances of `{}` differ in: its parameters where its plans use them.",
        t.ty
    );
    let inst_doc = format!(
        " One instance of `{}`: its names in Global Memory and its parameters.",
        t.ty
    );
    Shape {
        head: quote! {
            #[doc = #inst_doc]
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct Instance {
                /// The instance's name: its command and status buffers, traces.
                pub name: &'static str,
                /// The Global Memory buffers bound to its `reads`, in order.
                pub reads: [&'static str; #r],
                /// The Global Memory buffers bound to its `writes`, in order.
                pub writes: [&'static str; #w],
                /// The controllers bound to its `subordinates`, in order.
                pub subs: [&'static str; #s],
                /// Its parameters.
                pub params: Params,
            }
            #[doc = #params_doc]
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct Params { #(pub #fields: #tys),* }
        },
        vis: quote!(pub(super)),
        inst_field: quote!(inst: Instance,),
        inst_param: quote!(inst: Instance,),
        inst_init: quote!(inst,),
        gm_name: quote!(inst.name),
        self_name: quote!(self.inst.name),
        data_init: if vars_for_instance {
            quote!(Data {
                vars: Vars::for_instance(&inst),
                ..Data::default()
            })
        } else {
            quote!(Data::default())
        },
    }
}

/// A controller's Global Memory wiring, in declaration order: its `reads`
/// and `writes` buffers (field in `Reads`/`Writes`, Rust type, name in
/// Global Memory, handle field) and its subordinates (name, module, handle
/// field). The controller and its scenario driver both build on it.
pub(crate) struct Wiring<'a> {
    pub read_fields: Vec<Ident>,
    pub read_tys: Vec<TokenStream>,
    /// Names in Global Memory: string literals, or in a type's shared
    /// module the instance's (`inst.reads[0]`, see [`Wiring::of_instance`]).
    pub read_names: Vec<TokenStream>,
    pub read_handles: Vec<Ident>,
    pub write_fields: Vec<Ident>,
    pub write_tys: Vec<TokenStream>,
    pub write_names: Vec<TokenStream>,
    pub write_handles: Vec<Ident>,
    pub sub_names: Vec<TokenStream>,
    pub sub_modules: Vec<&'a Ident>,
    pub sub_handles: Vec<Ident>,
}

impl<'a> Wiring<'a> {
    pub fn new(ir: &'a Ir, names: &'a Names, ci: usize) -> Wiring<'a> {
        let c = &ir.controllers[ci];
        let n = &names.ctrls[ci];
        let fields = |list: &[BufferId]| -> Vec<Ident> {
            list.iter()
                .map(|b| n.buffers[b.index()].clone().expect("own buffer"))
                .collect()
        };
        let tys = |list: &[BufferId]| -> Vec<TokenStream> {
            list.iter()
                .map(|b| rust_type(names, &Type::Buffer(ir.buffers[b.index()].ty)))
                .collect()
        };
        let gm_names = |list: &[BufferId]| -> Vec<TokenStream> {
            list.iter()
                .map(|b| {
                    let n = ir.buffers[b.index()].name.as_str();
                    quote!(#n)
                })
                .collect()
        };
        let handles = |prefix: &str, ids: &[Ident]| -> Vec<Ident> {
            ids.iter().map(|f| prefixed(prefix, f)).collect()
        };
        let read_fields = fields(&c.reads);
        let write_fields = fields(&c.writes);
        Wiring {
            read_handles: handles("in", &read_fields),
            write_handles: handles("out", &write_fields),
            sub_handles: handles("sub", &n.subs),
            read_tys: tys(&c.reads),
            write_tys: tys(&c.writes),
            read_names: gm_names(&c.reads),
            write_names: gm_names(&c.writes),
            read_fields,
            write_fields,
            sub_names: c
                .subordinates
                .iter()
                .map(|s| {
                    let n = ir.controllers[s.index()].name.as_str();
                    quote!(#n)
                })
                .collect(),
            sub_modules: c
                .subordinates
                .iter()
                .map(|s| &names.ctrls[s.index()].module)
                .collect(),
        }
    }

    /// The wiring of a type's shared module: every name in Global Memory
    /// read from the instance, `#inst.reads[k]` and so on.
    pub fn of_instance(mut self, inst: &TokenStream) -> Self {
        let from = |list: &mut Vec<TokenStream>, field: &str| {
            let field = quote::format_ident!("{}", field);
            for (k, n) in list.iter_mut().enumerate() {
                let k = proc_macro2::Literal::usize_unsuffixed(k);
                *n = quote!(#inst.#field[#k]);
            }
        };
        from(&mut self.read_names, "reads");
        from(&mut self.write_names, "writes");
        from(&mut self.sub_names, "subs");
        self
    }
}
