//! The generated Rust of every-cycle processing and status data
//! (LANGUAGE.md §7, SEMANTICS.md steps 3b, 4b and 5): a controller's
//! `StatusFields` type and the Global Memory buffer it is published in
//! every cycle, its supervisor's copy of it (`Data::sub_fields`, read in
//! step 1 and by `X.NAME`), the `pre`/`post` jobs inlined into `cycle`,
//! and the scenario driver's side (`Driven::write_sub_field`).
//!
//! Every part is empty for a controller without status fields, `pre` or
//! `post` and without subordinates that have status fields, so such
//! controllers generate exactly what they did before these constructs.

use super::controller::derivable_default;
use super::expr::{rust_type, zero, Gen};
use super::names::Names;
use super::Comments;
use crate::ident::prefixed;
use proc_macro2::{Ident, TokenStream};
use quote::quote;
use rcs_dsl::ir::*;

/// The pieces `controller::module` splices into a controller's module.
#[derive(Default)]
pub(crate) struct Parts {
    /// `StatusFields` (if the controller has status fields) and
    /// `SubFields` (if a subordinate has them), at module level.
    pub items: TokenStream,
    /// `Data`'s field for the subordinates' status fields.
    pub data_field: TokenStream,
    /// The controller's Global Memory handles for them.
    pub handles: TokenStream,
    /// Their declarations in `Controller::new`.
    pub declares: TokenStream,
    /// Their initialisers in `Controller::new`.
    pub inits: TokenStream,
    /// Step 1: the subordinates' status fields copied in.
    pub read: TokenStream,
    /// Step 3b: the `pre` jobs.
    pub pre: TokenStream,
    /// Step 4b: the `post` jobs.
    pub post: TokenStream,
    /// Step 5: the status fields written out.
    pub write: TokenStream,
}

/// The subordinates of controller `ci` that publish status fields: their
/// field in `SubFields` (the subordinate's name as in `Subs`), module, name.
fn publishing_subs<'a>(
    ir: &'a Ir,
    names: &'a Names,
    ci: usize,
) -> Vec<(&'a Ident, &'a Ident, &'a str, usize)> {
    let c = &ir.controllers[ci];
    c.subordinates
        .iter()
        .enumerate()
        .filter(|(_, s)| ir.controller(**s).status_fields().next().is_some())
        .map(|(i, s)| {
            (
                &names.ctrls[ci].subs[i],
                &names.ctrls[s.index()].module,
                ir.controller(*s).name.as_str(),
                i,
            )
        })
        .collect()
}

/// `shared`: for a type's shared module, where names in Global Memory come
/// from the `inst` argument of `new`.
pub(crate) fn parts(
    ir: &Ir,
    names: &Names,
    ci: usize,
    comments: &mut Comments,
    shared: bool,
) -> Parts {
    let own_name = if shared {
        quote!(inst.name)
    } else {
        quote!(NAME)
    };
    let c = &ir.controllers[ci];
    let n = &names.ctrls[ci];
    let mut p = Parts::default();
    let gen = Gen::new(ir, names, ci);

    // ---- this controller's status fields
    let own: Vec<(VarId, &Var)> = c.status_fields().collect();
    if !own.is_empty() {
        let fields: Vec<&Ident> = own.iter().map(|(id, _)| &n.vars[id.index()]).collect();
        let tys: Vec<TokenStream> = own.iter().map(|(_, v)| rust_type(names, &v.ty)).collect();
        let zeros: Vec<TokenStream> = own.iter().map(|(_, v)| zero(names, &v.ty)).collect();
        let docs: Vec<TokenStream> = own
            .iter()
            .map(|(_, v)| {
                let lines = v.docs.iter().map(|l| format!(" {l}"));
                quote!(#(#[doc = #lines])*)
            })
            .collect();
        let doc = format!(
            " `{}`'s status fields, published every cycle in Global Memory buffer `{}.status_fields` (zero before its first cycle).",
            c.name, c.name
        );
        let wire = super::schema::derives(names);
        // Only a distributed set's status fields derive serde.
        let docs: Vec<TokenStream> = own
            .iter()
            .zip(docs)
            .map(|((_, v), d)| {
                if names.wire {
                    let with = super::types::serde_with(names, &v.ty, None);
                    quote!(#d #with)
                } else {
                    d
                }
            })
            .collect();
        let structure = format!(
            "status_fields {}{{{}}}",
            c.name,
            own.iter()
                .zip(&tys)
                .map(|((_, v), t)| format!("{}:{}", v.name, t))
                .collect::<Vec<_>>()
                .join(",")
        );
        p.items.extend(super::schema::schema_impl(
            names,
            &quote!(StatusFields),
            &structure,
            &tys,
        ));
        // Zero is every type's `Default` where std can derive it (arrays up to 32).
        if own.iter().all(|(_, v)| derivable_default(&v.ty)) {
            p.items.extend(quote! {
                #[doc = #doc]
                #wire
                #[derive(Clone, Copy, Debug, Default, PartialEq)]
                pub struct StatusFields { #(#docs pub #fields: #tys),* }
            });
        } else {
            p.items.extend(quote! {
                #[doc = #doc]
                #wire
                #[derive(Clone, Copy, Debug, PartialEq)]
                pub struct StatusFields { #(#docs pub #fields: #tys),* }
                impl Default for StatusFields {
                    fn default() -> Self { Self { #(#fields: #zeros),* } }
                }
            });
        }
        p.handles
            .extend(quote!(status_fields_out: rt::Writer<StatusFields>,));
        p.declares.extend(
            quote!(ports.declare::<StatusFields>(&rt::status_fields_buffer_name(#own_name));),
        );
        p.inits.extend(
            quote!(status_fields_out: ports.writer(&rt::status_fields_buffer_name(#own_name)),),
        );
        p.write.extend(quote! {
            self.status_fields_out.write(
                StatusFields { #(#fields: self.data.vars.#fields),* },
                ctx.cycle,
            );
        });
    }

    // ---- the subordinates' status fields
    let subs = publishing_subs(ir, names, ci);
    if !subs.is_empty() {
        let fields: Vec<&Ident> = subs.iter().map(|(f, _, _, _)| *f).collect();
        let modules: Vec<&Ident> = subs.iter().map(|(_, m, _, _)| *m).collect();
        let sub_names: Vec<TokenStream> = subs
            .iter()
            .map(|(_, _, s, k)| {
                if shared {
                    let k = proc_macro2::Literal::usize_unsuffixed(*k);
                    quote!(inst.subs[#k])
                } else {
                    quote!(#s)
                }
            })
            .collect();
        let handles: Vec<Ident> = fields.iter().map(|f| prefixed("fields", f)).collect();
        p.items.extend(quote! {
            /// The subordinates' status fields as they last published them, whatever serial they echo.
            #[derive(Clone, Copy, Debug, Default, PartialEq)]
            pub struct SubFields { #(pub #fields: super::#modules::StatusFields),* }
        });
        p.data_field.extend(quote! {
            /// The subordinates' status fields, copied in at the start of the cycle.
            pub sub_fields: SubFields,
        });
        p.handles
            .extend(quote!(#(#handles: rt::Reader<super::#modules::StatusFields>,)*));
        p.declares.extend(quote! {
            #(ports.declare::<super::#modules::StatusFields>(&rt::status_fields_buffer_name(#sub_names));)*
        });
        p.inits.extend(
            quote!(#(#handles: ports.reader(&rt::status_fields_buffer_name(#sub_names)),)*),
        );
        p.read
            .extend(quote!(#(self.data.sub_fields.#fields = self.#handles.read().value;)*));
    }

    // ---- pre and post
    if let Some(b) = &c.pre {
        let step = comments
            .marker("3b. Pre-process: the `pre` jobs, with or without an active plan.".to_string());
        let jobs = gen.jobs(&b.jobs);
        p.pre.extend(quote!(#step #jobs));
    }
    if let Some(b) = &c.post {
        let step = comments
            .marker("4b. Post-process: the `post` jobs, after the row or none.".to_string());
        let jobs = gen.jobs(&b.jobs);
        p.post.extend(quote!(#step #jobs));
    }
    p
}

/// `X.NAME` in controller `ci`'s code: the cycle's copy of what subordinate
/// `sub` published.
pub(crate) fn sub_field(
    names: &Names,
    ctrl: &Controller,
    ci: usize,
    sub: CtrlId,
    var: VarId,
) -> TokenStream {
    let i = ctrl.subordinate_index(sub).expect("a subordinate");
    let s = &names.ctrls[ci].subs[i];
    let f = &names.ctrls[sub.index()].vars[var.index()];
    quote!(self.data.sub_fields.#s.#f)
}

/// The scenario driver's side: it plays the subordinates, so it holds the
/// writers of their status-field buffers. Returns the `Driver` fields,
/// their initialisers and the `write_sub_field` method (all empty when no
/// subordinate publishes status fields).
pub(crate) fn driver_parts(
    ir: &Ir,
    names: &Names,
    ci: usize,
) -> (TokenStream, TokenStream, TokenStream) {
    let subs = publishing_subs(ir, names, ci);
    if subs.is_empty() {
        return Default::default();
    }
    let dv = quote!(::rcs_runtime::driver);
    let c = &ir.controllers[ci];
    let handles: Vec<Ident> = subs
        .iter()
        .map(|(f, _, _, _)| prefixed("fields", f))
        .collect();
    let modules: Vec<&Ident> = subs.iter().map(|(_, m, _, _)| *m).collect();
    let sub_names: Vec<&str> = subs.iter().map(|(_, _, s, _)| *s).collect();
    let arms = c.subordinates.iter().filter_map(|s| {
        let sc = ir.controller(*s);
        // Only subordinates that publish status fields get an arm.
        sc.status_fields().next()?;
        let i = c.subordinate_index(*s).expect("a subordinate");
        let handle = prefixed("fields", &names.ctrls[ci].subs[i]);
        let sub_name = sc.name.as_str();
        let field_names: Vec<&str> = sc.status_fields().map(|(_, v)| v.name.as_str()).collect();
        let field_idents: Vec<&Ident> = sc
            .status_fields()
            .map(|(id, _)| &names.ctrls[s.index()].vars[id.index()])
            .collect();
        let whats: Vec<String> = field_names
            .iter()
            .map(|f| format!("{sub_name}.{f}"))
            .collect();
        Some(quote! {
            #sub_name => {
                let mut fields = self.#handle.read().value;
                match field {
                    #(#field_names => fields.#field_idents = #dv::typed(NAME, #whats, value)?,)*
                    _ => return Err(#dv::unknown(NAME, "status field", &format!("{sub}.{field}"))),
                }
                self.#handle.write(fields, self.cycle);
                Ok(())
            }
        })
    });
    (
        quote!(#(#handles: rt::Writer<super::#modules::StatusFields>,)*),
        quote!(#(#handles: gm.writer(&rt::status_fields_buffer_name(#sub_names))?,)*),
        quote! {
            fn write_sub_field(&mut self, sub: &str, field: &str, value: &#dv::Value) -> Result<(), #dv::DriveError> {
                match sub {
                    #(#arms)*
                    _ => Err(#dv::unknown(NAME, "status field", &format!("{sub}.{field}"))),
                }
            }
        },
    )
}
