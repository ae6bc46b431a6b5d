//! A distributed plan set (its manifest places CPUs in more than one
//! process) → `PROCESSES` and `System::process`: set up one process's CPUs
//! with every buffer declared locally, and a Zenoh bridge
//! (`rcs_runtime::Bridge`, feature `zenoh` of the user's `rcs-runtime`)
//! exporting the buffers this process writes and others read, importing
//! those others write and this process reads. Which buffers cross comes
//! from `rcs_dsl::placement`. Every executive of the process gets the
//! bridge's cycle signal, so a cycle's writes are published when the cycle
//! ends rather than when a poll comes by. Nothing here is emitted for a
//! single-process set: its code does not mention Zenoh, so it builds
//! without the feature.

use proc_macro2::TokenStream;
use quote::quote;
use rcs_dsl::ir::Ir;
use rcs_dsl::placement::{BufferKind, Placement};

use super::names::Names;

/// The pieces of `System::new` that `System::process` shares.
pub(crate) struct Shared<'a> {
    /// `gm.declare::<T>(name)?;` for every `reads`/`writes` buffer.
    pub declare_all: TokenStream,
    /// `executives[i]`: build CPU `i`'s executive and push it.
    pub executives: &'a [TokenStream],
    /// The `Outputs { … }` and `Operators { … }` expressions.
    pub outputs: TokenStream,
    pub operators: TokenStream,
    /// `impl` bounds, `System`'s generics, the hooks parameter's name.
    pub bounds: TokenStream,
    pub generics: TokenStream,
    pub hooks_param: TokenStream,
}

pub(crate) fn process_api(
    ir: &Ir,
    names: &Names,
    placement: &Placement,
    sh: &Shared,
) -> TokenStream {
    let executives = sh.executives;
    let processes = &placement.processes;
    let count = processes.len();
    // Each crossing buffer: its type and its Global Memory name.
    let crossings: Vec<(TokenStream, TokenStream)> = placement
        .crossings
        .iter()
        .map(|x| match &x.kind {
            BufferKind::Declared(b) => {
                let ty = &names.buffers[ir.buffers[b.index()].ty.index()].ty;
                let name = ir.buffers[b.index()].name.as_str();
                (quote!(types::#ty), quote!(#name))
            }
            BufferKind::Command(c) => {
                let m = &names.ctrls[c.index()].module;
                (
                    quote!(rt::CommandBuffer<#m::Command>),
                    quote!(&rt::command_buffer_name(#m::NAME)),
                )
            }
            BufferKind::Status(c) => {
                let m = &names.ctrls[c.index()].module;
                (
                    quote!(rt::StatusBuffer),
                    quote!(&rt::status_buffer_name(#m::NAME)),
                )
            }
            BufferKind::StatusFields(c) => {
                let m = &names.ctrls[c.index()].module;
                (
                    quote!(#m::StatusFields),
                    quote!(&rt::status_fields_buffer_name(#m::NAME)),
                )
            }
        })
        .collect();
    // Every controller's command and status buffers exist in every
    // process (the operator handles connect to each root's), and every
    // crossing buffer, for the bridge.
    let modules: Vec<_> = names.ctrls.iter().map(|c| &c.module).collect();
    let (cross_tys, cross_names): (Vec<_>, Vec<_>) = crossings.iter().cloned().unzip();
    let declares = quote! {
        #(gm.declare_controller::<#modules::Command>(#modules::NAME)?;)*
        #(gm.declare::<#cross_tys>(#cross_names)?;)*
    };
    let arms = processes.iter().enumerate().map(|(p, process)| {
        let cpus = executives
            .iter()
            .zip(&placement.cpu_process)
            .filter(|(_, cp)| **cp == p)
            .map(|(e, _)| e);
        let bridged = placement
            .crossings
            .iter()
            .zip(&crossings)
            .filter_map(|(x, (ty, name))| {
                if x.writer == p {
                    Some(quote!(bridge.export::<#ty>(#name)?;))
                } else if x.readers.contains(&p) {
                    Some(quote!(bridge.import::<#ty>(#name)?;))
                } else {
                    None
                }
            });
        quote! {
            #process => {
                #[allow(unused_mut)]
                let mut bridge = rt::Bridge::builder(config, &gm);
                #(#bridged)*
                #(#cpus)*
                bridge.start()?
            }
        }
    });
    let inputs = ir
        .buffers
        .iter()
        .enumerate()
        .filter(|(_, b)| b.writer.is_none())
        .map(|(b, buf)| {
            let f = &names.gm_buffers[b];
            let name = buf.name.as_str();
            match placement.input_process(ir, rcs_dsl::ir::BufferId(b as u32)) {
                Some(p) => {
                    let process = processes[p].as_str();
                    quote!(#f: if process == #process { Some(gm.writer(#name)?) } else { None })
                }
                None => quote!(#f: Some(gm.writer(#name)?)),
            }
        });
    let Shared {
        declare_all,
        outputs,
        operators,
        bounds,
        generics,
        hooks_param,
        ..
    } = sh;
    quote! {
        /// The processes of this plan set (the manifest's `process:`), in
        /// the order the schedule names them.
        pub const PROCESSES: [&str; #count] = [#(#processes),*];

        impl #bounds System #generics {
            /// Set up process `process` only (one of [`PROCESSES`]): every
            /// buffer declared in a Global Memory of its own, the executives
            /// of this process's CPUs, and a Zenoh bridge carrying the
            /// buffers whose writer and readers sit in different processes
            /// (`docs/distribution.md`). Needs `rcs-runtime`'s feature
            /// `zenoh`. `inputs` holds the writers of the external inputs
            /// this process writes (`inputs:` in the manifest), `None` for
            /// the others; `operators` command roots that run here.
            /// Every executive raises the bridge's signal after each cycle,
            /// so the buffers it wrote leave at once; inputs written outside
            /// the executives leave with the next cycle, the bridge's
            /// fallback poll (`config.poll_period`), or at once if the
            /// writer raises `bridge.signal()`.
            pub fn process(
                process: &str,
                config: rt::BridgeConfig,
                #hooks_param: Hooks #generics,
            ) -> Result<(Self, rt::Bridge), rt::BridgeError> {
                let gm = rt::GlobalMemory::new();
                #declare_all
                #declares
                let mut executives = Vec::new();
                let bridge = match process {
                    #(#arms)*
                    _ => {
                        return Err(rt::BridgeError::UnknownProcess {
                            name: process.to_owned(),
                            known: PROCESSES.iter().map(|p| p.to_string()).collect(),
                        })
                    }
                };
                for exec in &mut executives {
                    exec.set_cycle_signal(bridge.signal());
                }
                let system = Self {
                    inputs: Inputs { #(#inputs),* },
                    outputs: #outputs,
                    operators: #operators,
                    gm,
                    executives,
                    hooks: ::core::marker::PhantomData,
                };
                Ok((system, bridge))
            }
        }
    }
}
