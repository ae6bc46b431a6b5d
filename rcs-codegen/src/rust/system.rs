//! The whole plan set → `System`: Global Memory with every buffer, one
//! executive per CPU of the schedule with its controllers in order, typed
//! handles for the external inputs, readers for the outputs and the
//! operator's handle on each root controller.

use super::names::Names;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use rcs_dsl::ir::Ir;

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
    let root_fields: Vec<_> = roots.iter().map(|c| &names.ctrls[*c].module).collect();
    let root_names: Vec<&str> = roots
        .iter()
        .map(|c| ir.controllers[*c].name.as_str())
        .collect();

    // One hooks argument per controller that has hooks.
    let hooked: Vec<usize> = (0..ir.controllers.len())
        .filter(|c| !ir.controllers[*c].hooks.is_empty())
        .collect();
    let hook_params: Vec<_> = hooked
        .iter()
        .map(|c| {
            format_ident!(
                "{}_hooks",
                names.ctrls[*c].module.to_string().trim_start_matches("r#")
            )
        })
        .collect();
    let hook_generics: Vec<_> = hooked.iter().map(|c| format_ident!("H{}", *c)).collect();
    let hook_bounds = hooked.iter().zip(&hook_generics).map(|(c, g)| {
        let m = &names.ctrls[*c].module;
        quote!(#g: #m::Hooks + 'static)
    });

    let executives = ir.schedule.iter().map(|cpu| {
        let name = &cpu.name;
        let period = cpu.period_ns;
        let adds = cpu.order.iter().map(|c| {
            let m = &names.ctrls[c.index()].module;
            let hooks = match hooked.iter().position(|h| *h == c.index()) {
                Some(i) => {
                    let p = &hook_params[i];
                    quote!(#p)
                }
                None => quote!(()),
            };
            quote!(exec.add(Box::new(#m::Controller::new(&gm, #hooks)?))?;)
        });
        quote! {{
            let mut exec = rt::Executive::new(rt::ExecutiveConfig::new(#name, ::core::time::Duration::from_nanos(#period)))?;
            #(#adds)*
            executives.push(exec);
        }}
    });
    let hooks_doc: Vec<String> = hooked
        .iter()
        .map(|c| {
            format!(
                " - `{}`: the hooks of `{}`",
                hook_params[hooked.iter().position(|h| h == c).unwrap_or(0)],
                ir.controllers[*c].name
            )
        })
        .collect();
    let system_doc = format!(
        " The `{}` system: Global Memory, its executives and the handles the outside world uses.",
        ir.system
    );

    quote! {
        /// Global Memory buffers no controller writes: sensor drivers and
        /// simulators write them through these handles (one writer each).
        #[derive(Debug)]
        pub struct Inputs { #(pub #in_fields: rt::Writer<#in_tys>),* }

        /// Readers of the buffers the controllers write, for actuators,
        /// simulators and displays.
        #[derive(Clone, Debug)]
        pub struct Outputs { #(pub #out_fields: rt::Reader<#out_tys>),* }

        /// The operator's handle on each root controller (§3.7): the only
        /// way in, through the root's command buffer.
        #[derive(Debug)]
        pub struct Operators { #(pub #root_fields: rt::Operator<#root_fields::Command>),* }

        #[doc = #system_doc]
        #[derive(Debug)]
        pub struct System {
            /// Global Memory, shared by every executive.
            pub gm: rt::GlobalMemory,
            /// One executive per CPU of the schedule, in schedule order.
            pub executives: Vec<rt::Executive>,
            pub inputs: Inputs,
            pub outputs: Outputs,
            pub operators: Operators,
        }

        impl System {
            /// Set up Global Memory and the executives. Hooks:
            #(#[doc = #hooks_doc])*
            pub fn new<#(#hook_bounds),*>(#(#hook_params: #hook_generics),*) -> Result<Self, rt::SetupError> {
                let gm = rt::GlobalMemory::new();
                #(gm.declare::<#all_tys>(#all_names)?;)*
                let mut executives = Vec::new();
                #(#executives)*
                Ok(Self {
                    inputs: Inputs { #(#in_fields: gm.writer(#in_names)?),* },
                    outputs: Outputs { #(#out_fields: gm.reader(#out_names)?),* },
                    operators: Operators { #(#root_fields: rt::Operator::connect(&gm, #root_names)?),* },
                    gm,
                    executives,
                })
            }

            /// Run `n` cycles as fast as possible on this thread, the
            /// executives interleaved cycle by cycle (tests and simulation).
            pub fn run_cycles(&mut self, n: u64) {
                for _ in 0..n {
                    for exec in &mut self.executives {
                        exec.step();
                    }
                }
            }
        }
    }
}
