//! Every Rust name the generated module uses, computed once from the IR
//! through [`crate::ident`], so that all parts of the generator agree.

use crate::ident::{camel, distinct, ident, screaming, snake};
use proc_macro2::Ident;
use rcs_dsl::ir::Ir;

#[derive(Clone)]
pub(crate) struct EnumNames {
    pub ty: Ident,
    pub variants: Vec<Ident>,
}

#[derive(Clone)]
pub(crate) struct BufferNames {
    pub ty: Ident,
    pub fields: Vec<Ident>,
}

#[derive(Clone)]
pub(crate) struct PlanNames {
    pub func: Ident,
    pub state_ty: Ident,
    pub states: Vec<Ident>,
}

#[derive(Clone)]
pub(crate) struct CtrlNames {
    pub module: Ident,
    pub commands: Vec<Ident>,
    pub params: Vec<Vec<Ident>>,
    pub status_consts: Vec<Ident>,
    pub status_variants: Vec<Ident>,
    pub error_consts: Vec<Ident>,
    pub error_variants: Vec<Ident>,
    pub vars: Vec<Ident>,
    pub hooks: Vec<Ident>,
    pub hook_params: Vec<Vec<Ident>>,
    /// Field of `Reads`/`Writes` per buffer, indexed like `ir.buffers`.
    pub buffers: Vec<Option<Ident>>,
    /// Field of `Subs` per subordinate, parallel to `subordinates`.
    pub subs: Vec<Ident>,
    pub plans: Vec<PlanNames>,
    /// An instance whose code is its type's module (LANGUAGE.md §8):
    /// built by its module's `new`, not `Controller::new`.
    pub shared: bool,
}

#[derive(Clone)]
pub(crate) struct Names {
    pub enums: Vec<EnumNames>,
    pub buffers: Vec<BufferNames>,
    pub ctrls: Vec<CtrlNames>,
    /// Field of `Inputs`/`Outputs` per Global Memory buffer.
    pub gm_buffers: Vec<Ident>,
    /// Whether the manifest places CPUs in more than one process: then
    /// every type that can sit in a buffer also travels over the Zenoh
    /// bridge (serde derives and a schema hash, [`super::schema`]).
    pub wire: bool,
    /// While a type's shared module is generated: the literals that are
    /// parameters of its instances ([`super::instances`]).
    pub slots: Option<SlotNames>,
}

/// Literals of a type's template that each instance gives: the template's
/// expression (by address) → its field of `Params`, read through `prefix`
/// (`self.inst.params`, or `inst.params` where there is no `self`).
#[derive(Clone)]
pub(crate) struct SlotNames {
    pub slot_of: std::collections::BTreeMap<usize, usize>,
    pub prefix: proc_macro2::TokenStream,
}

impl SlotNames {
    /// The field of slot `i` of `Params`.
    pub fn field(i: usize) -> Ident {
        ident(&format!("k{i}"))
    }
}

fn idents(v: Vec<String>) -> Vec<Ident> {
    v.iter().map(|s| ident(s)).collect()
}

impl Names {
    pub fn new(ir: &Ir) -> Names {
        let type_names = distinct(
            ir.enums
                .iter()
                .map(|e| e.name.as_str())
                .chain(ir.buffer_types.iter().map(|b| b.name.as_str())),
            camel,
            &[],
        );
        let (enum_tys, buffer_tys) = type_names.split_at(ir.enums.len());
        let enums = ir
            .enums
            .iter()
            .zip(enum_tys)
            .map(|(e, ty)| EnumNames {
                ty: ident(ty),
                variants: idents(distinct(
                    e.variants.iter().map(|v| v.name.as_str()),
                    camel,
                    &[],
                )),
            })
            .collect();
        let buffers = ir
            .buffer_types
            .iter()
            .zip(buffer_tys)
            .map(|(b, ty)| BufferNames {
                ty: ident(ty),
                fields: idents(distinct(
                    b.fields.iter().map(|f| f.name.as_str()),
                    snake,
                    &[],
                )),
            })
            .collect();
        let modules = distinct(
            ir.controllers.iter().map(|c| c.name.as_str()),
            snake,
            &["types", "rt", "new_driver"],
        );
        let ctrls = ir
            .controllers
            .iter()
            .zip(&modules)
            .map(|(c, module)| {
                let custom = c.statuses.iter().map(|s| s.name.as_str());
                let mut buffers = vec![None; ir.buffers.len()];
                let own: Vec<_> = c.reads.iter().chain(&c.writes).copied().collect();
                let fields = distinct(
                    own.iter().map(|b| ir.buffers[b.index()].name.as_str()),
                    snake,
                    &[],
                );
                for (b, f) in own.iter().zip(fields) {
                    buffers[b.index()] = Some(ident(&f));
                }
                let plans = {
                    let funcs = distinct(
                        c.plans
                            .iter()
                            .map(|p| c.commands[p.verb.index()].name.as_str()),
                        |n| format!("plan_{}", snake(n)),
                        &[],
                    );
                    c.plans
                        .iter()
                        .zip(funcs)
                        .map(|(p, f)| PlanNames {
                            func: ident(&f),
                            state_ty: ident(&format!(
                                "{}State",
                                camel(&c.commands[p.verb.index()].name)
                            )),
                            states: idents(distinct(
                                p.states.iter().map(|s| s.name.as_str()),
                                camel,
                                &[],
                            )),
                        })
                        .collect()
                };
                CtrlNames {
                    module: ident(module),
                    commands: idents(distinct(
                        c.commands.iter().map(|k| k.name.as_str()),
                        camel,
                        &[],
                    )),
                    params: c
                        .commands
                        .iter()
                        .map(|k| {
                            idents(distinct(
                                k.params.iter().map(|p| p.name.as_str()),
                                snake,
                                &[],
                            ))
                        })
                        .collect(),
                    status_consts: idents(distinct(custom.clone(), screaming, &[])),
                    status_variants: idents(distinct(custom, camel, &[])),
                    error_consts: idents(distinct(
                        c.errors.iter().map(|e| e.name.as_str()),
                        screaming,
                        &["NONE", "UNKNOWN_COMMAND", "INDEX_RANGE", "HOOK_PANIC"],
                    )),
                    error_variants: idents(distinct(
                        c.errors.iter().map(|e| e.name.as_str()),
                        camel,
                        &["UnknownCommand", "IndexRange", "HookPanic"],
                    )),
                    vars: idents(distinct(c.vars.iter().map(|v| v.name.as_str()), snake, &[])),
                    hooks: idents(distinct(
                        c.hooks.iter().map(|h| h.name.as_str()),
                        snake,
                        &[],
                    )),
                    hook_params: c
                        .hooks
                        .iter()
                        .map(|h| {
                            idents(distinct(
                                h.params.iter().map(|p| p.name.as_str()),
                                snake,
                                &["data", "self"],
                            ))
                        })
                        .collect(),
                    buffers,
                    subs: idents(distinct(
                        c.subordinates
                            .iter()
                            .map(|s| ir.controllers[s.index()].name.as_str()),
                        snake,
                        &[],
                    )),
                    plans,
                    shared: false,
                }
            })
            .collect();
        let gm_buffers = idents(distinct(
            ir.buffers.iter().map(|b| b.name.as_str()),
            snake,
            &[],
        ));
        Names {
            enums,
            buffers,
            ctrls,
            gm_buffers,
            wire: rcs_dsl::placement::Placement::of(ir).is_distributed(),
            slots: None,
        }
    }
}
