//! The whole plan set → `System`: Global Memory with every buffer, one
//! executive per CPU of the schedule with its controllers in order, typed
//! handles for the external inputs, readers for the outputs and the
//! operator's handle on each root controller.

use super::names::Names;
use crate::ident::camel;
use proc_macro2::Ident;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use rcs_dsl::ir::Ir;
use rcs_dsl::placement::Placement;

pub(crate) fn system(ir: &Ir, names: &Names) -> TokenStream {
    // At the system module's top level the schemas are `types::X`.
    let ty_of = |b: usize| {
        let id = &names.buffers[ir.buffers[b].ty.index()].ty;
        quote!(types::#id)
    };
    let all_names: Vec<&str> = ir.buffers.iter().map(|b| b.name.as_str()).collect();
    let all_tys: Vec<TokenStream> = (0..ir.buffers.len()).map(ty_of).collect();
    let external: Vec<usize> = (0..ir.buffers.len())
        .filter(|b| ir.buffers[*b].writer.is_none())
        .collect();
    let written: Vec<usize> = (0..ir.buffers.len())
        .filter(|b| ir.buffers[*b].writer.is_some())
        .collect();
    // A buffer's docs: those of a `reads`/`writes` declaration of it, if
    // any has some (its writer's first), else its name and type.
    let buffer_doc = |b: usize| -> TokenStream {
        let declared = ir.buffers[b]
            .writer
            .iter()
            .chain(&ir.buffers[b].readers)
            .find_map(|c| {
                ir.controllers[c.index()]
                    .buffer_docs
                    .iter()
                    .find(|(x, _)| x.index() == b)
            });
        let lines: Vec<String> = match declared {
            Some((_, lines)) => lines.iter().map(|l| format!(" {l}")).collect(),
            None => vec![format!(
                " Buffer `{}` (`{}`).",
                ir.buffers[b].name,
                ir.buffer_types[ir.buffers[b].ty.index()].name
            )],
        };
        quote!(#(#[doc = #lines])*)
    };
    let in_docs: Vec<TokenStream> = external.iter().map(|b| buffer_doc(*b)).collect();
    let out_docs: Vec<TokenStream> = written.iter().map(|b| buffer_doc(*b)).collect();
    let in_fields: Vec<_> = external.iter().map(|b| &names.gm_buffers[*b]).collect();
    let in_tys: Vec<_> = external.iter().map(|b| ty_of(*b)).collect();
    let in_names: Vec<&str> = external
        .iter()
        .map(|b| ir.buffers[*b].name.as_str())
        .collect();
    let out_fields: Vec<_> = written.iter().map(|b| &names.gm_buffers[*b]).collect();
    let out_tys: Vec<_> = written.iter().map(|b| ty_of(*b)).collect();
    let out_names: Vec<&str> = written
        .iter()
        .map(|b| ir.buffers[*b].name.as_str())
        .collect();

    let roots: Vec<usize> = (0..ir.controllers.len())
        .filter(|c| ir.controllers[*c].supervisor.is_none())
        .collect();
    let root_docs: Vec<String> = roots
        .iter()
        .map(|c| {
            format!(
                " Commands `{}` and reads its status.",
                ir.controllers[*c].name
            )
        })
        .collect();
    let root_fields: Vec<_> = roots.iter().map(|c| &names.ctrls[*c].module).collect();
    let root_names: Vec<&str> = roots
        .iter()
        .map(|c| ir.controllers[*c].name.as_str())
        .collect();

    // One field of `Hooks`, and one type parameter, per controller that
    // has hooks: passed by name, so the order of files never matters.
    let hooked = hooked(ir);
    let hook_fields: Vec<&Ident> = hooked.iter().map(|c| &names.ctrls[*c].module).collect();
    let hook_generics: Vec<Ident> = hooked
        .iter()
        .map(|c| {
            format_ident!(
                "{}Hooks",
                camel(&names.ctrls[*c].module.to_string().replace("r#", ""))
            )
        })
        .collect();
    let hook_bounds: Vec<TokenStream> = hooked
        .iter()
        .zip(&hook_generics)
        .map(|(c, g)| {
            let m = &names.ctrls[*c].module;
            quote!(#g: #m::Hooks + 'static)
        })
        .collect();
    let hook_field_docs: Vec<String> = hooked
        .iter()
        .map(|c| format!(" The hooks of `{}`.", ir.controllers[*c].name))
        .collect();
    let generics = if hooked.is_empty() {
        quote!()
    } else {
        quote!(<#(#hook_generics),*>)
    };
    let bounds = if hooked.is_empty() {
        quote!()
    } else {
        quote!(<#(#hook_bounds),*>)
    };
    let hooks_param = if hooked.is_empty() {
        quote!(_hooks)
    } else {
        quote!(hooks)
    };
    // The hook type of each controller inside a `System`.
    let hooks_of = |c: usize| match hooked.iter().position(|h| *h == c) {
        Some(i) => {
            let g = &hook_generics[i];
            quote!(#g)
        }
        None => quote!(()),
    };

    // Each CPU's executive and its controllers in cycle order: a line of
    // `Setup` calls that never return early (`rcs_runtime::setup`).
    let executives: Vec<TokenStream> = ir
        .schedule
        .iter()
        .map(|cpu| {
            let name = &cpu.name;
            let period = cpu.period_ns;
            let adds = cpu.order.iter().map(|c| {
                let m = &names.ctrls[c.index()].module;
                let arg = if ir.controllers[c.index()].hooks.is_empty() {
                    quote!(())
                } else {
                    quote!(hooks.#m)
                };
                if names.ctrls[c.index()].shared {
                    quote!(setup.add(exec, #m::boxed(setup.gm(), #m::INSTANCE, #arg));)
                } else {
                    quote!(setup.add(exec, #m::boxed(setup.gm(), #arg));)
                }
            });
            quote! {{
                let exec = setup.executive(#name, #period);
                #(#adds)*
            }}
        })
        .collect();
    let system_doc = format!(
        " The `{}` system: Global Memory, its executives and the handles the outside world uses.",
        ir.system
    );
    let example = system_example(ir, names);
    let accessors = (0..ir.controllers.len()).map(|c| {
        let m = &names.ctrls[c].module;
        let base = accessor(m);
        let get = crate::ident::ident(&base);
        let get_mut = format_ident!("{base}_mut");
        let h = hooks_of(c);
        let name = &ir.controllers[c].name;
        let doc = format!(
            " `{name}`, typed: its data, hooks, status, verb and state. `None` while its executive is out of `executives` (taken to run on a thread)."
        );
        let doc_mut = format!(" `{name}`, typed and mutable (its hooks, between cycles)."); 
        quote! {
            #[doc = #doc]
            pub fn #get(&self) -> Option<&#m::Controller<#h>> {
                rt::Executive::find_as(&self.executives, #m::NAME)
            }
            #[doc = #doc_mut]
            pub fn #get_mut(&mut self) -> Option<&mut #m::Controller<#h>> {
                rt::Executive::find_as_mut(&mut self.executives, #m::NAME)
            }
        }
    });

    // A distributed set's process writes only some external inputs: the
    // others' writers are `None` there (`System::process`).
    let placement = Placement::of(ir);
    let distributed = placement.is_distributed();
    let (in_field_tys, in_inits): (Vec<TokenStream>, Vec<TokenStream>) = in_tys
        .iter()
        .zip(&in_names)
        .map(|(ty, name)| {
            if distributed {
                (
                    quote!(Option<rt::Writer<#ty>>),
                    quote!(Some(setup.writer(#name))),
                )
            } else {
                (quote!(rt::Writer<#ty>), quote!(setup.writer(#name)))
            }
        })
        .unzip();
    let buffer_count = all_names.len();
    let buffer_table = quote! {
        /// Every Global Memory buffer of the plan set, with its type.
        const BUFFERS: [rt::BufferDecl; #buffer_count] = [#(rt::BufferDecl::of::<#all_tys>(#all_names)),*];
    };
    let outputs = quote!(Outputs { #(#out_fields: setup.reader(#out_names)),* });
    let operators = quote!(Operators { #(#root_fields: setup.operator(#root_names)),* });
    let process_api = if distributed {
        super::process::process_api(
            ir,
            names,
            &placement,
            &super::process::Shared {
                executives: &executives,
                outputs: outputs.clone(),
                operators: operators.clone(),
                bounds: bounds.clone(),
                generics: generics.clone(),
                hooks_param: hooks_param.clone(),
            },
        )
    } else {
        quote!()
    };

    quote! {
        #buffer_table

        /// Global Memory buffers no controller writes: sensor drivers and
        /// simulators write them through these handles (one writer each).
        #[derive(Debug)]
        pub struct Inputs { #(#in_docs pub #in_fields: #in_field_tys),* }

        /// Readers of the buffers the controllers write, for actuators,
        /// simulators and displays.
        #[derive(Clone, Debug)]
        pub struct Outputs { #(#out_docs pub #out_fields: rt::Reader<#out_tys>),* }

        /// The operator's handle on each root controller (§3.7): the only
        /// way in, through the root's command buffer.
        #[derive(Debug)]
        pub struct Operators { #(#[doc = #root_docs] pub #root_fields: rt::Operator<#root_fields::Command>),* }

        /// The hand-written hooks of each controller that has some, by the
        /// controller's name: what [`System::new`] builds the controllers with.
        #[derive(Clone, Debug, Default)]
        pub struct Hooks #generics { #(#[doc = #hook_field_docs] pub #hook_fields: #hook_generics),* }

        #[doc = #system_doc]
        ///
        /// # Example
        ///
        /// ```ignore
        #(#[doc = #example])*
        /// ```
        #[derive(Debug)]
        pub struct System #generics {
            /// Global Memory, shared by every executive.
            pub gm: rt::GlobalMemory,
            /// One executive per CPU of the schedule, in schedule order.
            pub executives: Vec<rt::Executive>,
            /// Writers of the external inputs.
            pub inputs: Inputs,
            /// Readers of the buffers the controllers write.
            pub outputs: Outputs,
            /// The operator's handle on each root controller.
            pub operators: Operators,
            hooks: ::core::marker::PhantomData<fn() -> (#(#hook_generics,)*)>,
        }

        impl #bounds System #generics {
            /// Set up Global Memory and the executives, each controller with
            /// its hooks from `hooks`.
            pub fn new(#hooks_param: Hooks #generics) -> Result<Self, rt::SetupError> {
                let mut setup = rt::Setup::new(&BUFFERS);
                #(#executives)*
                let inputs = Inputs { #(#in_fields: #in_inits),* };
                let outputs = #outputs;
                let operators = #operators;
                let (gm, executives) = setup.finish()?;
                Ok(Self {
                    gm,
                    executives,
                    inputs,
                    outputs,
                    operators,
                    hooks: ::core::marker::PhantomData,
                })
            }

            #(#accessors)*

            /// Run `n` cycles as fast as possible on this thread, the
            /// executives interleaved cycle by cycle (tests and simulation).
            /// A controller that panics is contained (its plan ends with
            /// `HOOK_PANIC`, the others run on); all `n` cycles run and the
            /// panics are returned as the error.
            pub fn run_cycles(&mut self, n: u64) -> Result<(), rt::CycleFault> {
                let mut fault: Option<rt::CycleFault> = None;
                for _ in 0..n {
                    for exec in &mut self.executives {
                        if let Err(f) = exec.step() {
                            match &mut fault {
                                Some(first) => first.merge(f),
                                None => fault = Some(f),
                            }
                        }
                    }
                }
                match fault {
                    Some(f) => Err(f),
                    None => Ok(()),
                }
            }
        }

        #process_api
    }
}

/// The text of `System`'s rustdoc example, one line a `#[doc]`: build with
/// hooks by name, feed the inputs, command the root, run cycles, read an
/// output and each controller's state by name (the README's "Using the
/// generated code" walks through the same steps and is tested).
fn system_example(ir: &Ir, names: &Names) -> Vec<String> {
    let system = crate::ident::snake(&ir.system);
    let mut lines = vec![format!("rcs_runtime::include_plans!({:?});", ir.system)];
    lines.push(format!("use {system}::{{Hooks, System}};"));
    lines.push(String::new());
    let hooked = hooked(ir);
    if hooked.is_empty() {
        lines.push("let mut system = System::new(Hooks {})?;".into());
    } else {
        lines.push("let mut system = System::new(Hooks {".into());
        for c in &hooked {
            let m = names.ctrls[*c].module.to_string().replace("r#", "");
            lines.push(format!(
                "    {m}: my_{m}_hooks, // your `impl {system}::{m}::Hooks`"
            ));
        }
        lines.push("})?;".into());
    }
    for (b, buf) in ir.buffers.iter().enumerate() {
        if buf.writer.is_none() {
            let f = names.gm_buffers[b].to_string().replace("r#", "");
            let ty = &names.buffers[buf.ty.index()].ty;
            lines.push(format!(
                "system.inputs.{f}.write({system}::types::{ty}::default(), 0);"
            ));
        }
    }
    for (c, ctrl) in ir.controllers.iter().enumerate() {
        if ctrl.supervisor.is_none() {
            let m = names.ctrls[c].module.to_string().replace("r#", "");
            lines.push(format!(
                "system.operators.{m}.command({system}::{m}::Command::default());"
            ));
        }
    }
    lines.push("system.run_cycles(10)?;".into());
    if let Some((b, _)) = ir
        .buffers
        .iter()
        .enumerate()
        .find(|(_, b)| b.writer.is_some())
    {
        let f = names.gm_buffers[b].to_string().replace("r#", "");
        lines.push(format!("let {f} = system.outputs.{f}.read().value;"));
    }
    if let Some(c) = ir.controllers.first() {
        let m = accessor(&names.ctrls[0].module);
        lines.push(format!("if let Some({m}) = system.{m}() {{"));
        lines.push(format!(
            "    println!(\"{}: {{:?}} {{:?}} {{:?}}\", {m}.verb_name(), {m}.state_name(), {m}.status());",
            c.name
        ));
        lines.push("}".into());
    }
    lines.extend(
        [
            "",
            "// Timing: per executive, and per controller (nanoseconds).",
            "let exec = &system.executives[0];",
            "println!(\"{} cycles, {} overruns\", exec.stats().cycles, exec.overruns());",
            "",
            "// Real time: each executive on its own thread, on its heartbeat.",
            "let mut running = Vec::new();",
            "for exec in std::mem::take(&mut system.executives) {",
            "    running.push(exec.spawn()?);",
            "}",
            "std::thread::sleep(std::time::Duration::from_secs(1)); // write inputs, read outputs",
            "for (handle, join) in running {",
            "    handle.stop();",
            "    system.executives.push(join.join().expect(\"executive thread\"));",
            "}",
        ]
        .map(String::from),
    );
    lines.iter().map(|l| format!(" {l}")).collect()
}

/// The name of `System`'s accessor of the controller in module `module`:
/// the module's name, unless a method of `System` has it.
fn accessor(module: &Ident) -> String {
    let base = module.to_string().replace("r#", "");
    if ["new", "run_cycles", "process"].contains(&base.as_str()) {
        format!("{base}_controller")
    } else {
        base
    }
}

/// The controllers with hooks, by name: the fields and type parameters of
/// `Hooks` and `System` in this order, so that renaming or reordering the
/// plan set's files never changes them.
fn hooked(ir: &Ir) -> Vec<usize> {
    let mut hooked: Vec<usize> = (0..ir.controllers.len())
        .filter(|c| !ir.controllers[*c].hooks.is_empty())
        .collect();
    hooked.sort_by(|a, b| ir.controllers[*a].name.cmp(&ir.controllers[*b].name));
    hooked
}
