//! The values the search tries for each leaf.
//!
//! Proving uses **cells**: the leaf's range cut at every constant its exact
//! atoms compare it with, so that each exact atom has one truth value on
//! each cell, and one representative value per cell. Booleans, enums and
//! statuses have one cell per value; integers are ranges within their
//! type's bounds; floats are ranges between the constants, the constants
//! themselves, ±∞ and NaN (which no ordering comparison holds for).
//!
//! A witness search tries the representatives and a few more concrete
//! values for leaves that opaque atoms read (the numbers those atoms
//! mention and their neighbours, 0, ±1, the bounds), since an opaque atom
//! has no cells of its own. An array an index by a value reads gets arrays
//! of equal elements, one per value tried for an element.

use super::eval::eval;
use super::terms::{Leaf, Terms};
use crate::ir::{FloatTy, IntTy, Ir, Type};
use rcs_runtime::driver::Value;

/// Per leaf, the representative value of each of its cells.
pub fn cells(ir: &Ir, terms: &Terms) -> Vec<Vec<Value>> {
    terms
        .leaves
        .iter()
        .enumerate()
        .map(|(i, (_, ty))| cells_of(ir, ty, &split_constants(terms, i)))
        .collect()
}

/// The constants the exact atoms of leaf `leaf` compare it with: where
/// its cells are cut.
pub fn split_constants(terms: &Terms, leaf: usize) -> Vec<Value> {
    terms.splits[leaf]
        .iter()
        .filter_map(|c| eval(c, &|_| None))
        .collect()
}

/// Per atom: for an exact one, its truth value on each cell of its leaf
/// (one entry for an atom that reads no leaf), so that a proof looks it up
/// instead of evaluating.
pub fn tables(terms: &Terms, cells: &[Vec<Value>]) -> Vec<Option<Vec<bool>>> {
    terms
        .atoms
        .iter()
        .map(|atom| {
            if !atom.exact {
                return None;
            }
            let truth = |v: Option<Value>| matches!(v, Some(Value::Bool(true)));
            match atom.leaves.as_slice() {
                [] => Some(vec![truth(eval(&atom.expr, &|_| None))]),
                [leaf] => Some(
                    cells[*leaf]
                        .iter()
                        // Every leaf the atom reads is this one.
                        .map(|cell| truth(eval(&atom.expr, &|_| Some(cell.clone()))))
                        .collect(),
                ),
                _ => None,
            }
        })
        .collect()
}

/// Per leaf, the values a witness search tries: its cells' representatives,
/// then the extra candidates, without repeats.
pub fn candidates(ir: &Ir, terms: &Terms, cells: &[Vec<Value>]) -> Vec<Vec<Value>> {
    let mut out: Vec<Vec<Value>> = cells.to_vec();
    for atom in terms.atoms.iter().filter(|a| !a.exact) {
        let mut numbers = Vec::new();
        atom.expr.visit(&mut |x| match &x.kind {
            crate::ir::ExprKind::Int(v) => numbers.push(*v as f64),
            crate::ir::ExprKind::Float(v) => numbers.push(*v),
            _ => {}
        });
        for &leaf in &atom.leaves {
            let ty = &terms.leaves[leaf].1;
            for v in extra(ir, ty, &numbers) {
                if !out[leaf].contains(&v) {
                    out[leaf].push(v);
                }
            }
        }
    }
    // Witnesses read best with small, finite numbers: try those first.
    for (values, (_, ty)) in out.iter_mut().zip(&terms.leaves) {
        if matches!(ty, Type::Int(_) | Type::Float(_)) {
            values.sort_by(|a, b| niceness(a).total_cmp(&niceness(b)));
        }
    }
    // The counters must be able to agree with each other and with
    // `new_command` (see `Search::consistent`): 0 and 1 for both, and
    // `plan_cycles` at least as large as any `state_cycles` tried.
    let find = |l: Leaf| terms.find(&l);
    for counter in [find(Leaf::StateCycles), find(Leaf::PlanCycles)]
        .into_iter()
        .flatten()
    {
        for v in [Value::Int(0), Value::Int(1)] {
            if !out[counter].contains(&v) {
                out[counter].push(v);
            }
        }
    }
    if let (Some(sc), Some(pc)) = (find(Leaf::StateCycles), find(Leaf::PlanCycles)) {
        let from_state: Vec<Value> = out[sc].clone();
        for v in from_state {
            if !out[pc].contains(&v) {
                out[pc].push(v);
            }
        }
    }
    out
}

/// How far a number is from a plain one: its magnitude, then ±∞, then NaN.
fn niceness(v: &Value) -> f64 {
    match v {
        Value::Int(i) => (*i as f64).abs(),
        Value::Float(f) if f.is_nan() => f64::INFINITY,
        Value::Float(f) if f.is_infinite() => f64::MAX,
        Value::Float(f) => f.abs(),
        _ => 0.0,
    }
}

fn cells_of(ir: &Ir, ty: &Type, constants: &[Value]) -> Vec<Value> {
    match ty {
        Type::Bool => vec![Value::Bool(false), Value::Bool(true)],
        Type::Enum(e) => (0..ir.enums[e.index()].variants.len() as u32)
            .map(Value::Enum)
            .collect(),
        Type::Status(c) => (0..ir.controller(*c).statuses.len() as u16)
            .map(Value::Status)
            .collect(),
        Type::Int(t) => int_cells(*t, constants),
        Type::Float(t) => float_cells(*t, constants),
        _ => Vec::new(),
    }
}

/// The range of `t` cut before each constant `c` and after it: every
/// `x OP c` is constant on each piece. One value per piece, the one
/// nearest 0.
fn int_cells(t: IntTy, constants: &[Value]) -> Vec<Value> {
    int_cell_bounds(t, constants)
        .into_iter()
        .map(|(a, b)| Value::Int(0.clamp(a, b)))
        .collect()
}

/// The pieces of [`int_cells`], as inclusive bounds, in order.
pub fn int_cell_bounds(t: IntTy, constants: &[Value]) -> Vec<(i128, i128)> {
    let (lo, hi) = t.range();
    let mut starts = vec![lo];
    for c in constants {
        if let Value::Int(c) = c {
            for s in [*c, c.saturating_add(1)] {
                if s > lo && s <= hi {
                    starts.push(s);
                }
            }
        }
    }
    starts.sort_unstable();
    starts.dedup();
    let mut out = Vec::with_capacity(starts.len());
    for (i, &a) in starts.iter().enumerate() {
        let b = starts.get(i + 1).map_or(hi, |n| n - 1);
        out.push((a, b));
    }
    out
}

/// NaN, ±∞, each constant, and one value strictly between each two
/// neighbours (when the type has one).
fn float_cells(t: FloatTy, constants: &[Value]) -> Vec<Value> {
    let mut points: Vec<f64> = vec![f64::NEG_INFINITY, f64::INFINITY];
    for c in constants {
        if let Value::Float(c) = c {
            if !c.is_nan() {
                // -0.0 and 0.0 compare equal: one point.
                points.push(if *c == 0.0 { 0.0 } else { *c });
            }
        }
    }
    points.sort_by(f64::total_cmp);
    points.dedup();
    let mut out = vec![Value::Float(f64::NAN)];
    for (i, &a) in points.iter().enumerate() {
        out.push(Value::Float(a));
        if let Some(&b) = points.get(i + 1) {
            if let Some(m) = between(t, a, b) {
                out.push(Value::Float(m));
            }
        }
    }
    out
}

/// A value of type `t` strictly between `a < b`, as round as possible.
fn between(t: FloatTy, a: f64, b: f64) -> Option<f64> {
    let inside = |x: f64| {
        let x = crate::arith::round(x, t);
        (a < x && x < b).then_some(x)
    };
    let nice = [
        0.0,
        a.floor() + 1.0,
        b.ceil() - 1.0,
        a + 1.0,
        b - 1.0,
        a / 2.0 + b / 2.0,
    ];
    nice.into_iter()
        .filter(|x| x.is_finite())
        .find_map(inside)
        .or_else(|| {
            let up = match t {
                FloatTy::F32 => (a as f32).next_up() as f64,
                FloatTy::F64 => a.next_up(),
            };
            inside(up)
        })
}

/// More values to try for a leaf an opaque atom reads.
fn extra(ir: &Ir, ty: &Type, numbers: &[f64]) -> Vec<Value> {
    match ty {
        Type::Int(t) => {
            let (lo, hi) = t.range();
            let mut vs = vec![0, 1, -1, lo, hi];
            for n in numbers {
                let n = *n as i128;
                vs.extend([n - 1, n, n + 1]);
            }
            vs.into_iter()
                .filter(|v| (lo..=hi).contains(v))
                .map(Value::Int)
                .collect()
        }
        Type::Float(t) => {
            let mut vs = vec![0.0, 1.0, -1.0, f64::NAN];
            for n in numbers {
                vs.extend([*n, n - 1.0, n + 1.0, n / 2.0, n * 2.0]);
            }
            vs.into_iter()
                .map(|v| Value::Float(crate::arith::round(v, *t)))
                .collect()
        }
        // An array read by a run-time index: every element alike, each
        // value tried for one element (the witness does not pick which).
        Type::Array(e, n) => {
            let mut vs = vec![crate::interp::zero(ir, e)];
            for v in extra(ir, e, numbers) {
                if !vs.contains(&v) {
                    vs.push(v);
                }
            }
            vs.into_iter()
                .map(|v| Value::Array(vec![v; *n as usize]))
                .collect()
        }
        other => cells_of(ir, other, &[]),
    }
}
