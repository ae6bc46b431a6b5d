//! The system scenario driver (emitted with the scenario driver,
//! `Options::driver`): `SystemDriver`, several generated controllers of the
//! plan set — every one, or a set of whole subtrees — on their own Global
//! Memory and executives, built as `System::new` builds them (one executive
//! per CPU of the schedule, its controllers in order, each with the
//! `ScriptedHooks` of its driver), driven by name through
//! `rcs_runtime::driver::DrivenSystem`. The caller plays the environment:
//! the operator of each root of the run and the buffers no controller of
//! the run writes; it steps one CPU at a time, so that it owns the
//! schedule (`rcs_dsl::scenario` interleaves a multi-rate set the same way
//! on the interpreter).
//!
//! Not on a running system's cycle path: it allocates, and it is for tests.

use super::names::Names;
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use rcs_dsl::ir::Ir;

pub(crate) fn system_driver(ir: &Ir, names: &Names) -> TokenStream {
    let dv: TokenStream = "::rcs_runtime::driver".parse().expect("a path");
    let n = ir.controllers.len();
    let count = Literal::usize_unsuffixed(n);
    let ctrl_names: Vec<&str> = ir.controllers.iter().map(|c| c.name.as_str()).collect();
    let modules: Vec<_> = names.ctrls.iter().map(|x| &x.module).collect();
    let ops: Vec<_> = (0..n).map(|i| format_ident!("op_{}", i)).collect();
    let cmds: Vec<_> = (0..n).map(|i| format_ident!("cmd_{}", i)).collect();
    let idx: Vec<Literal> = (0..n).map(Literal::usize_unsuffixed).collect();
    // A controller's supervisor, as an index (`None`: a root of the set).
    let sups: Vec<TokenStream> = ir
        .controllers
        .iter()
        .map(|c| match c.supervisor {
            Some(s) => {
                let s = Literal::usize_unsuffixed(s.index());
                quote!(Some(#s))
            }
            None => quote!(None),
        })
        .collect();
    let subs_of: Vec<Vec<usize>> = ir
        .controllers
        .iter()
        .map(|c| c.subordinates.iter().map(|s| s.index()).collect())
        .collect();

    let all_names: Vec<&str> = ir.buffers.iter().map(|b| b.name.as_str()).collect();
    let all_tys: Vec<TokenStream> = ir
        .buffers
        .iter()
        .map(|b| {
            let t = &names.buffers[b.ty.index()].ty;
            quote!(types::#t)
        })
        .collect();
    let ins: Vec<_> = (0..ir.buffers.len())
        .map(|i| format_ident!("in_{}", i))
        .collect();
    let idx_b: Vec<Literal> = (0..ir.buffers.len())
        .map(Literal::usize_unsuffixed)
        .collect();
    let buffer_count = Literal::usize_unsuffixed(ir.buffers.len());
    let writers: Vec<TokenStream> = ir
        .buffers
        .iter()
        .map(|b| match b.writer {
            Some(w) => {
                let w = Literal::usize_unsuffixed(w.index());
                quote!(Some(#w))
            }
            None => quote!(None),
        })
        .collect();

    let executives = ir.schedule.iter().map(|cpu| {
        let name = &cpu.name;
        let period = cpu.period_ns;
        let adds = cpu.order.iter().map(|c| {
            let m = &names.ctrls[c.index()].module;
            let i = Literal::usize_unsuffixed(c.index());
            let make = if names.ctrls[c.index()].shared {
                quote!(#m::new(&gm, #m::ScriptedHooks::default())?)
            } else {
                quote!(#m::Controller::new(&gm, #m::ScriptedHooks::default())?)
            };
            quote!(if in_run[#i] { exec.add(Box::new(#make))?; })
        });
        quote! {{
            let mut exec = rt::Executive::new(rt::ExecutiveConfig::new(#name, ::core::time::Duration::from_nanos(#period)))?;
            #(#adds)*
            if exec.controller_names().next().is_some() {
                cpus.push(#name);
                executives.push(exec);
            }
        }}
    });

    // One cycle's record for each controller, by name.
    let record_arms = (0..n).map(|ci| {
        let m = modules[ci];
        let name = ctrl_names[ci];
        let i = &idx[ci];
        let sent = subs_of[ci].iter().enumerate().map(|(k, s)| {
            let k = k as u16;
            let cmd = &cmds[*s];
            let s = Literal::usize_unsuffixed(*s);
            quote! {
                if after[#s] != before[#s] {
                    if let Some(r) = &self.#cmd {
                        let now = r.read().value;
                        let (verb, args) = #dv::DrivenCommand::parts(&now.command);
                        sent.push(#dv::Sent { sub: #k, verb, args, serial: now.serial });
                    }
                }
            }
        });
        quote! {
            #name => {
                let Some(c) = exec.controller_as_mut::<#m::Controller<#m::ScriptedHooks>>(#m::NAME) else { continue };
                #[allow(unused_mut)]
                let mut sent = Vec::new();
                #(#sent)*
                let rec = #m::driven_record(c, self.cycles[#i], sent);
                self.cycles[#i] += 1;
                out.push((name.clone(), rec));
            }
        }
    });
    let hook_arms = (0..n).map(|ci| {
        let m = modules[ci];
        let name = ctrl_names[ci];
        quote!(#name => {
            let c = self.executives.iter_mut().find_map(|e| e.controller_as_mut::<#m::Controller<#m::ScriptedHooks>>(#m::NAME)).ok_or_else(not_in_run)?;
            #m::driven_set_hook(c, hook, value)
        })
    });
    let var_arms = (0..n).map(|ci| {
        let m = modules[ci];
        let name = ctrl_names[ci];
        quote!(#name => {
            let c = self.executives.iter_mut().find_map(|e| e.controller_as_mut::<#m::Controller<#m::ScriptedHooks>>(#m::NAME)).ok_or_else(not_in_run)?;
            #m::driven_set_var(c, var, value)
        })
    });
    let command_arms = (0..n).map(|ci| {
        let m = modules[ci];
        let name = ctrl_names[ci];
        let op = &ops[ci];
        quote!(#name => {
            let command = <#m::Command as #dv::DrivenCommand>::from_parts(verb, args).map_err(|e| e.for_controller(#name))?;
            Ok(self.#op.as_mut().ok_or_else(|| #dv::unknown("the run", "root controller", root))?.command(command))
        })
    });
    let input_arms = (0..ir.buffers.len()).map(|b| {
        let name = all_names[b];
        let field = &ins[b];
        quote!(#name => {
            let w = self.#field.as_mut().ok_or_else(|| #dv::unknown("the run", "external buffer", buffer))?;
            w.write(#dv::typed("the run", buffer, value)?, 0);
            Ok(())
        })
    });
    let serial_reads = (0..n).map(|ci| {
        let cmd = &cmds[ci];
        quote!(self.#cmd.as_ref().map_or(0, |r| r.read().value.serial))
    });

    quote! {
        /// Controllers of the plan set — every one, or whole subtrees — on
        /// their own Global Memory and executives (as [`System::new`] builds
        /// them, with scripted hooks), driven by name
        /// (`rcs_runtime::driver::DrivenSystem`): the caller plays each
        /// root's operator and the buffers no controller of the run writes,
        /// and runs one CPU's cycle at a time.
        #[derive(Debug)]
        pub struct SystemDriver {
            executives: Vec<rt::Executive>,
            cpus: Vec<&'static str>,
            cycles: [u64; #count],
            #(#ops: Option<rt::Operator<#modules::Command>>,)*
            #(#cmds: Option<rt::Reader<rt::CommandBuffer<#modules::Command>>>,)*
            #(#ins: Option<rt::Writer<#all_tys>>,)*
        }

        // Names and values a small set leaves unused (no external buffer,
        // no subordinate): one shape for every set.
        #[allow(unused_variables, clippy::match_single_binding, clippy::single_match)]
        impl SystemDriver {
            /// The controllers named in `run`, fresh; a name the plan set
            /// lacks, or a run that leaves out a subordinate of one of its
            /// controllers, is an error.
            pub fn new(run: &[&str]) -> Result<Self, String> {
                const NAMES: [&str; #count] = [#(#ctrl_names),*];
                const SUPERVISORS: [Option<usize>; #count] = [#(#sups),*];
                let in_run: [bool; #count] = ::core::array::from_fn(|i| run.contains(&NAMES[i]));
                if let Some(name) = run.iter().find(|r| !NAMES.contains(r)) {
                    return Err(format!("no controller `{name}`"));
                }
                for (i, sup) in SUPERVISORS.iter().enumerate() {
                    if let Some(s) = sup {
                        if in_run[*s] && !in_run[i] {
                            return Err(format!("`{}` is a subordinate of `{}` but not in the run", NAMES[i], NAMES[*s]));
                        }
                    }
                }
                let root = |i: usize| in_run[i] && SUPERVISORS[i].is_none_or(|s| !in_run[s]);
                const WRITERS: [Option<usize>; #buffer_count] = [#(#writers),*];
                let external = |b: usize| WRITERS[b].is_none_or(|w| !in_run[w]);
                Self::build(&in_run, &root, &external).map_err(|e| e.to_string())
            }

            fn build(in_run: &[bool; #count], root: &dyn Fn(usize) -> bool, external: &dyn Fn(usize) -> bool) -> Result<Self, rt::SetupError> {
                let gm = rt::GlobalMemory::new();
                #(gm.declare::<#all_tys>(#all_names)?;)*
                let mut executives = Vec::new();
                let mut cpus = Vec::new();
                #(#executives)*
                Ok(Self {
                    executives,
                    cpus,
                    cycles: [0; #count],
                    #(#ops: if root(#idx) { Some(rt::Operator::connect(&gm, #ctrl_names)?) } else { None },)*
                    #(#cmds: if in_run[#idx] {
                        gm.declare_controller::<#modules::Command>(#ctrl_names)?;
                        Some(gm.command_reader(#ctrl_names)?)
                    } else { None },)*
                    #(#ins: if external(#idx_b) { Some(gm.writer(#all_names)?) } else { None },)*
                })
            }

            fn serials(&self) -> [u32; #count] {
                [#(#serial_reads),*]
            }
        }

        fn not_in_run() -> #dv::DriveError {
            #dv::unknown("the run", "controller", "(not in the run)")
        }

        #[allow(unused_variables, clippy::match_single_binding, clippy::single_match)]
        impl #dv::DrivenSystem for SystemDriver {
            fn command(&mut self, root: &str, verb: &str, args: &[#dv::Value]) -> Result<u32, #dv::DriveError> {
                match root {
                    #(#command_arms)*
                    _ => Err(#dv::unknown("the run", "root controller", root)),
                }
            }

            fn set_read(&mut self, buffer: &str, value: &#dv::Value) -> Result<(), #dv::DriveError> {
                match buffer {
                    #(#input_arms)*
                    _ => Err(#dv::unknown("the run", "external buffer", buffer)),
                }
            }

            fn set_hook(&mut self, controller: &str, hook: &str, value: &#dv::Value) -> Result<(), #dv::DriveError> {
                match controller {
                    #(#hook_arms)*
                    _ => Err(#dv::unknown("the run", "controller", controller)),
                }
            }

            fn set_var(&mut self, controller: &str, var: &str, value: &#dv::Value) -> Result<(), #dv::DriveError> {
                match controller {
                    #(#var_arms)*
                    _ => Err(#dv::unknown("the run", "controller", controller)),
                }
            }

            fn run_cpu(&mut self, cpu: &str) -> Result<Vec<(String, #dv::Record)>, #dv::DriveError> {
                let i = self.cpus.iter().position(|c| *c == cpu).ok_or_else(|| #dv::unknown("the run", "CPU", cpu))?;
                let before = self.serials();
                // Scripted hooks do not panic; a fault would show in the records.
                let _ = self.executives[i].step();
                let after = self.serials();
                let names: Vec<String> = self.executives[i].controller_names().map(str::to_string).collect();
                let mut out = Vec::new();
                for name in names {
                    let exec = &mut self.executives[i];
                    match name.as_str() {
                        #(#record_arms)*
                        _ => {}
                    }
                }
                Ok(out)
            }
        }

        /// A fresh [`SystemDriver`] of the controllers named in `run`
        /// (`Err`: a name the plan set lacks, or a run that is not whole subtrees).
        pub fn new_system_driver(run: &[&str]) -> Result<Box<dyn #dv::DrivenSystem>, String> {
            SystemDriver::new(run).map(|d| Box::new(d) as Box<dyn #dv::DrivenSystem>)
        }
    }
}
