//! The plan set's enums and buffer schemas → `mod types`: plain `Copy`
//! data that Global Memory can hold.

use super::controller::derivable_default;
use super::expr::{rust_type, zero};
use super::names::Names;
use proc_macro2::TokenStream;
use quote::quote;
use rcs_dsl::ir::{Ir, Type};

fn docs(lines: &[String]) -> TokenStream {
    let lines = lines.iter().map(|l| format!(" {l}"));
    quote!(#(#[doc = #lines])*)
}

/// Whether serde can derive for a type: it implements arrays only up to 32.
fn serde_derivable(ir: &Ir, t: &Type, depth: u32) -> bool {
    match t {
        Type::Array(elem, n) => *n <= 32 && serde_derivable(ir, elem, depth),
        Type::Buffer(b) => {
            depth < 64
                && ir.buffer_types[b.index()]
                    .fields
                    .iter()
                    .all(|f| serde_derivable(ir, &f.ty, depth + 1))
        }
        _ => true,
    }
}

/// `serde`: the serde derive attribute, if asked for. `extra`: more items
/// for the module (the driver's conversions).
pub(crate) fn module(
    ir: &Ir,
    names: &Names,
    serde: Option<&TokenStream>,
    extra: TokenStream,
) -> TokenStream {
    let enums = ir.enums.iter().enumerate().map(|(i, e)| {
        let n = &names.enums[i];
        let ty = &n.ty;
        let d = docs(&e.docs);
        let variants = e.variants.iter().enumerate().map(|(vi, v)| {
            let id = &n.variants[vi];
            let vd = docs(&v.docs);
            let default = if vi == 0 {
                quote!(#[default])
            } else {
                quote!()
            };
            quote!(#vd #default #id)
        });
        let ids = &n.variants;
        let texts: Vec<&str> = e.variants.iter().map(|v| v.name.as_str()).collect();
        let serde = serde.into_iter();
        let schema = super::schema::schema_impl(
            names,
            &quote!(#ty),
            &format!("enum {}{{{}}}", e.name, texts.join(",")),
            &[],
        );
        quote! {
            #d
            #(#serde)*
            #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
            pub enum #ty { #(#variants),* }
            #schema
            impl #ty {
                /// The variant's name as written in the plans.
                pub const fn name(self) -> &'static str {
                    match self { #(Self::#ids => #texts),* }
                }
            }
        }
    });
    let buffers = ir.buffer_types.iter().enumerate().map(|(i, b)| {
        let n = &names.buffers[i];
        let ty = &n.ty;
        let d = docs(&b.docs);
        let fields = &n.fields;
        let tys: Vec<TokenStream> = b.fields.iter().map(|f| rust_type(names, &f.ty)).collect();
        let fdocs = b.fields.iter().map(|f| docs(&f.docs));
        let derivable = b.fields.iter().all(|f| derivable_default(&f.ty));
        let (derive, default_impl) = if derivable {
            (quote!(Default,), quote!())
        } else {
            let zeros = b.fields.iter().map(|f| zero(names, &f.ty));
            (
                quote!(),
                quote! {
                    impl Default for #ty {
                        fn default() -> Self {
                            Self { #(#fields: #zeros),* }
                        }
                    }
                },
            )
        };
        // A buffer serde cannot derive for (an array over 32) goes without.
        let serde = serde
            .filter(|_| serde_derivable(ir, &Type::Buffer(rcs_dsl::ir::BufferTypeId(i as u32)), 0))
            .into_iter();
        let structure = format!(
            "buffer {}{{{}}}",
            b.name,
            b.fields
                .iter()
                .zip(&tys)
                .map(|(f, t)| format!("{}:{}", f.name, t))
                .collect::<Vec<_>>()
                .join(",")
        );
        let schema = super::schema::schema_impl(names, &quote!(#ty), &structure, &tys);
        quote! {
            #d
            #(#serde)*
            #[derive(Clone, Copy, Debug, #derive PartialEq)]
            pub struct #ty { #(#fdocs pub #fields: #tys),* }
            #default_impl
            #schema
        }
    });
    // Paths inside are `super::types::X`, which resolves from here too.
    quote! {
        /// The plan set's enums and Global Memory buffer schemas.
        pub mod types {
            #(#enums)*
            #(#buffers)*
            #extra
        }
    }
}
