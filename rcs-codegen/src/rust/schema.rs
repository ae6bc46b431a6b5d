//! What a type needs to travel between processes (plan sets whose manifest
//! places CPUs in more than one process, see `docs/distribution.md`): serde
//! derives through the runtime's re-export, so the user's crate needs no
//! serde of its own, and an `rt::Schema` impl whose hash is computed at
//! compile time from the type's structure (its declaration as text plus the
//! schemas of its field types), so two processes built from different
//! declarations refuse each other's samples. Single-process sets get
//! neither: their generated code is as before.

use proc_macro2::TokenStream;
use quote::quote;

use super::names::Names;

/// The serde derive and crate attributes for a type of a distributed set;
/// nothing otherwise.
pub(crate) fn derives(names: &Names) -> TokenStream {
    if names.wire {
        quote! {
            #[derive(::rcs_runtime::serde::Serialize, ::rcs_runtime::serde::Deserialize)]
            #[serde(crate = "rcs_runtime::serde")]
        }
    } else {
        quote!()
    }
}

/// `impl rt::Schema for #ty`: FNV-1a of `structure` (the declaration as
/// text, names and field order included) followed by the schemas of
/// `parts` (the field and parameter types, in order). Nothing for a
/// single-process set.
pub(crate) fn schema_impl(
    names: &Names,
    ty: &TokenStream,
    structure: &str,
    parts: &[TokenStream],
) -> TokenStream {
    if !names.wire {
        return quote!();
    }
    quote! {
        impl ::rcs_runtime::Schema for #ty {
            const SCHEMA: u64 = ::rcs_runtime::schema::combine(#structure, &[#(<#parts as ::rcs_runtime::Schema>::SCHEMA),*]);
        }
    }
}
