//! What runs did to the plans: how many cycles fired each row and how many
//! cycles ended in each state, per controller and verb. Filled from the
//! scenarios of `rcsc test` / `rcsc doc --coverage` or from runtime traces
//! (`rcsc trace`, `rcsc doc --trace`); drawn on the site's graphs and
//! tables, and summed up as text by [`RunCounts::summary`]. Keys are the
//! runtime's ids — a verb is its command's index, a row its position, a
//! state its index — so a trace needs no plans to be counted.

use rcs_dsl::ir::{Controller, Ir, Plan};
use std::collections::BTreeMap;
use std::fmt::Write;

/// (controller name, verb id, row or state id).
pub type Key = (String, u32, u32);

/// Row hits and cycles per state.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RunCounts {
    /// Where the counts come from, in words (`the scenarios`, `2 traces`).
    pub source: String,
    /// Cycles in which each row fired.
    pub rows: BTreeMap<Key, u64>,
    /// Cycles that ended in each state.
    pub states: BTreeMap<Key, u64>,
}

impl RunCounts {
    pub fn add_row(&mut self, ctrl: &str, verb: u32, row: u32, n: u64) {
        *self.rows.entry((ctrl.to_string(), verb, row)).or_default() += n;
    }

    pub fn add_state(&mut self, ctrl: &str, verb: u32, state: u32, n: u64) {
        *self
            .states
            .entry((ctrl.to_string(), verb, state))
            .or_default() += n;
    }

    /// Cycles that fired row `row` of `ctrl`'s verb `verb`.
    pub fn row(&self, ctrl: &str, verb: u32, row: u32) -> u64 {
        self.rows
            .get(&(ctrl.to_string(), verb, row))
            .copied()
            .unwrap_or(0)
    }

    /// Cycles that ended in state `state` of `ctrl`'s verb `verb`.
    pub fn state(&self, ctrl: &str, verb: u32, state: u32) -> u64 {
        self.states
            .get(&(ctrl.to_string(), verb, state))
            .copied()
            .unwrap_or(0)
    }

    /// Hits of every row of a plan, by row name (`E3`).
    pub fn row_weights(&self, ctrl: &str, plan: &Plan) -> BTreeMap<String, u64> {
        plan.rows
            .iter()
            .map(|r| (r.display_name(), self.row(ctrl, plan.verb.0, r.position)))
            .collect()
    }

    /// Whether anything of this controller ran.
    fn touches(&self, ctrl: &str) -> bool {
        let has = |m: &BTreeMap<Key, u64>| m.keys().any(|(c, _, _)| c == ctrl);
        has(&self.rows) || has(&self.states)
    }

    /// The counts as text: per plan that ran, each row's hits (never-fired
    /// rows marked) and the cycles spent in each state. With the plans
    /// (`ir`), rows and states are named and rows that never fired listed;
    /// without, or for a controller the plans do not have, by id.
    pub fn summary(&self, ir: Option<&Ir>) -> String {
        let mut out = String::new();
        let mut named: Vec<&str> = Vec::new();
        if let Some(ir) = ir {
            for c in ir.controllers.iter().filter(|c| self.touches(&c.name)) {
                named.push(&c.name);
                for plan in &c.plans {
                    self.plan_summary(c, plan, &mut out);
                }
            }
        }
        // By id: what the plans do not name.
        let mut plans: Vec<(&str, u32)> = self
            .rows
            .keys()
            .chain(self.states.keys())
            .filter(|(c, _, _)| !named.contains(&c.as_str()))
            .map(|(c, v, _)| (c.as_str(), *v))
            .collect();
        plans.sort();
        plans.dedup();
        for (c, v) in plans {
            let rows: Vec<(u32, u64)> = self
                .rows
                .iter()
                .filter(|((rc, rv, _), _)| rc == c && *rv == v)
                .map(|((_, _, r), n)| (*r, *n))
                .collect();
            let cycles: u64 = self.cycles_of(c, v);
            let _ = writeln!(out, "{c} verb {v}: {} cycles", cycles);
            for (r, n) in rows {
                let _ = writeln!(out, "    {:<8} {n:>8}", format!("E{r}"));
            }
            let states: Vec<String> = self
                .states
                .iter()
                .filter(|((sc, sv, _), _)| sc == c && *sv == v)
                .map(|((_, _, s), n)| format!("#{s} {n}"))
                .collect();
            let _ = writeln!(out, "    states (cycles): {}", states.join(", "));
        }
        out
    }

    fn cycles_of(&self, ctrl: &str, verb: u32) -> u64 {
        self.states
            .iter()
            .filter(|((c, v, _), _)| c == ctrl && *v == verb)
            .map(|(_, n)| n)
            .sum()
    }

    fn plan_summary(&self, c: &Controller, plan: &Plan, out: &mut String) {
        let verb = plan.verb.0;
        let cycles = self.cycles_of(&c.name, verb);
        if cycles == 0
            && !plan
                .rows
                .iter()
                .any(|r| self.row(&c.name, verb, r.position) > 0)
        {
            return;
        }
        let fired = plan
            .rows
            .iter()
            .filter(|r| self.row(&c.name, verb, r.position) > 0)
            .count();
        let _ = writeln!(
            out,
            "{}.{}: {fired}/{} rows fired, {cycles} cycles",
            c.name,
            c.commands[plan.verb.index()].name,
            plan.rows.len()
        );
        for r in &plan.rows {
            let n = self.row(&c.name, verb, r.position);
            let mark = if n == 0 { "  never fired" } else { "" };
            let _ = writeln!(out, "    {:<8} {n:>8}{mark}", r.display_name());
        }
        let states: Vec<String> = plan
            .states
            .iter()
            .enumerate()
            .map(|(i, s)| format!("{} {}", s.name, self.state(&c.name, verb, i as u32)))
            .collect();
        let _ = writeln!(out, "    states (cycles): {}", states.join(", "));
    }
}
