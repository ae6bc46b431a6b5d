//! The scenario driver (emitted only when asked: `Options::driver`): what
//! `rcsc test --backend compiled` and the differential tests need to run a
//! generated controller alone, by name — conversions between the plan
//! types and `rcs_runtime::driver::Value`, `DrivenCommand` for each command
//! enum, and per controller `ScriptedHooks` plus a `Driver` implementing
//! `rcs_runtime::driver::Driven` on its own Global Memory.
//!
//! None of this is on a running system's cycle path: it allocates, and it
//! is meant for tests.

use super::controller::derivable_default;
use super::expr::{rust_type, zero};
use super::names::Names;
use super::shape::Wiring;
use crate::ident::prefixed;
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use rcs_dsl::ir::{Ir, Type};

const DV: &str = "::rcs_runtime::driver";

fn dv() -> TokenStream {
    DV.parse().expect("a path")
}

/// `ToValue`/`FromValue` for the plan set's enums and buffer types (inside `mod types`).
pub(crate) fn type_conversions(ir: &Ir, names: &Names) -> TokenStream {
    let dv = dv();
    let enums = ir.enums.iter().enumerate().map(|(i, e)| {
        let n = &names.enums[i];
        let ty = &n.ty;
        let ids = &n.variants;
        let idx: Vec<Literal> = (0..e.variants.len())
            .map(|k| Literal::u32_unsuffixed(k as u32))
            .collect();
        quote! {
            impl #dv::ToValue for #ty {
                fn to_value(&self) -> #dv::Value {
                    #dv::Value::Enum(match self { #(Self::#ids => #idx),* })
                }
            }
            impl #dv::FromValue for #ty {
                fn from_value(v: &#dv::Value) -> Option<Self> {
                    match v {
                        #(#dv::Value::Enum(#idx) => Some(Self::#ids),)*
                        _ => None,
                    }
                }
            }
        }
    });
    let buffers = ir.buffer_types.iter().enumerate().map(|(i, _)| {
        let n = &names.buffers[i];
        let ty = &n.ty;
        let fields = &n.fields;
        let locals: Vec<_> = (0..fields.len()).map(|k| format_ident!("f{}", k)).collect();
        quote! {
            impl #dv::ToValue for #ty {
                fn to_value(&self) -> #dv::Value {
                    #dv::Value::Buffer(vec![#(#dv::ToValue::to_value(&self.#fields)),*])
                }
            }
            impl #dv::FromValue for #ty {
                fn from_value(v: &#dv::Value) -> Option<Self> {
                    let #dv::Value::Buffer(fields) = v else { return None; };
                    let [#(#locals),*] = fields.as_slice() else { return None; };
                    Some(Self { #(#fields: #dv::FromValue::from_value(#locals)?),* })
                }
            }
        }
    });
    quote!(#(#enums)* #(#buffers)*)
}

/// `DrivenCommand`, `ScriptedHooks` and `Driver` for controller `ci`
/// (inside its module).
/// Which parts of a controller's driver to write.
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum DriverPart {
    /// A controller's own module: all of it.
    Whole,
    /// A type's shared module: `DrivenCommand` for its one `Command`.
    TypeCommand,
    /// An instance's module: all but `DrivenCommand`, with its `INSTANCE`.
    Instance,
}

pub(crate) fn controller_driver(ir: &Ir, names: &Names, ci: usize) -> TokenStream {
    driver_parts(ir, names, ci, DriverPart::Whole)
}

pub(crate) fn driver_parts(ir: &Ir, names: &Names, ci: usize, part: DriverPart) -> TokenStream {
    let dv = dv();
    let c = &ir.controllers[ci];
    let n = &names.ctrls[ci];

    // ---- DrivenCommand
    let command_impl = if c.commands.is_empty() {
        quote! {
            impl #dv::DrivenCommand for Command {
                fn from_parts(verb: &str, _: &[#dv::Value]) -> Result<Self, #dv::DriveError> {
                    Err(#dv::unknown(NAME, "verb", verb))
                }
                fn parts(&self) -> (rt::VerbId, Vec<#dv::Value>) {
                    (0, Vec::new())
                }
            }
        }
    } else {
        let from_arms = c.commands.iter().enumerate().map(|(i, k)| {
            let v = &n.commands[i];
            let text = &k.name;
            let count = k.params.len();
            let ps = &n.params[i];
            let pnames = k.params.iter().map(|p| p.name.as_str());
            let idx = 0..count;
            if count == 0 {
                quote!(#text => { #dv::arity(NAME, verb, args, 0)?; Ok(Self::#v) })
            } else {
                quote!(#text => {
                    #dv::arity(NAME, verb, args, #count)?;
                    Ok(Self::#v { #(#ps: #dv::arg(NAME, verb, #pnames, args, #idx)?),* })
                })
            }
        });
        let part_arms = c.commands.iter().enumerate().map(|(i, k)| {
            let v = &n.commands[i];
            let id = i as u16;
            let ps = &n.params[i];
            if k.params.is_empty() {
                quote!(Self::#v => (#id, Vec::new()))
            } else {
                quote!(Self::#v { #(#ps),* } => (#id, vec![#(#dv::ToValue::to_value(#ps)),*]))
            }
        });
        quote! {
            impl #dv::DrivenCommand for Command {
                fn from_parts(verb: &str, args: &[#dv::Value]) -> Result<Self, #dv::DriveError> {
                    match verb {
                        #(#from_arms)*
                        _ => Err(#dv::unknown(NAME, "verb", verb)),
                    }
                }
                fn parts(&self) -> (rt::VerbId, Vec<#dv::Value>) {
                    match self { #(#part_arms),* }
                }
            }
        }
    };

    let command_impl = match part {
        DriverPart::Whole => command_impl,
        DriverPart::TypeCommand => {
            // The type's `Command` has no `NAME`: its errors name the type
            // (an instance's driver renames them, `for_controller`).
            let ty = c
                .instance_of
                .as_ref()
                .map_or(c.name.as_str(), |i| i.ty.as_str());
            return quote! {
                const NAME: &str = #ty;
                #command_impl
            };
        }
        DriverPart::Instance => quote!(),
    };
    let (new_controller, from_parts) = match part {
        DriverPart::Instance => (
            quote!(Controller::new(&gm, INSTANCE, ScriptedHooks::default())?),
            quote!(<Command as #dv::DrivenCommand>::from_parts(verb, args).map_err(|e| e.for_controller(NAME))?),
        ),
        _ => (
            quote!(Controller::new(&gm, ScriptedHooks::default())?),
            quote!(<Command as #dv::DrivenCommand>::from_parts(verb, args)?),
        ),
    };

    // ---- ScriptedHooks
    let hook_fields = &n.hooks;
    let hook_tys: Vec<TokenStream> = c.hooks.iter().map(|h| rust_type(names, &h.ret)).collect();
    let hook_fns = c.hooks.iter().enumerate().map(|(hi, h)| {
        let id = &n.hooks[hi];
        let tys = h.params.iter().map(|p| rust_type(names, &p.ty));
        let args: Vec<_> = (0..h.params.len())
            .map(|k| format_ident!("a{}", k))
            .collect();
        let i = proc_macro2::Literal::usize_unsuffixed(hi);
        let i16 = proc_macro2::Literal::u16_suffixed(hi as u16);
        let count = quote! {
            self.call_counts[#i] = self.call_counts[#i].saturating_add(1);
            self.call_args.push((#i16, vec![#(#dv::ToValue::to_value(&#args)),*]));
        };
        if h.ret == Type::Unit {
            quote!(fn #id(&mut self, _: &Data #(, #args: #tys)*) { #count })
        } else {
            let ret = rust_type(names, &h.ret);
            quote!(fn #id(&mut self, _: &Data #(, #args: #tys)*) -> #ret { #count self.#id })
        }
    });
    let hook_count = proc_macro2::Literal::usize_unsuffixed(c.hooks.len());
    let hooks_default = if c.hooks.iter().all(|h| derivable_default(&h.ret)) {
        quote! {
            #[derive(Clone, Debug, Default, PartialEq)]
            pub struct ScriptedHooks {
                #(pub #hook_fields: #hook_tys,)*
                /// Calls of each hook since the last cycle's record.
                pub call_counts: [u32; #hook_count],
                /// Those calls' hook indices and arguments, in order.
                pub call_args: Vec<(u16, Vec<#dv::Value>)>,
            }
        }
    } else {
        let zeros = c.hooks.iter().map(|h| zero(names, &h.ret));
        quote! {
            #[derive(Clone, Debug, PartialEq)]
            pub struct ScriptedHooks {
                #(pub #hook_fields: #hook_tys,)*
                /// Calls of each hook since the last cycle's record.
                pub call_counts: [u32; #hook_count],
                /// Those calls' hook indices and arguments, in order.
                pub call_args: Vec<(u16, Vec<#dv::Value>)>,
            }
            impl Default for ScriptedHooks {
                fn default() -> Self { Self { #(#hook_fields: #zeros,)* call_counts: [0; #hook_count], call_args: Vec::new() } }
            }
        }
    };
    let hook_names = c.hooks.iter().map(|h| h.name.as_str());

    // ---- Driver: the controller's own wiring, plus the other ends of
    // its subordinates' buffers (the driver plays them).
    let Wiring {
        read_tys,
        read_names,
        read_handles,
        write_fields,
        write_names,
        sub_names,
        sub_modules,
        ..
    } = Wiring::new(ir, names, ci);
    let var_names: Vec<&str> = c.vars.iter().map(|v| v.name.as_str()).collect();
    let var_fields = &n.vars;
    let sub_cmd: Vec<_> = n.subs.iter().map(|f| prefixed("cmd", f)).collect();
    let sub_status: Vec<_> = n.subs.iter().map(|f| prefixed("status", f)).collect();
    let sub_idx: Vec<u16> = (0..c.subordinates.len() as u16).collect();
    let doc = format!(
        " `{}` alone on its own Global Memory, driven by name (`rcs_runtime::driver::Driven`): the caller plays its supervisor, its subordinates, its `reads` buffers and its hooks.",
        c.name
    );
    let sent_body = if c.subordinates.is_empty() {
        quote!(Vec::new())
    } else {
        quote! {{
            let mut sent = Vec::new();
            #(
                let now = self.#sub_cmd.read().value;
                if now.serial != before[#sub_idx as usize] {
                    let (verb, args) = #dv::DrivenCommand::parts(&now.command);
                    sent.push(#dv::Sent { sub: #sub_idx, verb, args, serial: now.serial });
                }
            )*
            sent
        }}
    };
    let bind_data = if c.vars.is_empty() && c.writes.is_empty() {
        quote!()
    } else {
        quote!(let data = c.data();)
    };
    let (hook_c, var_c) = (
        if c.hooks.is_empty() {
            quote!(_)
        } else {
            quote!(c)
        },
        if c.vars.is_empty() {
            quote!(_)
        } else {
            quote!(c)
        },
    );
    let before = if c.subordinates.is_empty() {
        quote!()
    } else {
        quote!(let before = [#(self.#sub_cmd.read().value.serial),*];)
    };
    let (subs_param, sub_match) = if c.subordinates.is_empty() {
        (quote!(_), quote!())
    } else {
        (
            quote!(status),
            // An echo without an epoch is in the epoch of the commands sent
            // (`Driven::write_sub_status`): scenarios name serials only.
            quote!(#(#sub_names => {
                let mut status = status;
                if status.echo_epoch == 0 {
                    status.echo_epoch = self.#sub_cmd.read().value.epoch;
                }
                if status.refused_serial != 0 && status.refused_epoch == 0 {
                    status.refused_epoch = self.#sub_cmd.read().value.epoch;
                }
                self.#sub_status.write(status, self.cycle);
                Ok(())
            })*),
        )
    };
    let sub_last = if c.subordinates.is_empty() {
        quote!()
    } else {
        quote!(#(#sub_names => Ok(self.#sub_cmd.read().value.serial),)*)
    };
    let (read_param, read_match) = if c.reads.is_empty() {
        (quote!(_), quote!())
    } else {
        (
            quote!(value),
            quote!(#(#read_names => {
                self.#read_handles.write(#dv::typed(NAME, buffer, value)?, self.cycle);
                Ok(())
            })*),
        )
    };
    let (hook_param, hook_match) = if c.hooks.is_empty() {
        (quote!(_), quote!())
    } else {
        (
            quote!(value),
            quote!(#(#hook_names => {
                c.hooks_mut().#hook_fields = #dv::typed(NAME, hook, value)?;
                Ok(())
            })*),
        )
    };

    let (var_param, var_match) = if c.vars.is_empty() {
        (quote!(_), quote!())
    } else {
        (
            quote!(value),
            quote!(#(#var_names => {
                c.data.vars.#var_fields = #dv::typed(NAME, var, value)?;
                Ok(())
            })*),
        )
    };
    let (write_param, write_match) = if c.writes.is_empty() {
        (quote!(_), quote!())
    } else {
        (
            quote!(value),
            quote!(#(#write_names => {
                self.controller.data.writes.#write_fields = #dv::typed(NAME, buffer, value)?;
                Ok(())
            })*),
        )
    };
    let (fields_handles, fields_inits, write_sub_field) =
        super::every_cycle::driver_parts(ir, names, ci);
    let var_match_body = by_name("var", "var", var_match);
    let write_match_body = by_name("buffer", "write buffer", write_match);
    let read_match_body = by_name("buffer", "read buffer", read_match);
    let hook_match_body = by_name("hook", "hook", hook_match);
    let sub_match_body = by_name("sub", "subordinate", sub_match);
    let sub_last_body = by_name("sub", "subordinate", sub_last);

    quote! {
        #command_impl

        /// Hooks that return what a scenario or test set (`Driven::set_hook`).
        #hooks_default
        impl Hooks for ScriptedHooks { #(#hook_fns)* }

        #[doc = #doc]
        #[derive(Debug)]
        pub struct Driver {
            controller: Controller<ScriptedHooks>,
            operator: rt::Operator<Command>,
            #(#read_handles: rt::Writer<#read_tys>,)*
            #(#sub_cmd: rt::Reader<rt::CommandBuffer<super::#sub_modules::Command>>,)*
            #(#sub_status: rt::Writer<rt::StatusBuffer>,)*
            #fields_handles
            cycle: u64,
        }

        impl Driver {
            /// A fresh controller: vars at their initialisers, every buffer zero.
            pub fn new() -> Result<Self, rt::SetupError> {
                let gm = rt::GlobalMemory::new();
                let controller = #new_controller;
                Ok(Self {
                    controller,
                    operator: rt::Operator::connect(&gm, NAME)?,
                    #(#read_handles: gm.writer(#read_names)?,)*
                    #(#sub_cmd: gm.command_reader(#sub_names)?,)*
                    #(#sub_status: gm.status_writer(#sub_names)?,)*
                    #fields_inits
                    cycle: 0,
                })
            }

            /// The controller underneath.
            pub fn controller(&self) -> &Controller<ScriptedHooks> {
                &self.controller
            }
        }

        impl #dv::Driven for Driver {
            fn name(&self) -> &str { NAME }

            fn command(&mut self, verb: &str, args: &[#dv::Value]) -> Result<u32, #dv::DriveError> {
                let command = #from_parts;
                Ok(self.operator.command(command))
            }

            fn set_read(&mut self, buffer: &str, #read_param: &#dv::Value) -> Result<(), #dv::DriveError> {
                #read_match_body
            }

            fn set_hook(&mut self, hook: &str, value: &#dv::Value) -> Result<(), #dv::DriveError> {
                driven_set_hook(&mut self.controller, hook, value)
            }

            fn set_var(&mut self, var: &str, value: &#dv::Value) -> Result<(), #dv::DriveError> {
                driven_set_var(&mut self.controller, var, value)
            }

            fn set_write(&mut self, buffer: &str, #write_param: &#dv::Value) -> Result<(), #dv::DriveError> {
                #write_match_body
            }

            fn write_sub_status(&mut self, sub: &str, #subs_param: rt::StatusBuffer) -> Result<(), #dv::DriveError> {
                #sub_match_body
            }

            fn last_sent(&mut self, sub: &str) -> Result<u32, #dv::DriveError> {
                #sub_last_body
            }

            #write_sub_field

            fn cycle(&mut self) -> #dv::Record {
                #before
                let ctx = rt::CycleContext {
                    cycle: self.cycle,
                    now: ::std::time::Instant::now(),
                    period: ::core::time::Duration::from_millis(1),
                };
                rt::Controller::cycle(&mut self.controller, &ctx);
                self.cycle += 1;
                let sent = #sent_body;
                driven_record(&mut self.controller, ctx.cycle, sent)
            }
        }

        /// Hook `hook` of `c` returns `value` from now on (`Driven::set_hook`;
        /// also what the `SystemDriver` of the plan set calls).
        pub fn driven_set_hook(#hook_c: &mut Controller<ScriptedHooks>, hook: &str, #hook_param: &#dv::Value) -> Result<(), #dv::DriveError> {
            #hook_match_body
        }

        /// Var `var` of `c` holds `value` (`Driven::set_var`).
        pub fn driven_set_var(#var_c: &mut Controller<ScriptedHooks>, var: &str, #var_param: &#dv::Value) -> Result<(), #dv::DriveError> {
            #var_match_body
        }

        /// The record of the cycle `c` just ran (its `cycle` number and the
        /// commands it `sent`), taking the hook calls it counted.
        pub fn driven_record(c: &mut Controller<ScriptedHooks>, cycle: u64, sent: Vec<#dv::Sent>) -> #dv::Record {
            let hook_calls = c.hooks().call_counts.to_vec();
            c.hooks_mut().call_counts = [0; #hook_count];
            let hook_args = ::std::mem::take(&mut c.hooks_mut().call_args);
            let bk = c.bookkeeping();
            #bind_data
            #dv::Record {
                cycle,
                verb: (bk.echo_serial() != 0).then_some(bk.verb()),
                fired: bk.fired(),
                state: bk.state(),
                status: bk.status(),
                error: bk.error(),
                echo_serial: bk.echo_serial(),
                refused_serial: bk.refused_serial(),
                sent,
                vars: vec![#(#dv::ToValue::to_value(&data.vars.#var_fields)),*],
                writes: vec![#(#dv::ToValue::to_value(&data.writes.#write_fields)),*],
                hook_calls,
                hook_args,
            }
        }
    }
}

/// `match name { arms…, _ => Err(unknown) }`, or just the error when
/// there are no arms (clippy refuses a match with only a wildcard).
fn by_name(scrutinee: &str, kind: &str, arms: TokenStream) -> TokenStream {
    let dv = dv();
    let name = format_ident!("{}", scrutinee);
    let fallback = quote!(Err(#dv::unknown(NAME, #kind, #name)));
    if arms.is_empty() {
        fallback
    } else {
        quote!(match #name { #arms _ => #fallback })
    }
}

/// `new_driver(name)` and `CONTROLLERS` at the plan set's top level.
pub(crate) fn set_driver(ir: &Ir, names: &Names) -> TokenStream {
    let dv = dv();
    let ctrl_names: Vec<&str> = ir.controllers.iter().map(|c| c.name.as_str()).collect();
    let modules = names.ctrls.iter().map(|n| &n.module);
    quote! {
        /// Every controller of the plan set, by name.
        pub const CONTROLLERS: &[&str] = &[#(#ctrl_names),*];

        /// A fresh [`Driven`](rt::driver::Driven) controller by name (`None`: no such controller).
        pub fn new_driver(controller: &str) -> Option<Result<Box<dyn #dv::Driven>, rt::SetupError>> {
            Some(match controller {
                #(#ctrl_names => #modules::Driver::new().map(|d| Box::new(d) as Box<dyn #dv::Driven>),)*
                _ => return None,
            })
        }
    }
}
