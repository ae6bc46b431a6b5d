//! Back end, Rust: a controller's statuses and error codes as runtime
//! values — the `status` and `error` modules of constants and the typed
//! `Status` and `Error` enums with their conversions and names, the
//! built-ins first. Part of the controller's module ([`super::controller`]).
//! A controller with nothing but the built-ins re-exports the runtime's
//! (`rcs_runtime::builtin`).

use super::controller::docs;
use super::names::Names;
use proc_macro2::TokenStream;
use quote::quote;
use rcs_dsl::ir::{Controller, StatusId};

/// The status and error items of controller `c` (index `ci`, named `name`).
pub(super) fn codes(names: &Names, ci: usize, c: &Controller, name: &str) -> TokenStream {
    // Only the built-ins: the runtime's copies, the same names and
    // methods, compiled once for every such controller (issue 30).
    if c.statuses.len() == StatusId::BUILTIN.len() && c.errors.is_empty() && !c.can_refuse() {
        return quote! {
            pub use rt::builtin::{error, status, Error, Status};
        };
    }
    let n = &names.ctrls[ci];
    let status_consts = c.statuses.iter().enumerate().map(|(i, s)| {
        let id = &n.status_consts[i];
        let value = match i {
            0 => quote!(rt::Status::NOT_READY),
            1 => quote!(rt::Status::EXECUTING),
            2 => quote!(rt::Status::DONE),
            3 => quote!(rt::Status::ERROR),
            _ => {
                let k = (i - 4) as u16;
                quote!(rt::Status::custom(#k))
            }
        };
        let d = docs(&s.docs);
        quote!(#d pub const #id: rt::Status = #value;)
    });
    let status_variants: Vec<_> = n.status_variants.iter().collect();
    let status_consts_ids: Vec<_> = n.status_consts.iter().collect();
    let status_names: Vec<&str> = c.statuses.iter().map(|s| s.name.as_str()).collect();
    let error_consts = c.errors.iter().enumerate().map(|(i, e)| {
        let id = &n.error_consts[i];
        let k = i as u16;
        let d = docs(&e.docs);
        quote!(#d pub const #id: rt::ErrorCode = rt::ErrorCode::custom(#k);)
    });
    let error_variants: Vec<_> = n.error_variants.iter().collect();
    let error_consts_ids: Vec<_> = n.error_consts.iter().collect();
    let error_names: Vec<&str> = c.errors.iter().map(|e| e.name.as_str()).collect();
    let status_doc =
        format!(" `{name}`'s statuses as runtime values: the built-ins, then its own.");
    let error_doc = format!(" `{name}`'s error codes as runtime values.");
    // The built-in error REFUSED, only where a verb can be refused.
    let refuses = c.can_refuse();
    let (refused_const, refused_variant, refused_from_raw, refused_raw, refused_name) = if refuses {
        (
            quote! {
                /// A command refused by its verb's `accept when` (seen by the sender only).
                pub const REFUSED: rt::ErrorCode = rt::ErrorCode::REFUSED;
            },
            quote!(Refused,),
            quote!(if raw.0 == error::REFUSED.0 {
                return Some(Self::Refused);
            }),
            quote!(Self::Refused => error::REFUSED,),
            quote!(Self::Refused => "REFUSED",),
        )
    } else {
        Default::default()
    };
    quote! {
            #[doc = #status_doc]
            pub mod status {
                use ::rcs_runtime as rt;
                #(#status_consts)*
            }

            #[doc = #error_doc]
            pub mod error {
                use ::rcs_runtime as rt;
                /// No error.
                pub const NONE: rt::ErrorCode = rt::ErrorCode::NONE;
                /// A command whose verb has no plan (only from an outside writer).
                pub const UNKNOWN_COMMAND: rt::ErrorCode = rt::ErrorCode::UNKNOWN_COMMAND;
                /// An index by a run-time value outside its array (the cycle ended the plan).
                pub const INDEX_RANGE: rt::ErrorCode = rt::ErrorCode::INDEX_RANGE;
                /// A hook panicked; the executive caught it and ended the plan.
                pub const HOOK_PANIC: rt::ErrorCode = rt::ErrorCode::HOOK_PANIC;
                #refused_const
                #(#error_consts)*
            }

            /// A status of this controller.
            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub enum Status { #(#status_variants),* }
            impl Status {
                /// The typed status of a runtime value, if it is one of this controller's.
                pub const fn from_raw(raw: rt::Status) -> Option<Self> {
                    #(if raw.0 == status::#status_consts_ids.0 { return Some(Self::#status_variants); })*
                    None
                }
                /// The runtime value.
                pub const fn raw(self) -> rt::Status {
                    match self { #(Self::#status_variants => status::#status_consts_ids),* }
                }
                /// The name as written in the plans.
                pub const fn name(self) -> &'static str {
                    match self { #(Self::#status_variants => #status_names),* }
                }
            }

            /// An error code this controller reports.
            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub enum Error { UnknownCommand, IndexRange, HookPanic, #refused_variant #(#error_variants),* }
            impl Error {
                /// The typed error of a runtime code (`None` for no error).
                pub const fn from_raw(raw: rt::ErrorCode) -> Option<Self> {
                    if raw.0 == error::UNKNOWN_COMMAND.0 { return Some(Self::UnknownCommand); }
                    if raw.0 == error::INDEX_RANGE.0 { return Some(Self::IndexRange); }
                    if raw.0 == error::HOOK_PANIC.0 { return Some(Self::HookPanic); }
                    #refused_from_raw
                    #(if raw.0 == error::#error_consts_ids.0 { return Some(Self::#error_variants); })*
                    None
                }
                /// The runtime code.
                pub const fn raw(self) -> rt::ErrorCode {
                    match self {
                        Self::UnknownCommand => error::UNKNOWN_COMMAND,
                        Self::IndexRange => error::INDEX_RANGE,
                        Self::HookPanic => error::HOOK_PANIC,
                        #refused_raw
                        #(Self::#error_variants => error::#error_consts_ids),*
                    }
                }
                /// The name as written in the plans.
                pub const fn name(self) -> &'static str {
                    match self {
                        Self::UnknownCommand => "UNKNOWN_COMMAND",
                        Self::IndexRange => "INDEX_RANGE",
                        Self::HookPanic => "HOOK_PANIC",
                        #refused_name
                        #(Self::#error_variants => #error_names),*
                    }
                }
            }
    }
}
