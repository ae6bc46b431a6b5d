//! The reference interpreter's part of every-cycle processing and status
//! data (LANGUAGE.md §7, SEMANTICS.md steps 3b and 4b): running the `pre`
//! and `post` jobs, and the subordinates' status fields a supervisor reads
//! as `X.NAME` (what the subordinate last published, never through the
//! handshake).

use super::{zero, Hooks, Interpreter, Value};
use crate::ir::*;

/// Subordinate `sub`'s status fields, each at its type's zero: what a
/// supervisor reads before the subordinate has published (the generated
/// status-field buffer starts zeroed too).
pub(super) fn zero_fields(ir: &Ir, sub: CtrlId) -> Vec<(VarId, Value)> {
    ir.controller(sub)
        .status_fields()
        .map(|(id, v)| (id, zero(ir, &v.ty)))
        .collect()
}

impl Interpreter<'_> {
    /// Steps 3b and 4b: a `pre` or `post` block's jobs, in order. Lowering
    /// admits only assignments and hook calls, so nothing is sent.
    pub(super) fn every_cycle(&mut self, block: Option<&EveryCycle>, hooks: &mut dyn Hooks) {
        let Some(block) = block else { return };
        let mut sent = Vec::new();
        self.jobs(&block.jobs, hooks, &mut sent);
        debug_assert!(sent.is_empty(), "a send in an every-cycle block");
    }

    /// `X.NAME`: the value subordinate `sub` last published for field `var`.
    pub(super) fn sub_field(&self, sub: CtrlId, var: VarId) -> Value {
        let i = self.ctrl.subordinate_index(sub).expect("a subordinate");
        self.subs[i]
            .fields
            .iter()
            .find(|(v, _)| *v == var)
            .map(|(_, x)| x.clone())
            .unwrap_or(Value::Unit)
    }

    /// Subordinate `index` (in `subordinates`) publishes `value` for its
    /// status field `var`; `false` when it has no such field.
    pub fn write_sub_field(&mut self, index: usize, var: VarId, value: Value) -> bool {
        match self.subs[index].fields.iter_mut().find(|(v, _)| *v == var) {
            Some((_, slot)) => {
                *slot = value;
                true
            }
            None => false,
        }
    }

    /// This controller's status fields as they stand (what step 5
    /// publishes), in declaration order.
    pub fn status_fields(&self) -> Vec<(VarId, Value)> {
        self.ctrl
            .status_fields()
            .map(|(id, _)| (id, self.vars[id.index()].clone()))
            .collect()
    }
}
