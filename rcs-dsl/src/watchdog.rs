//! Watchdogs on `reads` buffers (LANGUAGE.md §8): which of a controller's
//! `reads` buffers its expressions watch (`B.stale_cycles`, or
//! `B.stale_time` lowered to it). Only those cost anything: the generated
//! controller keeps a `BufferWatch` for each, and scenarios rewrite them
//! every cycle (as a live writer does) unless `silent:` holds them. A
//! controller that watches nothing generates exactly the code it did
//! before watchdogs existed.

use crate::ir::{Controller, ExprKind};

/// Whether any expression of `c` (rows, `pre`, `post`, var initialisers)
/// reads `B.stale_cycles` for each of its `reads` buffers, in `reads` order.
pub fn watched_reads(c: &Controller) -> Vec<bool> {
    let mut watched = vec![false; c.reads.len()];
    let mut mark = |e: &crate::ir::Expr| {
        if let ExprKind::BufferStale(b) = e.kind {
            if let Some(i) = c.reads.iter().position(|r| *r == b) {
                watched[i] = true;
            }
        }
    };
    for r in c.plans.iter().flat_map(|p| &p.rows) {
        r.visit_exprs(&mut mark);
    }
    for block in [&c.pre, &c.post].into_iter().flatten() {
        block.visit_exprs(&mut mark);
    }
    for v in &c.vars {
        if let Some(init) = &v.init {
            init.visit(&mut mark);
        }
    }
    watched
}
