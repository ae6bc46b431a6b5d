//! Stage 3a: the questions a supervisor's handshake checks
//! (`checks/handshake/`) ask of one plan — about commands and their answers
//! rather than rows: whether the plan stalls while a subordinate shows a
//! status, whether its verb's `accept when` can be (or is always) false,
//! whether a command with given parameters is always answered `ERROR`, and
//! whether a row can fire with the parameters pinned.

use super::search::{Mode, Outcome, Search};
use super::terms::{Formula, Leaf, LeafId};
use super::{Answer, PlanAnalysis, Witness};
use crate::ir::{CtrlId, StateId, StatusId, Target};
use rcs_runtime::driver::Value;

impl PlanAnalysis<'_> {
    /// Whether, in `state`, no row can match while subordinate `sub` shows
    /// `status`, whatever every other input is: the plan then stays in
    /// `state` until a new command. `Some` carries one such cycle's inputs;
    /// `None` when some row may match (or the analysis cannot tell, or no
    /// condition reads `sub`'s status).
    ///
    /// With `alive`, `sub` keeps writing its status buffer every cycle of
    /// this controller (it runs at least as often), so `sub.stale_cycles`
    /// is 0 on every cycle: a watchdog on it cannot fire.
    pub fn stalls_in(
        &self,
        state: StateId,
        sub: CtrlId,
        status: StatusId,
        alive: bool,
    ) -> Option<Witness> {
        let (some_row, fixed) = self.stall_question(state, sub, status, alive)?;
        if !matches!(self.prove(&some_row, &fixed), Outcome::None) {
            return None;
        }
        self.no_row_witness(state, &some_row, &fixed)
    }

    /// A weaker stall than [`stalls_in`](Self::stalls_in): inputs the
    /// outside world can hold (buffers read, hook results, the other
    /// subordinates' statuses and fields) at values with which no row of
    /// `state` matches while `sub` shows `status`, whatever the counters
    /// (`state_cycles`, `plan_cycles`, every `stale_cycles`) and vars
    /// become — so while those inputs hold, the plan stays for ever: the
    /// rows that could leave wait on something else that may never come.
    /// A proof for the held values; the witness holds them.
    pub fn stalls_while(
        &self,
        state: StateId,
        sub: CtrlId,
        status: StatusId,
        alive: bool,
    ) -> Option<Witness> {
        let (some_row, fixed) = self.stall_question(state, sub, status, alive)?;
        let w = self.no_row_witness(state, &some_row, &fixed)?;
        let mut held = fixed;
        for (l, v) in &w.inputs {
            let holds = matches!(
                l,
                Leaf::Buffer(..) | Leaf::Call(..) | Leaf::SubStatus(_) | Leaf::SubField(..)
            );
            if let (true, Some(id)) = (holds, self.terms.find(l)) {
                if !held.iter().any(|(h, _)| *h == id) {
                    held.push((id, v.clone()));
                }
            }
        }
        matches!(self.prove(&some_row, &held), Outcome::None).then_some(w)
    }

    /// A cycle's inputs, with `fixed`, on which no row of `state` matches
    /// (`some_row` false): the witness of a stall.
    fn no_row_witness(
        &self,
        state: StateId,
        some_row: &Formula,
        fixed: &[(LeafId, Value)],
    ) -> Option<Witness> {
        let none = Formula::Not(Box::new(some_row.clone()));
        match Search::new(&self.terms, Mode::Witness, self.candidates(), &[], fixed)
            .in_order(self.indexed)
            .run(&none)
        {
            Outcome::Found(values) => Some(self.witness(&none, state, values)),
            Outcome::None | Outcome::Unknown => None,
        }
    }

    /// What a stall in `state` asks: "some row of the state matches", and
    /// the leaves fixed there (`sub` showing `status`; with `alive`, its
    /// `stale_cycles` at 0).
    fn stall_question(
        &self,
        state: StateId,
        sub: CtrlId,
        status: StatusId,
        alive: bool,
    ) -> Option<(Formula, Vec<(LeafId, Value)>)> {
        if !self.analysed_over_cycles() {
            return None;
        }
        let leaf = self.terms.find(&Leaf::SubStatus(sub))?;
        let any = self.conditions_covering(state)?;
        let mut fixed = self.fixed(state);
        fixed.push((leaf, Value::Status(status.0 as u16)));
        if let Some(stale) = alive
            .then(|| self.terms.find(&Leaf::SubStale(sub)))
            .flatten()
        {
            fixed.push((stale, Value::Int(0)));
        }
        Some((Formula::Or(any), fixed))
    }

    /// Whether the verb's `accept when` condition can be false on a
    /// command's arrival: `Some` carries such a cycle's inputs, in `S0`.
    /// `None` when the verb has none, it always holds, or the analysis
    /// cannot tell.
    pub fn refusal(&self) -> Option<Witness> {
        let accept = self.accept.as_ref()?;
        let refused = Formula::Not(Box::new(accept.clone()));
        let fixed = [(self.new_command, Value::Bool(true))];
        match self.decide(&refused, &fixed, StateId::S0) {
            Answer::Can(w) => Some(w),
            Answer::Never | Answer::Unknown => None,
        }
    }

    /// [`never_fires_in`](Self::never_fires_in) with some leaves pinned
    /// (the command's parameters): a proof, `false` when unknown.
    pub fn never_fires_in_given(
        &self,
        row: usize,
        state: StateId,
        given: &[(LeafId, Value)],
    ) -> bool {
        if self.skipped {
            return false;
        }
        let Some(f) = self.fires(row, state) else {
            return true;
        };
        let mut fixed = self.fixed(state);
        fixed.extend(given.iter().cloned());
        matches!(self.prove(&f, &fixed), Outcome::None)
    }

    /// Whether the verb's `accept when` is false on a command's arrival
    /// whatever the inputs not `given` (the command's parameters) are: a
    /// proof that such a command is refused; `false` when unknown.
    pub fn always_refused(&self, given: &[(LeafId, Value)]) -> bool {
        let Some(accept) = &self.accept else {
            return false;
        };
        let mut fixed = vec![(self.new_command, Value::Bool(true))];
        fixed.extend(given.iter().cloned());
        matches!(self.prove(accept, &fixed), Outcome::None)
    }

    /// Whether a command of this plan's verb is answered `ERROR` on its
    /// arrival cycle whatever the inputs, with the `given` leaves (its
    /// parameters) pinned: refused by `accept when`, or accepted and then
    /// the first row to match always ends in `Error`. A proof: `None` when
    /// it is not so or the analysis cannot tell. `Some(rows)` lists the
    /// rows that can answer (empty for a refusal).
    pub fn always_rejects(&self, given: &[(LeafId, Value)]) -> Option<Vec<usize>> {
        if self.skipped || self.indexed {
            return None;
        }
        if self.always_refused(given) {
            return Some(Vec::new());
        }
        let mut fixed = vec![(self.new_command, Value::Bool(true))];
        fixed.extend(given.iter().cloned());
        let accepted = self.accept.clone().unwrap_or(Formula::Const(true));
        let mut failing = Vec::new();
        for (i, row) in self.plan.rows.iter().enumerate() {
            let Some(fires) = self.fires(i, StateId::S0) else {
                continue;
            };
            let can = !matches!(self.prove(&fires, &fixed), Outcome::None);
            match row.to {
                Target::Error(_) | Target::ErrorOf(_) if can => failing.push(i),
                Target::Error(_) | Target::ErrorOf(_) => {}
                _ if can => return None,
                _ => {}
            }
        }
        // Accepted, some row must fire: else the plan waits in S0.
        let any = self.conditions_covering(StateId::S0)?;
        let idle = Formula::And(vec![accepted, Formula::Not(Box::new(Formula::Or(any)))]);
        if !matches!(self.prove(&idle, &fixed), Outcome::None) || failing.is_empty() {
            return None;
        }
        Some(failing)
    }
}
