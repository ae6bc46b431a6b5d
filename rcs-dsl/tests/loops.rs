//! The findings of `livelock` and `command_every_cycle`, replayed on the
//! reference interpreter. For each finding of the golden cases, the
//! command is given with the finding's parameters and the way from the
//! entry is replayed cycle by cycle (each step's inputs, then the row it
//! says fires); then:
//!
//! - a livelock's inputs are held for 1500 cycles (past the `plan_cycles`
//!   constants of the cases): the states go round the
//!   cycle exactly as claimed, one of its rows per cycle, so no other row
//!   (the timeout the finding names included) ever fires;
//! - a command storm's inputs are given with the subordinate showing
//!   `EXECUTING`: the row fires and sends again on each of the next two
//!   cycles.
//!
//! The check and this test share one computation,
//! `rcs_dsl::analysis::cycles`.

mod common;

use proptest::prelude::*;
use rcs_dsl::analysis::cycles::{command_storms, livelocks, Inputs, Step};
use rcs_dsl::analysis::run::replay;
use rcs_dsl::analysis::terms::{Leaf, Step as PathStep};
use rcs_dsl::analysis::PlanAnalysis;
use rcs_dsl::interp;
use rcs_dsl::ir::{Controller, CtrlId, Ir, Plan, StatusId, Type};
use rcs_runtime::driver::{Driven, Record, Value};
use rcs_runtime::{Status, StatusBuffer};

fn load(case: &str) -> Ir {
    let sets = rcs_dsl::load_paths(&[case.into()]).unwrap();
    rcs_dsl::lower_unchecked(&sets[0]).expect(case)
}

fn cases(prefix: &str) -> Vec<String> {
    let mut out: Vec<String> = std::fs::read_dir("../tests/data/err")
        .unwrap()
        .map(|e| e.unwrap().path().to_string_lossy().into_owned())
        .filter(|p| {
            p.rsplit('/')
                .next()
                .is_some_and(|name| name.starts_with(prefix))
        })
        .collect();
    out.sort();
    out
}

/// A controller on the interpreter, with the inputs it has been given so
/// far: the reads buffers, and each subordinate's status.
struct Rig<'ir> {
    ir: &'ir Ir,
    ctrl: &'ir Controller,
    d: interp::Driven<'ir>,
    reads: Vec<Value>,
    statuses: Vec<Option<u16>>,
}

impl<'ir> Rig<'ir> {
    fn new(ir: &'ir Ir, c: CtrlId, plan: &Plan, params: &Inputs) -> Rig<'ir> {
        let ctrl = ir.controller(c);
        let verb = &ctrl.commands[plan.verb.index()];
        let mut args: Vec<Value> = verb
            .params
            .iter()
            .map(|q| interp::zero(ir, &q.ty))
            .collect();
        for (leaf, v) in params {
            match leaf {
                Leaf::Param(p, steps) if steps.is_empty() => args[p.index()] = v.clone(),
                other => panic!("a parameter the test cannot give: {other:?}"),
            }
        }
        let mut d = interp::Driven::new(ir, c);
        d.command(&verb.name, &args).unwrap();
        let reads = ctrl
            .reads
            .iter()
            .map(|b| interp::zero(ir, &Type::Buffer(ir.buffers[b.index()].ty)))
            .collect();
        Rig {
            ir,
            ctrl,
            d,
            reads,
            statuses: vec![None; ctrl.subordinates.len()],
        }
    }

    /// Give a cycle's inputs (the counters and `new_command` follow from
    /// the cycles run; parameters were given with the command).
    fn give(&mut self, inputs: &Inputs) {
        for (leaf, v) in inputs {
            match leaf {
                Leaf::NewCommand | Leaf::StateCycles | Leaf::PlanCycles | Leaf::Param(..) => {}
                Leaf::SubStatus(x) => {
                    let i = self.ctrl.subordinate_index(*x).unwrap();
                    let Value::Status(s) = v else { panic!("{v:?}") };
                    self.statuses[i] = Some(*s);
                }
                Leaf::Buffer(b, steps) => {
                    let i = self.ctrl.reads.iter().position(|r| r == b).unwrap();
                    set_at(&mut self.reads[i], steps, v.clone());
                    let name = &self.ir.buffers[b.index()].name;
                    self.d.set_read(name, &self.reads[i]).unwrap();
                }
                Leaf::Call(h, _) => self
                    .d
                    .set_hook(&self.ctrl.hooks[h.index()].name, v)
                    .unwrap(),
                // `stale_cycles` is 0: every subordinate (and buffer) writes each cycle.
                Leaf::SubStale(_) | Leaf::BufStale(_) => assert_eq!(*v, Value::Int(0)),
                Leaf::Var(..) => {} // vars no job assigns: their initial value
                Leaf::SubField(..) | Leaf::SubErrorCode(_) => {
                    unreachable!("the generated plans read no status field nor error code")
                }
            }
        }
    }

    /// One cycle, every subordinate writing its status first: echoing the
    /// last command sent to it, `NOT_READY` before any, else the status
    /// given (`EXECUTING` if none was).
    fn cycle(&mut self) -> Record {
        for (i, x) in self.ctrl.subordinates.iter().enumerate() {
            let name = &self.ir.controller(*x).name;
            let serial = self.d.last_sent(name).unwrap();
            let status = match (serial, self.statuses[i]) {
                (0, _) => StatusId::NOT_READY.0 as u16,
                (_, Some(s)) => s,
                (_, None) => StatusId::EXECUTING.0 as u16,
            };
            let buffer = StatusBuffer {
                echo_serial: serial,
                status: Status(status),
                ..StatusBuffer::default()
            };
            self.d.write_sub_status(name, buffer).unwrap();
        }
        self.d.cycle()
    }

    /// Replay a way from the entry: each step's row fires in its state (or,
    /// for a wait, none does).
    fn walk(&mut self, path: &[Step], case: &str) {
        let mut state = 0;
        for step in path {
            assert_eq!(state, step.state.0 as u16, "{case}: the walk's state");
            self.give(&step.inputs);
            let rec = self.cycle();
            assert_eq!(
                rec.fired,
                step.row.map(|r| r as u16),
                "{case}: step {step:?}"
            );
            state = rec.state;
        }
    }
}

/// Set the part of `value` that `steps` lead to.
fn set_at(value: &mut Value, steps: &[PathStep], v: Value) {
    match (steps.split_first(), value) {
        (None, value) => *value = v,
        (Some((PathStep::Field(i), rest)), Value::Buffer(xs))
        | (Some((PathStep::Index(i), rest)), Value::Array(xs)) => {
            set_at(&mut xs[*i as usize], rest, v)
        }
        (Some(_), other) => panic!("no such part in {other:?}"),
    }
}

/// Run `replay` on every plan of every golden case whose name starts with
/// `prefix`; it returns how many findings it replayed. Every case must
/// give at least one; the total.
fn replay_cases(
    prefix: &str,
    replay: impl Fn(&str, &Ir, CtrlId, &Plan, &PlanAnalysis) -> usize,
) -> usize {
    let mut found = 0;
    for case in cases(prefix) {
        let ir = load(&case);
        let mut in_case = 0;
        for (ci, c) in ir.controllers.iter().enumerate() {
            for p in &c.plans {
                let a = PlanAnalysis::new(&ir, c, p);
                in_case += replay(&case, &ir, CtrlId(ci as u32), p, &a);
            }
        }
        assert!(in_case > 0, "{case}: nothing found");
        found += in_case;
    }
    found
}

/// Replay every livelock of one plan; how many.
fn replay_livelocks(case: &str, ir: &Ir, c: CtrlId, p: &Plan, a: &PlanAnalysis) -> usize {
    let locks = livelocks(ir.controller(c), p, a);
    for lock in &locks {
        // The finding's run, its last step (round the ring) held for 1500
        // cycles: the rows it names fire in turn, and no other.
        if let Some(run) = &lock.run {
            let mut long = run.clone();
            if let Some(last) = long.steps.last_mut() {
                last.cycles = 1500;
            }
            if let Err(e) = replay(ir, c, &long) {
                panic!("{case}: the livelock's run does not go round: {e}");
            }
        }
        // A ring reached by a run (a plan whose conditions read vars that
        // jobs change) has no walk to replay: its run is its witness.
        if lock.path.is_empty() {
            assert!(
                lock.run.is_some(),
                "{case}: a ring with neither walk nor run"
            );
            continue;
        }
        let mut rig = Rig::new(ir, c, p, &lock.params);
        rig.walk(&lock.path, case);
        rig.give(&lock.held);
        let n = lock.cycle.len();
        // Past 30 cycles, and past the plan-cycle constants of the cases.
        for k in 0..1500 {
            let (row, state) = lock.cycle[k % n];
            let (_, next) = lock.cycle[(k + 1) % n];
            let rec = rig.cycle();
            assert_eq!(
                (rec.fired, rec.state),
                (Some(row as u16), next.0 as u16),
                "{case}: cycle {k} of the loop, in state {state:?}"
            );
            assert_ne!(rec.fired, Some(lock.defeated.0 as u16));
        }
    }
    locks.len()
}

/// Replay every command storm of one plan; how many.
fn replay_storms(case: &str, ir: &Ir, c: CtrlId, p: &Plan, a: &PlanAnalysis) -> usize {
    let ctrl = ir.controller(c);
    let storms = command_storms(ctrl, p, a);
    for storm in &storms {
        let mut rig = Rig::new(ir, c, p, &storm.params);
        rig.walk(&storm.path, case);
        let x = ctrl.subordinate_index(storm.sub).unwrap();
        let first = rig.d.last_sent(&ir.controller(storm.sub).name).unwrap();
        assert_ne!(first, 0, "{case}: the walk ends with a send");
        rig.give(&storm.repeat);
        rig.statuses[x] = Some(StatusId::EXECUTING.0 as u16);
        let mut serial = first;
        for k in 0..2 {
            let rec = rig.cycle();
            assert_eq!(rec.fired, Some(storm.row as u16), "{case}: repeat {k}");
            assert_eq!(rec.state, storm.state.0 as u16);
            let sent: Vec<_> = rec.sent.iter().filter(|s| s.sub as usize == x).collect();
            assert_eq!(sent.len(), 1, "{case}: repeat {k} sends");
            assert_ne!(sent[0].serial, serial, "{case}: a new command each time");
            serial = sent[0].serial;
        }
    }
    storms.len()
}

#[test]
fn livelocks_go_round_on_the_interpreter() {
    let found = replay_cases("33", replay_livelocks);
    assert!(found >= 3, "only {found} livelocks replayed");
}

/// The livelock shapes of issue 27 (5200–5219): rings through `*N` rows,
/// through a subordinate the plan commands and polls, and in plans whose
/// conditions read vars that jobs change; each replays.
#[test]
fn livelock_shapes_go_round_on_the_interpreter() {
    let found = replay_cases("52", replay_livelocks);
    assert!(found >= 12, "only {found} livelocks replayed");
}

#[test]
fn command_storms_send_on_consecutive_cycles_on_the_interpreter() {
    let found = replay_cases("34", replay_storms);
    assert!(found >= 3, "only {found} command storms replayed");
}

/// A random row: from a state, a state set, `*` or `* except …`, a
/// condition over the inputs, the counters, the parameter and the
/// subordinate, a target, maybe a send.
fn row() -> impl Strategy<Value = String> {
    let atom = prop::sample::select(vec![
        "s.a",
        "!s.a",
        "s.b",
        "!s.b",
        "s.n < 3",
        "s.n >= 3",
        "state_cycles > 1",
        "state_cycles > 4",
        "state_cycles == 1",
        "plan_cycles > 5",
        "plan_cycles > 1000",
        "cmd.k == 0",
        "cmd.k > 0",
        "X.done",
        "X.executing",
        "!X.executing",
        "X.status == NOT_READY",
        "X.error",
        "n < 2",
        "n >= 2",
    ]);
    let from = prop::sample::select(vec![
        "S1",
        "S2",
        "S3",
        "*",
        "S1",
        "S2",
        "S3",
        "*",
        "S1 | S2",
        "S2 | S3",
        "* except S1",
        "* except S2 | S3",
    ]);
    // Mostly to states, for rings to form.
    let to = prop::sample::select(vec!["S1", "S2", "S3", "S1", "S2", "S3", "same", "Done"]);
    (
        from,
        prop::collection::vec(atom, 1..=2),
        to,
        prop::bool::weighted(0.3),
        prop::bool::weighted(0.2),
    )
        .prop_map(|(from, atoms, to, send, count)| {
            // A row may count in `n`, which other rows read: such plans
            // are not walked, their rings are reached by replayed runs.
            let send = match (send, count) {
                (true, true) => " { X <- RUN; n += 1 }",
                (true, false) => " { X <- RUN }",
                (false, true) => " { n += 1 }",
                (false, false) => "",
            };
            format!("        {from} when {} -> {to}{send}\n", atoms.join(" && "))
        })
}

fn random_plan() -> impl Strategy<Value = String> {
    (
        prop::bool::ANY,
        prop::bool::ANY,
        prop::collection::vec(row(), 2..=7),
        prop::bool::ANY,
    )
        .prop_map(|(send, timeout, rows, slow)| {
            // X answers at once, or (slow) only after a few cycles: then a
            // ring through it can be a livelock.
            let x_plan = if slow {
                "*0 when new_command -> S1\n        S1 when state_cycles > 2 -> Done"
            } else {
                "* when new_command -> Done"
            };
            let send = if send { " { X <- RUN }" } else { "" };
            // A timeout over every state, first, for rings to defeat.
            let timeout = if timeout {
                "        * when state_cycles > 4 -> Error\n"
            } else {
                ""
            };
            format!(
                "buffer In {{ a: bool, b: bool, n: u8 }}
controller P {{
    subordinates X
    reads s: In
    var n: u8 = 0
    command GO(k: u8)
    plan GO {{
        * when new_command -> S1{send}
{timeout}{}    }}
}}
controller X {{
    command RUN
    plan RUN {{
        {x_plan}
    }}
}}
",
                rows.concat()
            )
        })
}

/// On random plans, every livelock and command storm found replays as
/// claimed: no false alarm. Not vacuous: both are found in some.
#[test]
fn random_plans_replay_every_finding() {
    let mut runner = common::deterministic_runner("RCS_LOOPS_CASES", 800);
    let found = std::cell::Cell::new((0, 0));
    let kinds = std::cell::Cell::new((0, 0));
    runner
        .run(&random_plan(), |text| {
            let set = rcs_dsl::PlanSet::from_texts("p", [("p.rcs", text.as_str())], None);
            let Some(ir) = rcs_dsl::lower_unchecked(&set) else {
                return Ok(());
            };
            let (c, p) = (CtrlId(0), &ir.controllers[0].plans[0]);
            let a = PlanAnalysis::new(&ir, &ir.controllers[0], p);
            let (l, s) = found.get();
            found.set((
                l + replay_livelocks(&text, &ir, c, p, &a),
                s + replay_storms(&text, &ir, c, p, &a),
            ));
            let locks = livelocks(&ir.controllers[0], p, &a);
            let (r, t) = kinds.get();
            kinds.set((
                r + locks.iter().filter(|l| l.path.is_empty()).count(),
                t + locks.iter().filter(|l| !l.through.is_empty()).count(),
            ));
            Ok(())
        })
        .unwrap();
    let (locks, storms) = found.get();
    let (by_run, through) = kinds.get();
    eprintln!(
        "loops: 800 random plans; {locks} livelocks ({by_run} reached by a run, {through} \
         through X), {storms} command storms replayed"
    );
    assert!(
        locks >= 5 && storms >= 5 && by_run >= 1 && through >= 1,
        "{locks} livelocks ({by_run} by a run, {through} through X), {storms} storms"
    );
}

/// The clean cases give no finding at all.
#[test]
fn clean_cases_have_no_loops() {
    for case in std::fs::read_dir("../tests/data/ok").unwrap() {
        let case = case.unwrap().path().to_string_lossy().into_owned();
        if !case.ends_with(".rcs") {
            continue;
        }
        let ir = load(&case);
        for c in &ir.controllers {
            for p in &c.plans {
                let a = PlanAnalysis::new(&ir, c, p);
                assert!(livelocks(c, p, &a).is_empty(), "{case}");
                assert!(command_storms(c, p, &a).is_empty(), "{case}");
            }
        }
    }
}

/// The rings of the golden cases through a subordinate, on the whole plan
/// set: with the ring's inputs held from the start, the real subordinate
/// (not a status the test gives) is commanded again on every round and
/// the supervisor is still executing 400 ticks later: its timeout,
/// shorter than that, never fired.
#[test]
fn rings_through_a_subordinate_hold_in_the_whole_system() {
    let mut checked = 0;
    for case in cases("52") {
        let ir = load(&case);
        for c in &ir.controllers {
            for p in &c.plans {
                let a = PlanAnalysis::new(&ir, c, p);
                for lock in livelocks(c, p, &a) {
                    if lock.through.is_empty() {
                        continue;
                    }
                    let run = lock.run.as_ref().expect("a ring through X has a run");
                    let reads = &run.steps.last().expect("a step").reads;
                    let command = if run.params.is_empty() {
                        serde_json::json!(run.command)
                    } else {
                        serde_json::json!({ &run.command: run.params })
                    };
                    let mut expect = serde_json::Map::new();
                    expect.insert(c.name.clone(), serde_json::json!({ "status": "EXECUTING" }));
                    let text = format!(
                        "name: ring\nsystem: true\ninitial:\n  reads: {}\nsteps:\n  - command: {}\n    cycles: 400\n    expect: {}\n",
                        serde_json::to_string(reads).unwrap(),
                        command,
                        serde_json::Value::Object(expect),
                    );
                    let script = rcs_dsl::scenario::SystemScript::from_yaml(&ir, &text, "ring")
                        .unwrap_or_else(|e| panic!("{case}: {e:?}\n{text}"));
                    let outcome = rcs_dsl::scenario::run_script(&ir, &script)
                        .unwrap_or_else(|e| panic!("{case}: {e:?}"));
                    assert_eq!(outcome.failure, None, "{case}:\n{text}");
                    checked += 1;
                }
            }
        }
    }
    assert!(checked >= 5, "only {checked} rings through a subordinate");
}
