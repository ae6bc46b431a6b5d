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

/// Whether serde handles a type itself: it implements arrays only up to 32
/// long. (Every generated buffer type serialises, see [`serde_with`].)
fn serde_native(t: &Type) -> bool {
    match t {
        Type::Array(elem, n) => *n <= 32 && serde_native(elem),
        _ => true,
    }
}

/// The `rcs_runtime::serde_array` codec of `t`, as the text of a type in
/// generic-argument position.
fn codec(names: &Names, t: &Type) -> String {
    match t {
        Type::Array(elem, n) if !serde_native(t) => {
            format!(
                "::rcs_runtime::serde_array::Array<{}, {n}>",
                codec(names, elem)
            )
        }
        _ => {
            let ty = rust_type(names, t).to_string().replace(' ', "");
            format!("::rcs_runtime::serde_array::Leaf<{ty}>")
        }
    }
}

/// The serde attribute of a field (or command parameter) of type `t`:
/// nothing where serde handles the type itself, else
/// `#[serde(with = "::rcs_runtime::serde_array::Array::<…>")]` (an array
/// longer than 32, or holding one), behind `cfg_attr(feature = …)` when
/// the derives are. Plan sets without such arrays get the same code as
/// before.
pub(crate) fn serde_with(names: &Names, t: &Type, feature: Option<&str>) -> TokenStream {
    let Type::Array(elem, n) = t else {
        return quote!();
    };
    if serde_native(t) {
        return quote!();
    }
    let with = format!(
        "::rcs_runtime::serde_array::Array::<{}, {n}>",
        codec(names, elem)
    );
    match feature {
        Some(f) => quote!(#[cfg_attr(feature = #f, serde(with = #with))]),
        None => quote!(#[serde(with = #with)]),
    }
}

/// How generated types derive serde, if they do.
pub(crate) struct SerdeDerive {
    /// The derive (and crate) attributes of each type.
    pub attrs: TokenStream,
    /// `Some(name)`: the derives sit behind `cfg_attr(feature = name)`, and
    /// so must the fields' `serde(with)`.
    pub feature: Option<String>,
}

/// `serde`: the serde derives, if asked for. `extra`: more items for the
/// module (the driver's conversions).
pub(crate) fn module(
    ir: &Ir,
    names: &Names,
    serde: Option<&SerdeDerive>,
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
        let serde = serde.map(|s| &s.attrs).into_iter();
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
        // A field serde cannot handle itself (an array over 32) goes
        // through `rcs_runtime::serde_array`.
        let withs: Vec<TokenStream> = match serde {
            Some(s) => b
                .fields
                .iter()
                .map(|f| serde_with(names, &f.ty, s.feature.as_deref()))
                .collect(),
            None => b.fields.iter().map(|_| quote!()).collect(),
        };
        let serde = serde.map(|s| &s.attrs).into_iter();
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
            pub struct #ty { #(#fdocs #withs pub #fields: #tys),* }
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
