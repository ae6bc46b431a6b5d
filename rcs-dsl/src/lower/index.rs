//! Stage 2: every declared name of the IR indexed by name, built once when
//! the declarations are lowered, for the checker of plan bodies. Looking a
//! name up is then O(log n) however many a file declares: a hostile file of
//! a million statuses and a million references to them must not take a
//! million squared comparisons.

use super::expr::Value;
use super::ByName;
use crate::ir::{BufferId, HookId, Ir, VarId};
use std::collections::BTreeMap;

/// One controller's names.
pub(in crate::lower) struct ControllerNames {
    /// Vars, then `writes` and `reads` buffers, hooks and subordinates: what
    /// a bare name in an expression stands for, in that order of precedence.
    pub values: BTreeMap<String, Value>,
    pub statuses: ByName,
    pub errors: ByName,
    pub commands: ByName,
    /// Per command, its parameters.
    pub params: Vec<ByName>,
}

/// The names of the whole IR.
pub(in crate::lower) struct Index {
    pub controllers: Vec<ControllerNames>,
    /// Per enum, its variants.
    pub variants: Vec<ByName>,
    /// Per buffer type, its fields.
    pub fields: Vec<ByName>,
}

impl Index {
    pub fn new(ir: &Ir) -> Index {
        let controllers = ir
            .controllers
            .iter()
            .map(|c| {
                let mut values = BTreeMap::new();
                let buffer = |b: &BufferId| ir.buffers[b.index()].name.as_str();
                let candidates = c
                    .vars
                    .iter()
                    .enumerate()
                    .map(|(i, v)| (v.name.as_str(), Value::Var(VarId(i as u32))))
                    .chain(
                        c.writes
                            .iter()
                            .map(|b| (buffer(b), Value::Buffer(*b, true))),
                    )
                    .chain(
                        c.reads
                            .iter()
                            .map(|b| (buffer(b), Value::Buffer(*b, false))),
                    )
                    .chain(
                        c.hooks
                            .iter()
                            .enumerate()
                            .map(|(i, h)| (h.name.as_str(), Value::Hook(HookId(i as u32)))),
                    )
                    .chain(
                        c.subordinates
                            .iter()
                            .map(|s| (ir.controllers[s.index()].name.as_str(), Value::Sub)),
                    );
                for (name, value) in candidates {
                    values.entry(name.to_string()).or_insert(value);
                }
                ControllerNames {
                    values,
                    statuses: ByName::of(c.statuses.iter().map(|s| s.name.as_str())),
                    errors: ByName::of(c.errors.iter().map(|e| e.name.as_str())),
                    commands: ByName::of(c.commands.iter().map(|k| k.name.as_str())),
                    params: c
                        .commands
                        .iter()
                        .map(|k| ByName::of(k.params.iter().map(|p| p.name.as_str())))
                        .collect(),
                }
            })
            .collect();
        Index {
            controllers,
            variants: ir
                .enums
                .iter()
                .map(|e| ByName::of(e.variants.iter().map(|v| v.name.as_str())))
                .collect(),
            fields: ir
                .buffer_types
                .iter()
                .map(|b| ByName::of(b.fields.iter().map(|f| f.name.as_str())))
                .collect(),
        }
    }
}
