//! Stage 2: every declared name of the IR indexed by name, built once when
//! the declarations are lowered, for the checker of plan bodies. Looking a
//! name up is then O(log n) however many a file declares: a hostile file of
//! a million statuses and a million references to them must not take a
//! million squared comparisons.

use super::expr::Value;
use crate::ir::{BufferId, HookId, Ir, VarId};
use std::collections::BTreeMap;

type Positions = BTreeMap<String, u32>;

/// Names to positions, the first declaration of a name winning.
fn positions<'a>(names: impl Iterator<Item = &'a str>) -> Positions {
    let mut out = Positions::new();
    for (i, n) in names.enumerate() {
        out.entry(n.to_string()).or_insert(i as u32);
    }
    out
}

/// One controller's names.
pub(in crate::lower) struct ControllerNames {
    /// Vars, then `writes` and `reads` buffers, hooks and subordinates: what
    /// a bare name in an expression stands for, in that order of precedence.
    pub values: BTreeMap<String, Value>,
    pub statuses: Positions,
    pub errors: Positions,
    pub commands: Positions,
    /// Per command, its parameters.
    pub params: Vec<Positions>,
}

/// The names of the whole IR.
pub(in crate::lower) struct Index {
    pub controllers: Vec<ControllerNames>,
    /// Per enum, its variants.
    pub variants: Vec<Positions>,
    /// Per buffer type, its fields.
    pub fields: Vec<Positions>,
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
                    statuses: positions(c.statuses.iter().map(|s| s.name.as_str())),
                    errors: positions(c.errors.iter().map(|e| e.name.as_str())),
                    commands: positions(c.commands.iter().map(|k| k.name.as_str())),
                    params: c
                        .commands
                        .iter()
                        .map(|k| positions(k.params.iter().map(|p| p.name.as_str())))
                        .collect(),
                }
            })
            .collect();
        Index {
            controllers,
            variants: ir
                .enums
                .iter()
                .map(|e| positions(e.variants.iter().map(|v| v.name.as_str())))
                .collect(),
            fields: ir
                .buffer_types
                .iter()
                .map(|b| positions(b.fields.iter().map(|f| f.name.as_str())))
                .collect(),
        }
    }
}

/// `name`'s position in `positions`, as an index.
pub(in crate::lower) fn find(positions: &Positions, name: &str) -> Option<usize> {
    positions.get(name).map(|&i| i as usize)
}
