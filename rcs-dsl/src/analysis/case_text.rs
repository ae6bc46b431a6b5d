//! Stage 3a, for messages: the cases of a command
//! ([`super::command`]) as the language writes them. A case pins one
//! representative value per cell of each parameter; a message names the
//! whole cell (`cmd.n >= 6`, `1.0 < cmd.x < 2.0`), and joins neighbouring
//! cells into one range when one parameter tells the cases apart.

use super::command::Case;
use super::terms::LeafId;
use super::PlanAnalysis;
use rcs_runtime::driver::Value;

impl PlanAnalysis<'_> {
    /// A case's values as the language writes them, for a witness:
    /// `("cmd.n", "0")`.
    pub fn case_shown(&self, case: &Case) -> Vec<(String, String)> {
        case.iter()
            .map(|(l, v)| {
                let (leaf, ty) = &self.terms.leaves[*l];
                (self.leaf_name(leaf), self.value_text(ty, v))
            })
            .collect()
    }

    /// The cells of a case as ranges, for a message: `cmd.n >= 6,
    /// cmd.mode = Mode::B`. Parameters with one cell (every value alike)
    /// are left out.
    pub fn case_text(&self, case: &Case) -> String {
        case.iter()
            .filter(|(l, _)| self.cells[*l].len() > 1)
            .map(|(l, v)| self.cell_text(*l, v))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Several cases, for a message: `cmd.n >= 6`, `cmd.m = Mode::A or
    /// cmd.m = Mode::B`. When one parameter tells the cases apart, runs of
    /// neighbouring cells are joined into one range; otherwise the first
    /// few cases are listed.
    pub fn cases_text(&self, cases: &[Case]) -> String {
        let distinct: Vec<LeafId> = self
            .command_leaves()
            .into_iter()
            .filter(|&l| self.cells[l].len() > 1)
            .collect();
        if let [l] = distinct[..] {
            let mut reached: Vec<usize> = cases
                .iter()
                .filter_map(|c| c.iter().find(|(x, _)| *x == l))
                .filter_map(|(_, v)| self.cells[l].iter().position(|c| same_value(c, v)))
                .collect();
            reached.sort_unstable();
            reached.dedup();
            return self.runs_text(l, &reached);
        }
        let mut shown: Vec<String> = cases
            .iter()
            .take(4)
            .map(|c| self.case_text(c))
            .filter(|t| !t.is_empty())
            .collect();
        if cases.len() > 4 {
            shown.push("…".into());
        }
        shown.join(" or ")
    }

    /// Cells `reached` of leaf `l` (indices, sorted), runs of neighbours
    /// joined: `cmd.x >= 1.0 or cmd.x = NaN`.
    fn runs_text(&self, l: LeafId, reached: &[usize]) -> String {
        let cells = &self.cells[l];
        let (leaf, ty) = &self.terms.leaves[l];
        let name = self.leaf_name(leaf);
        let mut runs: Vec<(usize, usize)> = Vec::new();
        // NaN is no neighbour of any number: it stays a run of its own.
        let is_nan = |i: usize| matches!(cells[i], Value::Float(x) if x.is_nan());
        for &i in reached {
            match runs.last_mut() {
                Some((_, end)) if *end + 1 == i && !is_nan(i) && !is_nan(*end) => *end = i,
                _ => runs.push((i, i)),
            }
        }
        let text = |v: &Value| self.value_text(ty, v);
        let points = super::domain::split_constants(&self.terms, l);
        let mut parts = Vec::new();
        for (a, b) in runs {
            if a == b {
                parts.push(self.cell_text(l, &cells[a]));
                continue;
            }
            let part = match ty {
                crate::ir::Type::Int(t) => {
                    let bounds = super::domain::int_cell_bounds(*t, &points);
                    let (lo, hi) = t.range();
                    match (bounds.get(a), bounds.get(b)) {
                        (Some(&(x, _)), Some(&(_, y))) if x == lo && y == hi => {
                            format!("any {name}")
                        }
                        (Some(&(x, _)), Some(&(_, y))) if x == lo => format!("{name} <= {y}"),
                        (Some(&(x, _)), Some(&(_, y))) if y == hi => format!("{name} >= {x}"),
                        (Some(&(x, _)), Some(&(_, y))) => format!("{x} <= {name} <= {y}"),
                        _ => format!("{name} = {}", text(&cells[a])),
                    }
                }
                crate::ir::Type::Float(_) => {
                    let point = |i: usize| match &cells[i] {
                        Value::Float(x) => x.is_infinite() || points.contains(&cells[i]),
                        _ => false,
                    };
                    let low = match &cells[a] {
                        Value::Float(x) if *x == f64::NEG_INFINITY => None,
                        v if point(a) => Some(format!("{name} >= {}", text(v))),
                        _ => a
                            .checked_sub(1)
                            .map(|p| format!("{name} > {}", text(&cells[p]))),
                    };
                    let high = match &cells[b] {
                        Value::Float(x) if *x == f64::INFINITY => None,
                        v if point(b) => Some(format!("{name} <= {}", text(v))),
                        _ => cells.get(b + 1).map(|n| format!("{name} < {}", text(n))),
                    };
                    match (low, high) {
                        (Some(l), Some(h)) => format!("{l} && {h}"),
                        (Some(x), None) | (None, Some(x)) => x,
                        (None, None) => format!("{name} is not NaN"),
                    }
                }
                _ => (a..=b)
                    .map(|i| self.cell_text(l, &cells[i]))
                    .collect::<Vec<_>>()
                    .join(" or "),
            };
            parts.push(part);
        }
        parts.join(" or ")
    }

    /// The cell of leaf `l` that `v` lies in, as a condition on the leaf.
    fn cell_text(&self, l: LeafId, v: &Value) -> String {
        let (leaf, ty) = &self.terms.leaves[l];
        let name = self.leaf_name(leaf);
        let text = |v: &Value| self.value_text(ty, v);
        match (ty, v) {
            (crate::ir::Type::Int(t), Value::Int(x)) => {
                let constants = super::domain::split_constants(&self.terms, l);
                let (lo, hi) = t.range();
                let piece = super::domain::int_cell_bounds(*t, &constants)
                    .into_iter()
                    .find(|(a, b)| a <= x && x <= b);
                match piece {
                    Some((a, b)) if a == b => format!("{name} = {a}"),
                    Some((a, b)) if a == lo => format!("{name} <= {b}"),
                    Some((a, b)) if b == hi => format!("{name} >= {a}"),
                    Some((a, b)) => format!("{a} <= {name} <= {b}"),
                    None => format!("{name} = {x}"),
                }
            }
            (crate::ir::Type::Float(_), Value::Float(x)) => {
                let cells = &self.cells[l];
                let i = cells.iter().position(|c| same_value(c, v));
                let points = super::domain::split_constants(&self.terms, l);
                let is_point = x.is_nan() || x.is_infinite() || points.contains(v);
                match i {
                    Some(i) if !is_point && i > 0 && i + 1 < cells.len() => {
                        format!("{} < {name} < {}", text(&cells[i - 1]), text(&cells[i + 1]))
                    }
                    _ => format!("{name} = {}", text(v)),
                }
            }
            _ => format!("{name} = {}", text(v)),
        }
    }
}

/// Value equality with NaN equal to itself: a cell's representative is
/// found again by its value.
fn same_value(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Float(x), Value::Float(y)) => x == y || (x.is_nan() && y.is_nan()),
        _ => a == b,
    }
}
