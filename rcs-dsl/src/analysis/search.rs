//! The decision procedure: a depth-first search over leaf values (and, when
//! proving, opaque atoms as free booleans), evaluating the formula in
//! three-valued logic after every choice and backtracking as soon as it is
//! false. Exhaustive over the cells, so "no assignment" is a proof; bounded
//! by a node budget, past which the answer is "unknown".

use super::eval::eval;
use super::terms::{Formula, Leaf, LeafId, Terms};
use rcs_runtime::driver::Value;

/// How many search nodes one question may take before it is undecided.
pub const BUDGET: u64 = 200_000;

/// What the search is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Over cells, opaque atoms free: an empty answer proves the formula
    /// unsatisfiable.
    Prove,
    /// Over concrete candidate values, every atom evaluated: an answer is a
    /// real assignment (consistent counters included), but finding none
    /// proves nothing.
    Witness,
}

pub enum Outcome {
    /// No assignment satisfies the formula (a proof only in `Prove` mode).
    None,
    /// An assignment: a value per leaf (`None`: any value will do); empty
    /// in `Prove` mode, where only its existence matters.
    Found(Vec<Option<Value>>),
    /// The budget ran out.
    Unknown,
}

pub struct Search<'a> {
    terms: &'a Terms<'a>,
    mode: Mode,
    /// `Prove` only: per exact atom, its truth value on each cell of its
    /// leaf (one leaf; constant atoms have one entry).
    tables: &'a [Option<Vec<bool>>],
    /// Per leaf, the values to try.
    domains: &'a [Vec<Value>],
    /// The assignment under construction and the search order.
    buf: Buffers,
    nodes: u64,
    new_command: Option<LeafId>,
    /// `Witness` only: `&&` and `||` decide left to right as the
    /// interpreter does, so an operand with no value yet (or none at all:
    /// an index out of range) leaves the rest undecided.
    in_order: bool,
    state_cycles: Option<LeafId>,
    plan_cycles: Option<LeafId>,
}

/// The vectors one search works in. A plan set's analysis asks tens of
/// thousands of questions, and allocating these afresh for each was over a
/// quarter of `check`'s allocations: a finished search hands them to the
/// next one on the same thread (see [`SPARE`]).
#[derive(Default)]
struct Buffers {
    /// Per leaf, its value so far (`None`: unassigned).
    leaves: Vec<Option<Value>>,
    /// `Prove` only: the cell index each assigned leaf is in.
    cell: Vec<usize>,
    /// Per opaque atom, its truth value so far (`Prove`).
    opaque: Vec<Option<bool>>,
    /// Search variables in order: leaves, then opaque atoms (`Prove`).
    order: Vec<Var>,
    /// The atoms the formula reads.
    atoms: Vec<usize>,
}

thread_local! {
    /// Buffers of finished searches, for the next search on this thread.
    /// A pool rather than one slot: a search may run while another is
    /// alive.
    static SPARE: std::cell::RefCell<Vec<Buffers>> = const { std::cell::RefCell::new(Vec::new()) };
}

impl Drop for Search<'_> {
    fn drop(&mut self) {
        let buf = std::mem::take(&mut self.buf);
        SPARE.with(|spare| spare.borrow_mut().push(buf));
    }
}

#[derive(Clone, Copy)]
enum Var {
    Leaf(LeafId),
    Atom(usize),
}

impl<'a> Search<'a> {
    /// A search over `domains` (cells or candidates, per leaf) with the
    /// leaves in `fixed` already set.
    pub fn new(
        terms: &'a Terms<'a>,
        mode: Mode,
        domains: &'a [Vec<Value>],
        tables: &'a [Option<Vec<bool>>],
        fixed: &[(LeafId, Value)],
    ) -> Search<'a> {
        let mut buf = SPARE
            .with(|spare| spare.borrow_mut().pop())
            .unwrap_or_default();
        buf.leaves.clear();
        buf.leaves.resize(terms.leaves.len(), None);
        buf.cell.clear();
        buf.cell.resize(terms.leaves.len(), 0);
        buf.opaque.clear();
        buf.opaque.resize(terms.atoms.len(), None);
        buf.order.clear();
        buf.atoms.clear();
        for (l, v) in fixed {
            buf.leaves[*l] = Some(v.clone());
            if mode == Mode::Prove {
                buf.cell[*l] = cell_of(terms, tables, domains, *l, v);
            }
        }
        let find = |l: Leaf| terms.find(&l);
        Search {
            terms,
            mode,
            tables,
            domains,
            buf,
            nodes: 0,
            new_command: find(Leaf::NewCommand),
            in_order: false,
            state_cycles: find(Leaf::StateCycles),
            plan_cycles: find(Leaf::PlanCycles),
        }
    }

    /// This search, deciding `&&` and `||` strictly left to right when
    /// `in_order` (a witness over conditions that index by a value: an
    /// operand the interpreter reaches must have a value, the index in
    /// range, for the witness to be what the interpreter computes).
    pub fn in_order(mut self, in_order: bool) -> Search<'a> {
        self.in_order = in_order && self.mode == Mode::Witness;
        self
    }

    pub fn run(mut self, f: &Formula) -> Outcome {
        // Only what the formula reads is searched over: first the leaves
        // of the atoms that are evaluated, then (`Prove`) the opaque atoms.
        let mut atoms = std::mem::take(&mut self.buf.atoms);
        collect_atoms(f, &mut atoms);
        let prove = self.mode == Mode::Prove;
        for &a in &atoms {
            let atom = &self.terms.atoms[a];
            if prove && !atom.exact {
                continue;
            }
            for &l in &atom.leaves {
                self.push_leaf(l);
            }
        }
        if self.mode == Mode::Witness {
            // The counters are related to each other and to `new_command`.
            for l in [self.new_command, self.state_cycles, self.plan_cycles]
                .into_iter()
                .flatten()
            {
                self.push_leaf(l);
            }
        }
        if prove {
            for &a in &atoms {
                if !self.terms.atoms[a].exact {
                    self.buf.order.push(Var::Atom(a));
                }
            }
        }
        self.buf.atoms = atoms;
        match self.dfs(f, 0) {
            // A proof's assignment is over cells, not values: nobody reads
            // it, so it is not copied out.
            Ok(true) if prove => Outcome::Found(Vec::new()),
            Ok(true) => Outcome::Found(self.buf.leaves.clone()),
            Ok(false) => Outcome::None,
            Err(()) => Outcome::Unknown,
        }
    }

    /// Adds leaf `l` to the search order unless it is fixed or already in.
    fn push_leaf(&mut self, l: LeafId) {
        let listed = self
            .buf
            .order
            .iter()
            .any(|v| matches!(v, Var::Leaf(x) if *x == l));
        if !listed && self.buf.leaves[l].is_none() {
            self.buf.order.push(Var::Leaf(l));
        }
    }

    fn dfs(&mut self, f: &Formula, depth: usize) -> Result<bool, ()> {
        self.nodes += 1;
        if self.nodes > BUDGET {
            return Err(());
        }
        let verdict = and3(self.value(f), self.consistent());
        match verdict {
            Some(v) => return Ok(v),
            None if depth == self.buf.order.len() => return Ok(false),
            None => {}
        }
        match self.buf.order[depth] {
            Var::Leaf(l) => {
                for (i, v) in self.domains[l].iter().enumerate() {
                    self.buf.leaves[l] = Some(v.clone());
                    self.buf.cell[l] = i;
                    if self.dfs(f, depth + 1)? {
                        return Ok(true);
                    }
                }
                self.buf.leaves[l] = None;
            }
            Var::Atom(a) => {
                for b in [true, false] {
                    self.buf.opaque[a] = Some(b);
                    if self.dfs(f, depth + 1)? {
                        return Ok(true);
                    }
                }
                self.buf.opaque[a] = None;
            }
        }
        Ok(false)
    }

    /// The formula's value under the current partial assignment.
    fn value(&self, f: &Formula) -> Option<bool> {
        match f {
            Formula::Const(b) => Some(*b),
            Formula::Atom(a) => self.atom(*a),
            Formula::Not(x) => self.value(x).map(|b| !b),
            Formula::Shared(x) => self.value(x),
            Formula::NotShared(x) => self.value(x).map(|b| !b),
            Formula::And(xs) => {
                let mut all = Some(true);
                for x in xs {
                    match self.value(x) {
                        Some(false) => return Some(false),
                        None if self.in_order => return None,
                        None => all = None,
                        Some(true) => {}
                    }
                }
                all
            }
            Formula::Or(xs) => {
                let mut any = Some(false);
                for x in xs {
                    match self.value(x) {
                        Some(true) => return Some(true),
                        None if self.in_order => return None,
                        None => any = None,
                        Some(false) => {}
                    }
                }
                any
            }
        }
    }

    fn atom(&self, a: usize) -> Option<bool> {
        let atom = &self.terms.atoms[a];
        if self.mode == Mode::Prove {
            if !atom.exact {
                return self.buf.opaque[a];
            }
            // Exact: a table lookup on the cell of its one leaf.
            let table = self.tables[a].as_ref()?;
            return match atom.leaves.as_slice() {
                [] => table.first().copied(),
                [l] => {
                    self.buf.leaves[*l].as_ref()?;
                    table.get(self.buf.cell[*l]).copied()
                }
                _ => None,
            };
        }
        let lookup = |l: &Leaf| self.buf.leaves[self.terms.find(l)?].clone();
        match eval(&atom.expr, &lookup)? {
            Value::Bool(b) => Some(b),
            _ => None,
        }
    }

    /// Whether the counters agree with each other and with `new_command`
    /// (witnesses only): on a new command's cycle both are 0; on any later
    /// cycle both are at least 1 and `plan_cycles >= state_cycles`.
    fn consistent(&self) -> Option<bool> {
        if self.mode == Mode::Prove {
            return Some(true);
        }
        let get = |l: Option<LeafId>| l.map(|i| self.buf.leaves[i].clone());
        let int = |v: Option<Option<Value>>| match v {
            Some(Some(Value::Int(i))) => Some(Some(i)),
            Some(None) => Some(None),
            None => None,
            Some(Some(_)) => Some(None),
        };
        let nc = match get(self.new_command) {
            Some(Some(Value::Bool(b))) => Some(b),
            Some(_) => return None,
            None => None,
        };
        // `None` (outer): the leaf does not exist; `Some(None)`: unassigned.
        let sc = int(get(self.state_cycles));
        let pc = int(get(self.plan_cycles));
        if matches!(sc, Some(None)) || matches!(pc, Some(None)) {
            return None;
        }
        let (sc, pc) = (sc.flatten(), pc.flatten());
        let ok = match nc {
            Some(true) => sc.unwrap_or(0) == 0 && pc.unwrap_or(0) == 0,
            _ => {
                sc.is_none_or(|s| s >= 1)
                    && pc.is_none_or(|p| p >= 1)
                    && match (sc, pc) {
                        (Some(s), Some(p)) => p >= s,
                        _ => true,
                    }
            }
        };
        Some(ok)
    }
}

/// The cell of leaf `l` that value `v` lies in: the one on which every
/// exact atom of `l` has the truth value it has on `v`.
fn cell_of(
    terms: &Terms,
    tables: &[Option<Vec<bool>>],
    cells: &[Vec<Value>],
    l: LeafId,
    v: &Value,
) -> usize {
    if let Some(i) = cells[l].iter().position(|d| d == v) {
        return i;
    }
    let lookup = |leaf: &Leaf| (terms.find(leaf) == Some(l)).then(|| v.clone());
    let truths: Vec<(usize, bool)> = terms
        .atoms
        .iter()
        .enumerate()
        .filter(|(_, a)| a.exact && a.leaves == [l])
        .map(|(i, a)| (i, matches!(eval(&a.expr, &lookup), Some(Value::Bool(true)))))
        .collect();
    (0..cells[l].len())
        .find(|&c| {
            truths
                .iter()
                .all(|&(a, t)| tables[a].as_ref().and_then(|tb| tb.get(c)) == Some(&t))
        })
        .unwrap_or(0)
}

fn and3(a: Option<bool>, b: Option<bool>) -> Option<bool> {
    match (a, b) {
        (Some(false), _) | (_, Some(false)) => Some(false),
        (Some(true), Some(true)) => Some(true),
        _ => None,
    }
}

fn collect_atoms(f: &Formula, out: &mut Vec<usize>) {
    f.visit_atoms(&mut |a| {
        if !out.contains(&a) {
            out.push(a);
        }
    });
}
