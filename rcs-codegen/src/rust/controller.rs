//! One controller → one Rust module: its command enum, status and error
//! enums, a state enum per plan, the `Hooks` trait, the `Data` it works on
//! and `Controller`, whose `cycle` is docs/semantics.md's six steps with the
//! rows compiled to a dispatch on the state.

use super::expr::{rust_type, zero, Gen};
use super::names::Names;
use super::plan::{plan_fn, used_params, uses_subs};
use super::shape::{shape, Shape, Wiring};
use super::Comments;
use crate::ident::prefixed;
use proc_macro2::TokenStream;
use quote::quote;
use rcs_dsl::ir::*;

pub(super) fn docs(lines: &[String]) -> TokenStream {
    let lines = lines.iter().map(|l| format!(" {l}"));
    quote!(#(#[doc = #lines])*)
}

/// Doc lines as a paragraph after a first line: a blank line, then them.
pub(super) fn paragraph(lines: &[String]) -> TokenStream {
    if lines.is_empty() {
        return TokenStream::new();
    }
    let d = docs(lines);
    quote!(#[doc = ""] #d)
}

/// Whether `Default` can be derived for a type (std has it for arrays up to 32).
pub(crate) fn derivable_default(t: &Type) -> bool {
    match t {
        Type::Array(elem, n) => *n <= 32 && derivable_default(elem),
        _ => true,
    }
}

pub(crate) fn is_zero(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Int(0) | ExprKind::Bool(false) => true,
        ExprKind::Float(v) => *v == 0.0 && v.is_sign_positive(),
        ExprKind::Variant(_, 0) => true,
        _ => false,
    }
}

/// A controller type's shared module (LANGUAGE.md §8): generated from
/// its first instance, every name in Global Memory and every parameter
/// read from an `Instance` value.
pub(crate) struct TypeModule<'a> {
    pub ty: &'a str,
    pub group: &'a super::instances::Group,
}

/// `extra`: more items for the module (the scenario driver). `shared`:
/// generate the module of the type controller `ci` is the first instance
/// of, rather than `ci`'s own.
pub(crate) fn module(
    ir: &Ir,
    names: &Names,
    ci: usize,
    comments: &mut Comments,
    extra: TokenStream,
    shared: Option<&TypeModule>,
) -> TokenStream {
    let c = &ir.controllers[ci];
    let n = &names.ctrls[ci];
    let name = shared.map_or(c.name.as_str(), |t| t.ty);
    let module = &n.module;
    // The controller's doc comment, which usually names it already; the
    // title line only stands in for a missing one.
    let mod_docs = if c.docs.is_empty() {
        let title = c
            .title
            .as_ref()
            .map(|t| format!(" `{name}`: {t}."))
            .unwrap_or_else(|| format!(" Controller `{name}`."));
        quote!(#[doc = #title])
    } else {
        docs(&c.docs)
    };

    // ---- commands
    let verb_count = c.commands.len();
    let no_commands_doc = format!(" `{name}` accepts no commands.");
    let command_enum = if c.commands.is_empty() {
        let wire = super::schema::derives(names);
        let schema = super::schema::schema_impl(
            names,
            &quote!(Command),
            &format!("command {name}{{}}"),
            &[],
        );
        quote! {
            #[doc = #no_commands_doc]
            #wire
            #[derive(Clone, Copy, Debug, Default, PartialEq)]
            pub struct Command;
            #schema
            impl rt::Command for Command {
                fn verb(&self) -> rt::VerbId { 0 }
            }
        }
    } else {
        // `#[default]` only works on a unit variant; otherwise the first
        // verb with zero parameters is the default, written out.
        let unit_first = c.commands[0].params.is_empty();
        let variants = c.commands.iter().enumerate().map(|(i, k)| {
            let v = &n.commands[i];
            let d = docs(&k.docs);
            let default = if i == 0 && unit_first {
                quote!(#[default])
            } else {
                quote!()
            };
            if k.params.is_empty() {
                quote!(#d #default #v)
            } else {
                let ps = &n.params[i];
                let tys = k.params.iter().map(|p| rust_type(names, &p.ty));
                let pdocs = k.params.iter().map(|p| docs(&p.docs));
                // Only a distributed set's commands derive serde.
                let withs = k.params.iter().map(|p| {
                    if names.wire {
                        super::types::serde_with(names, &p.ty, None)
                    } else {
                        quote!()
                    }
                });
                quote!(#d #default #v { #(#pdocs #withs #ps: #tys),* })
            }
        });
        let arms = c.commands.iter().enumerate().map(|(i, k)| {
            let v = &n.commands[i];
            let i = i as u16;
            if k.params.is_empty() {
                quote!(Self::#v => #i)
            } else {
                quote!(Self::#v { .. } => #i)
            }
        });
        let cmd_doc = format!(" The command verbs of `{name}`, with their parameters.");
        let (derive_default, default_impl) = if unit_first {
            (quote!(Default,), quote!())
        } else {
            let v = &n.commands[0];
            let ps = &n.params[0];
            let zeros = c.commands[0].params.iter().map(|p| zero(names, &p.ty));
            (
                quote!(),
                quote! {
                    impl Default for Command {
                        fn default() -> Self { Self::#v { #(#ps: #zeros),* } }
                    }
                },
            )
        };
        let wire = super::schema::derives(names);
        let param_tys: Vec<TokenStream> = c
            .commands
            .iter()
            .flat_map(|k| k.params.iter().map(|p| rust_type(names, &p.ty)))
            .collect();
        let structure = format!(
            "command {name}{{{}}}",
            c.commands
                .iter()
                .map(|k| format!(
                    "{}({})",
                    k.name,
                    k.params
                        .iter()
                        .map(|p| format!("{}:{}", p.name, rust_type(names, &p.ty)))
                        .collect::<Vec<_>>()
                        .join(",")
                ))
                .collect::<Vec<_>>()
                .join(",")
        );
        let schema = super::schema::schema_impl(names, &quote!(Command), &structure, &param_tys);
        quote! {
            #[doc = #cmd_doc]
            #wire
            #[derive(Clone, Copy, Debug, #derive_default PartialEq)]
            pub enum Command { #(#variants),* }
            #default_impl
            #schema
            impl rt::Command for Command {
                fn verb(&self) -> rt::VerbId {
                    match self { #(#arms),* }
                }
            }
        }
    };

    // ---- statuses and errors
    let codes = super::codes::codes(names, ci, c, name);

    // ---- plan state enums
    let state_enums = c.plans.iter().enumerate().map(|(pi, p)| {
        let pn = &n.plans[pi];
        let ty = &pn.state_ty;
        let vs = &pn.states;
        let ids: Vec<u16> = (0..p.states.len() as u16).collect();
        let doc = format!(" The states of plan `{}`.", c.plan_title(p));
        let plan_docs = paragraph(&p.docs);
        let state_names: Vec<&str> = p.states.iter().map(|s| s.name.as_str()).collect();
        quote! {
            #[doc = #doc] #plan_docs
            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub enum #ty { #(#vs),* }
            impl #ty {
                /// The state with this runtime id.
                pub const fn from_raw(raw: rt::StateId) -> Option<Self> {
                    match raw { #(#ids => Some(Self::#vs),)* _ => None }
                }
                /// The runtime id of this state.
                pub const fn raw(self) -> rt::StateId {
                    match self { #(Self::#vs => #ids),* }
                }
                /// The state's name in the plan.
                pub const fn name(self) -> &'static str {
                    match self { #(Self::#vs => #state_names),* }
                }
            }
        }
    });

    // ---- verb and state names: tables, looked up by one runtime
    // function for every controller (issue 30)
    let verb_names: Vec<&str> = c.commands.iter().map(|k| k.name.as_str()).collect();
    let plan_state_names = c.commands.iter().map(|k| {
        let states = k
            .plan
            .map(|pid| {
                c.plans[pid.index()]
                    .states
                    .iter()
                    .map(|s| s.name.as_str())
                    .collect()
            })
            .unwrap_or_else(Vec::new);
        quote!(&[#(#states),*])
    });
    let verbs = proc_macro2::Literal::usize_unsuffixed(verb_count);
    let names_fns = quote! {
        /// Each verb's name, by verb id.
        const VERB_NAMES: [&str; #verbs] = [#(#verb_names),*];
        /// Each verb's plan's state names, by verb id and state id.
        const STATE_NAMES: [&[&str]; #verbs] = [#(#plan_state_names),*];
        /// The name of a verb of this controller's, as written in the plans.
        pub const fn verb_name(verb: rt::VerbId) -> Option<&'static str> {
            rt::builtin::name_at(&VERB_NAMES, verb)
        }
        /// The name of a state of a verb's plan, as written in the plans.
        pub const fn state_name(verb: rt::VerbId, state: rt::StateId) -> Option<&'static str> {
            rt::builtin::state_name_at(&STATE_NAMES, verb, state)
        }
    };

    // ---- hooks
    let hook_fns = c.hooks.iter().enumerate().map(|(hi, h)| {
        let id = &n.hooks[hi];
        let ps = &n.hook_params[hi];
        let tys = h.params.iter().map(|p| rust_type(names, &p.ty));
        // Parameters cannot carry docs in Rust: theirs follow the hook's.
        let mut lines = h.docs.clone();
        let documented: Vec<&Param> = h.params.iter().filter(|p| !p.docs.is_empty()).collect();
        if !documented.is_empty() {
            if !lines.is_empty() {
                lines.push(String::new());
            }
            lines.push("Parameters:".into());
            for p in documented {
                lines.push(format!("- `{}`: {}", p.name, p.docs.join(" ")));
            }
        }
        let d = docs(&lines);
        if h.ret == Type::Unit {
            quote!(#d fn #id(&mut self, data: &Data #(, #ps: #tys)*);)
        } else {
            let ret = rust_type(names, &h.ret);
            quote!(#d fn #id(&mut self, data: &Data #(, #ps: #tys)*) -> #ret;)
        }
    });
    let unit_hooks = if c.hooks.is_empty() {
        quote!(impl Hooks for () {})
    } else {
        quote!()
    };
    let hooks_doc = format!(
        " The hand-written sensory-processing and world-model functions of `{name}`. Each sees the controller's current data read-only."
    );

    // ---- data
    let Wiring {
        read_fields,
        read_tys,
        read_names,
        read_handles,
        write_fields,
        write_tys,
        write_names,
        write_handles,
        sub_names,
        sub_modules,
        sub_handles,
    } = match shared {
        Some(_) => Wiring::new(ir, names, ci).of_instance(&quote!(inst)),
        None => Wiring::new(ir, names, ci),
    };
    let watch = super::watchdog::Watches::new(c, &read_fields, &read_handles);
    let (watch_fields, read_stmts) = (&watch.fields, &watch.reads);
    // A `reads`/`writes` declaration's doc comment, else the buffer's name.
    let buffer_docs = |list: &[BufferId]| -> Vec<TokenStream> {
        list.iter()
            .map(|b| match c.buffer_docs.iter().find(|(x, _)| x == b) {
                Some((_, lines)) => docs(lines),
                None => {
                    let d = format!(" Global Memory buffer `{}`.", ir.buffers[b.index()].name);
                    quote!(#[doc = #d])
                }
            })
            .collect()
    };
    let read_docs = buffer_docs(&c.reads);
    let write_docs = buffer_docs(&c.writes);
    let sub_fields = &n.subs;
    let var_fields = &n.vars;
    let var_tys: Vec<_> = c.vars.iter().map(|v| rust_type(names, &v.ty)).collect();
    let var_docs: Vec<_> = c.vars.iter().map(|v| docs(&v.docs)).collect();
    let const_gen = Gen::new(ir, names, ci);
    let var_defaults_derivable = c
        .vars
        .iter()
        .all(|v| derivable_default(&v.ty) && v.init.as_ref().is_none_or(is_zero));
    // A type's shared module: `Default` with the first instance's values
    // (for `Data::default`), and each instance's own in `Vars::for_instance`.
    // Built only when needed: a `Names` holds every controller's names, so
    // a copy per controller would make generation quadratic in the set.
    let first;
    let (vars_derive, mut vars_default) = if var_defaults_derivable {
        (quote!(Default,), quote!())
    } else {
        let gen = if shared.is_some() {
            first = Names {
                slots: None,
                ..names.clone()
            };
            Gen::new(ir, &first, ci)
        } else {
            const_gen
        };
        let inits = c.vars.iter().map(|v| match &v.init {
            Some(e) => gen.expr(e).ts,
            None => zero(names, &v.ty),
        });
        (
            quote!(),
            quote! {
                impl Default for Vars {
                    fn default() -> Self {
                        Self { #(#var_fields: #inits),* }
                    }
                }
            },
        )
    };

    let vars_for_instance = shared.is_some()
        && names.slots.as_ref().is_some_and(|slots| {
            c.vars.iter().filter_map(|v| v.init.as_ref()).any(|e| {
                let mut found = false;
                e.visit(&mut |x| found |= slots.slot_of.contains_key(&(x as *const Expr as usize)));
                found
            })
        });
    if vars_for_instance {
        let per_instance = Names {
            slots: names.slots.clone().map(|mut s| {
                s.prefix = quote!(inst.params);
                s
            }),
            ..names.clone()
        };
        let gen = Gen::new(ir, &per_instance, ci);
        let inits = c.vars.iter().map(|v| match &v.init {
            Some(e) => gen.expr(e).ts,
            None => zero(names, &v.ty),
        });
        vars_default.extend(quote! {
            impl Vars {
                /// The variables at an instance's initialisers.
                pub fn for_instance(inst: &Instance) -> Self {
                    Self { #(#var_fields: #inits),* }
                }
            }
        });
    }

    // ---- plans
    let plan_fns: Vec<TokenStream> = c
        .plans
        .iter()
        .enumerate()
        .map(|(pi, p)| plan_fn(ir, names, ci, pi, p, comments))
        .collect();
    let decide_arms = c.commands.iter().enumerate().filter_map(|(i, k)| {
        let pid = k.plan?;
        let func = &n.plans[pid.index()].func;
        let v = &n.commands[i];
        let used = used_params(c, &c.plans[pid.index()]);
        let binds: Vec<TokenStream> = k
            .params
            .iter()
            .enumerate()
            .filter(|(pi, _)| used.contains(&ParamId(*pi as u32)))
            .map(|(pi, _)| {
                let field = &n.params[i][pi];
                let local = prefixed("cmd", field);
                quote!(#field: #local)
            })
            .collect();
        let locals: Vec<TokenStream> = k
            .params
            .iter()
            .enumerate()
            .filter(|(pi, _)| used.contains(&ParamId(*pi as u32)))
            .map(|(pi, _)| {
                let local = prefixed("cmd", &n.params[i][pi]);
                quote!(#local)
            })
            .collect();
        let subs_arg = if uses_subs(&c.plans[pid.index()]) {
            quote!(subs)
        } else {
            quote!()
        };
        let sep = if uses_subs(&c.plans[pid.index()]) && !locals.is_empty() {
            quote!(,)
        } else {
            quote!()
        };
        Some(if k.params.is_empty() {
            quote!(Command::#v => self.#func(#subs_arg))
        } else {
            quote!(Command::#v { #(#binds,)* .. } => self.#func(#subs_arg #sep #(#locals),*))
        })
    });
    // The timing report's count of stale echoes, per subordinate.
    let old_echoes = if sub_handles.is_empty() {
        quote!()
    } else {
        let sub_names: Vec<TokenStream> = match shared {
            Some(_) => (0..sub_handles.len())
                .map(|k| {
                    let k = proc_macro2::Literal::usize_unsuffixed(k);
                    quote!(self.inst.subs[#k])
                })
                .collect(),
            None => sub_names.clone(),
        };
        quote! {
            fn old_echoes(&self, f: &mut dyn FnMut(&str, u64)) {
                #(f(#sub_names, self.#sub_handles.link().old_echoes());)*
            }
        }
    };
    let any_subs = c.plans.iter().any(uses_subs);
    let subs_param = if any_subs {
        quote!(subs)
    } else {
        quote!(_subs)
    };
    let decide = if c.commands.is_empty() {
        quote!(
            fn decide(&mut self) {}
        )
    } else {
        quote! {
            /// Step 4: the plan of the active command picks at most one row.
            fn decide(&mut self, #subs_param: Subs) {
                match self.data.command { #(#decide_arms,)* }
            }
        }
    };

    let super::every_cycle::Parts {
        items: every_cycle_items,
        data_field: sub_fields_data,
        handles: every_cycle_handles,
        declares: every_cycle_declares,
        inits: every_cycle_inits,
        read: sub_fields_read,
        pre: pre_jobs,
        post: post_jobs,
        write: status_fields_write,
    } = super::every_cycle::parts(ir, names, ci, comments, shared.is_some());
    let (decide_call, post_call) = super::index::cycle_steps(&ir.controllers[ci], post_jobs);
    // Step 3 and 3b: a controller that may refuse a command judges it after
    // `pre` and puts everything back if it refuses (`accept`).
    let (accept_method, step3_and_pre) = match super::accept::refusal(ir, names, ci, &pre_jobs) {
        Some(r) => (r.method, r.cycle),
        None => (
            quote!(),
            quote! {
                if self.bk.new_command() {
                    self.data.command = command.command;
                }
                #pre_jobs
            },
        ),
    };

    let verb_count_lit = proc_macro2::Literal::usize_unsuffixed(verb_count);
    // The six steps of a cycle (docs/semantics.md), as comments in the output.
    let step1 = comments.marker(
        "1. Read: the command, every read buffer and every subordinate's status, once.".to_string(),
    );
    let step2 = comments.marker(
        "2. Handshake view of each subordinate; rows read this local copy, hooks see `data.subs`."
            .to_string(),
    );
    let step3 = comments.marker("3. A new serial starts the plan of its verb in S0.".to_string());
    let step4 = comments.marker("4. Decide: the active plan fires at most one row.".to_string());
    let step5 =
        comments.marker("5. Write: status, written buffers, commands sent this cycle.".to_string());
    let step6 = comments.marker("6. Account: state and plan cycle counters, timing.".to_string());

    let Shape {
        head,
        vis,
        inst_field,
        inst_param,
        inst_init,
        gm_name,
        self_name,
        data_init,
    } = shape(names, c, name, shared, vars_for_instance);
    let inst_arg = if shared.is_some() {
        quote!(inst,)
    } else {
        quote!()
    };
    let reads_record = record(
        " The Global Memory buffers this controller reads, as copied in this cycle.",
        quote!(Reads),
        quote!(#(#read_docs pub #read_fields: #read_tys),*),
        read_fields.is_empty(),
    );
    let writes_record = record(
        " The Global Memory buffers this controller alone writes.",
        quote!(Writes),
        quote!(#(#write_docs pub #write_fields: #write_tys),*),
        write_fields.is_empty(),
    );
    let subs_record = record(
        " The subordinates' statuses, seen through the handshake.",
        quote!(Subs),
        quote!(#(pub #sub_fields: rt::SubordinateView),*),
        sub_fields.is_empty(),
    );
    quote! {
        #mod_docs
        pub mod #module {
            use ::rcs_runtime as rt;

            #head

            #command_enum

            #names_fns

            #codes

            #(#state_enums)*

            #[doc = #hooks_doc]
            pub trait Hooks: Send { #(#hook_fns)* }
            #unit_hooks

            #reads_record

            #writes_record

            #subs_record

            /// The controller's own world-model variables; they persist across cycles.
            #[derive(Clone, Copy, Debug, #vars_derive PartialEq)]
            pub struct Vars { #(#var_docs pub #var_fields: #var_tys),* }
            #vars_default

            #every_cycle_items

            /// Everything a cycle works on. Hooks see it read-only.
            #[derive(Clone, Copy, Debug, Default, PartialEq)]
            pub struct Data {
                /// The command being executed.
                pub command: Command,
                /// The buffers read, copied in at the start of the cycle.
                pub reads: Reads,
                /// The subordinates' statuses this cycle.
                pub subs: Subs,
                /// The world-model variables.
                pub vars: Vars,
                /// The buffers written, copied out at the end of the cycle.
                pub writes: Writes,
                #sub_fields_data
            }

            /// The controller: its data, its plans' bookkeeping and its Global Memory handles.
            #[derive(Debug)]
            pub struct Controller<H: Hooks> {
                #vis hooks: H,
                #vis data: Data,
                bk: rt::Bookkeeping,
                #inst_field
                command_in: rt::Reader<rt::CommandBuffer<Command>>,
                status_out: rt::Writer<rt::StatusBuffer>,
                #(#read_handles: rt::Reader<#read_tys>,)*
                #(#watch_fields: rt::BufferWatch,)*
                #(#write_handles: rt::Writer<#write_tys>,)*
                #(#sub_handles: rt::Subordinate<super::#sub_modules::Command>,)*
                #every_cycle_handles
            }

            impl<H: Hooks> Controller<H> {
                /// Connect to Global Memory: this controller's command and
                /// status buffers, its buffers, and its subordinates' command
                /// buffers (taking their one writer).
                pub fn new(gm: &rt::GlobalMemory, #inst_param hooks: H) -> Result<Self, rt::SetupError> {
                    // Every step runs (a failed one gives a stand-in handle);
                    // `finish` returns the errors: one exit, not one per handle.
                    let mut ports = rt::Ports::new(gm);
                    ports.declare_controller::<Command>(#gm_name);
                    #(ports.declare::<#read_tys>(#read_names);)*
                    #(ports.declare::<#write_tys>(#write_names);)*
                    #every_cycle_declares
                    let controller = Self {
                        hooks,
                        data: #data_init,
                        bk: rt::Bookkeeping::new(#verb_count_lit),
                        command_in: ports.command_reader(#gm_name),
                        status_out: ports.status_writer(#gm_name),
                        #inst_init
                        #(#read_handles: ports.reader(#read_names),)*
                        #(#watch_fields: rt::BufferWatch::new(),)*
                        #(#write_handles: ports.writer(#write_names),)*
                        #(#sub_handles: ports.subordinate(#sub_names),)*
                        #every_cycle_inits
                    };
                    ports.finish()?;
                    Ok(controller)
                }

                /// The data of the last cycle.
                pub fn data(&self) -> &Data { &self.data }
                /// The hooks.
                pub fn hooks(&self) -> &H { &self.hooks }
                /// The hooks, to adjust hand-written state between cycles.
                pub fn hooks_mut(&mut self) -> &mut H { &mut self.hooks }
                /// The plan bookkeeping: verb, state, status, counters, fired row.
                pub fn bookkeeping(&self) -> &rt::Bookkeeping { &self.bk }
                /// The current status, typed.
                pub fn status(&self) -> Option<Status> { Status::from_raw(self.bk.status()) }
                /// The verb being executed, by name (`None` before the first command).
                pub fn verb_name(&self) -> Option<&'static str> {
                    if self.bk.echo_serial() == 0 { None } else { verb_name(self.bk.verb()) }
                }
                /// The state of the plan being executed, by name (`None` before the first command).
                pub fn state_name(&self) -> Option<&'static str> {
                    if self.bk.echo_serial() == 0 { None } else { state_name(self.bk.verb(), self.bk.state()) }
                }

                /// Step 5: the status, the written buffers and the commands sent
                /// this cycle (also after a fault, so that the supervisor sees it).
                fn publish(&mut self, ctx: &rt::CycleContext) {
                    self.status_out.write(self.bk.status_buffer(), ctx.cycle);
                    #status_fields_write
                    #(self.#write_handles.write(self.data.writes.#write_fields, ctx.cycle);)*
                    #(self.#sub_handles.flush(ctx.cycle);)*
                }

                #decide
                #accept_method

                #(#plan_fns)*
            }

            /// [`Controller::new`], boxed for an executive: `System::new`'s
            /// step for this controller. Out of line and cold, so that a plan
            /// set's setup code grows with its controllers, not their square.
            #[cold]
            #[inline(never)]
            pub fn boxed<H: Hooks + 'static>(gm: &rt::GlobalMemory, #inst_param hooks: H) -> Result<Box<dyn rt::Controller>, rt::SetupError> {
                Ok(Box::new(Controller::new(gm, #inst_arg hooks)?))
            }

            impl<H: Hooks + 'static> rt::Controller for Controller<H> {
                fn name(&self) -> &str { #self_name }

                fn cycle(&mut self, ctx: &rt::CycleContext) {
                    #step1
                    let command = self.command_in.read().value;
                    #(#read_stmts)*
                    #sub_fields_read
                    #step2
                    let subs = Subs { #(#sub_fields: self.#sub_handles.read()),* };
                    self.data.subs = subs;
                    #step3
                    self.bk.begin_cycle(ctx.tick(), &command, true);
                    #step3_and_pre
                    #step4
                    #decide_call
                    #post_call
                    #step5
                    self.publish(ctx);
                    #step6
                    self.bk.end_cycle();
                }

                fn fault(&mut self, code: rt::ErrorCode, ctx: &rt::CycleContext) {
                    // The cycle was cut short (a hook panicked): end the plan with
                    // `code`, then steps 5 and 6 as the cycle would have.
                    self.bk.fault(code);
                    self.publish(ctx);
                    self.bk.end_cycle();
                }

                fn bookkeeping(&self) -> Option<&rt::Bookkeeping> { Some(&self.bk) }

                #old_echoes
            }

            #extra
        }
    }
}

/// A record of the controller's data (`Reads`, `Writes`, `Subs`): a struct
/// with the usual derives, or, with no fields, the runtime's one empty
/// record (issue 30: five derived impls less per controller).
fn record(doc: &str, name: TokenStream, fields: TokenStream, empty: bool) -> TokenStream {
    if empty {
        quote! {
            #[doc = #doc]
            pub type #name = rt::builtin::NoFields;
        }
    } else {
        quote! {
            #[doc = #doc]
            #[derive(Clone, Copy, Debug, Default, PartialEq)]
            pub struct #name { #fields }
        }
    }
}
