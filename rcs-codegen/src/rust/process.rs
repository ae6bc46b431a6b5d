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
    /// `executives[i]`: make CPU `i`'s executive and add its controllers
    /// (`rcs_runtime::Setup` calls on `setup`).
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
        #(setup.declare_controller::<#modules::Command>(#modules::NAME);)*
        #(setup.declare::<#cross_tys>(#cross_names);)*
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
                let writer = processes[x.writer].as_str();
                if x.writer == p {
                    Some(quote!(bridge.export::<#ty>(#name)?;))
                } else if !x.readers.contains(&p) {
                    None
                } else if let BufferKind::Status(c) = &x.kind {
                    // A status the subordinate cannot write is refused.
                    let [statuses, errors, verbs, states] =
                        status_ranges(&ir.controllers[c.index()]);
                    Some(quote! {
                        bridge.import_checked::<#ty>(#name, #writer, |s: &rt::StatusBuffer| {
                            s.check_range(#statuses, #errors, #verbs, #states)
                        })?;
                    })
                } else {
                    Some(quote!(bridge.import::<#ty>(#name, #writer)?;))
                }
            });
        let policy = crate::acl::policy(ir, placement, p).to_string();
        // A remote operator (identity `operator`) commands the roots that
        // run here through their local operators' writers, and sees their
        // statuses.
        let roots = (0..ir.controllers.len())
            .filter(|&c| placement.ctrl_process[c] == p && ir.controllers[c].supervisor.is_none())
            .map(|c| {
                let m = &names.ctrls[c].module;
                quote! {
                    bridge.import_operator::<#m::Command>(#m::NAME, &operators.#m)?;
                    bridge.export::<rt::StatusBuffer>(&rt::status_buffer_name(#m::NAME))?;
                }
            });
        quote! {
            #process => {
                if config.policy.is_none() {
                    config.policy = Some(#policy.to_owned());
                }
                #[allow(unused_mut)]
                let mut bridge = rt::Bridge::builder(config, &gm);
                #(#bridged)*
                #(#roots)*
                #(#cpus)*
                bridge
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
                    quote!(#f: if process == #process { Some(setup.writer(#name)) } else { None })
                }
                None => quote!(#f: Some(setup.writer(#name))),
            }
        });
    let Shared {
        outputs,
        operators,
        bounds,
        generics,
        hooks_param,
        ..
    } = sh;
    // The operator in a process of its own: every root's command out,
    // every root's status in, under the operator's policy.
    let operator_policy = crate::acl::operator_policy(ir, placement).to_string();
    let remote_roots = (0..ir.controllers.len())
        .filter(|&c| ir.controllers[c].supervisor.is_none())
        .map(|c| {
            let m = &names.ctrls[c].module;
            let process = processes[placement.ctrl_process[c]].as_str();
            let [statuses, errors, verbs, states] = status_ranges(&ir.controllers[c]);
            quote! {
                bridge.export::<rt::CommandBuffer<#m::Command>>(&rt::command_buffer_name(#m::NAME))?;
                bridge.import_checked::<rt::StatusBuffer>(
                    &rt::status_buffer_name(#m::NAME),
                    #process,
                    |s: &rt::StatusBuffer| s.check_range(#statuses, #errors, #verbs, #states),
                )?;
            }
        });
    let operators_expr = &sh.operators;
    quote! {
        impl Operators {
            /// The operators of every root, from a process of their own (a
            /// console, a supervisory program): `config` names process
            /// `operator` (`BridgeConfig::new(SYSTEM, "operator")`, with the
            /// `operator` certificate) and connects to the processes that
            /// run the roots. Each root's command goes to its process, and
            /// its status comes back, under the operator's access-control
            /// policy (`config.policy`, when `None`); the root's process
            /// takes the command through the root's one command writer,
            /// beside its local operator (`docs/distribution.md`).
            pub fn remote(
                mut config: rt::BridgeConfig,
            ) -> Result<(Self, rt::Bridge), rt::BridgeError> {
                if config.process != rt::bridge::OPERATOR {
                    return Err(rt::BridgeError::Identity(format!(
                        "the operator's bridge is process `{}`, not `{}`",
                        rt::bridge::OPERATOR, config.process
                    )));
                }
                if config.policy.is_none() {
                    config.policy = Some(#operator_policy.to_owned());
                }
                let mut setup = rt::Setup::new(&[]);
                let operators = #operators_expr;
                let (gm, _) = setup.finish()?;
                let mut bridge = rt::Bridge::builder(config, &gm);
                #(#remote_roots)*
                Ok((operators, bridge.start()?))
            }
        }

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
            /// `config.policy`, when `None`, becomes this process's
            /// access-control policy generated from the plan set (it applies
            /// under `config.security = Security::Tls`, which
            /// `BridgeConfig::certs` sets; `BridgeConfig::insecure` opts out
            /// of it, loudly).
            pub fn process(
                process: &str,
                mut config: rt::BridgeConfig,
                #hooks_param: Hooks #generics,
            ) -> Result<(Self, rt::Bridge), rt::BridgeError> {
                let mut setup = rt::Setup::new(&BUFFERS);
                #declares
                let gm = setup.gm().clone();
                let operators = #operators;
                let bridge = match process {
                    #(#arms)*
                    _ => {
                        return Err(rt::BridgeError::UnknownProcess {
                            name: process.to_owned(),
                            known: PROCESSES.iter().map(|p| p.to_string()).collect(),
                        })
                    }
                };
                let inputs = Inputs { #(#inputs),* };
                let outputs = #outputs;
                let (gm, mut executives) = setup.finish()?;
                let bridge = bridge.start()?;
                for exec in &mut executives {
                    exec.set_cycle_signal(bridge.signal());
                }
                let system = Self {
                    inputs,
                    outputs,
                    operators,
                    gm,
                    executives,
                    hooks: ::core::marker::PhantomData,
                };
                Ok((system, bridge))
            }
        }
    }
}

/// `[custom statuses, declared errors, verbs, most states of a plan]` of a
/// controller: the ranges its status buffer can take.
fn status_ranges(ctrl: &rcs_dsl::ir::Controller) -> [u16; 4] {
    let n = |x: usize| u16::try_from(x).unwrap_or(u16::MAX);
    let states = ctrl.plans.iter().map(|p| p.states.len()).max().unwrap_or(0);
    [
        n(ctrl.statuses.len()),
        n(ctrl.errors.len()),
        n(ctrl.commands.len()),
        n(states),
    ]
}
