//! The command analysis (`rcs_dsl::analysis::command`) against the
//! reference interpreter, on the golden cases of `incomplete_state` and of
//! `unreachable_row` by entry values:
//!
//! - every hang is replayed: issue the command with the hang's parameter
//!   values, drive the plan along the path the analysis found (each row
//!   fired by its witness's inputs), then run many cycles with random and
//!   edge values of every input that changes (buffers, hooks, subordinate
//!   statuses): no row fires and the plan stays in the state;
//! - a row found unreachable because of the values its state is entered
//!   with never fires in random runs, which do visit that state.

mod common;

use proptest::prelude::RngExt;
use proptest::test_runner::{RngAlgorithm, TestRng};
use rcs_dsl::analysis::command::Step;
use rcs_dsl::analysis::terms::{Leaf, Step as Proj};
use rcs_dsl::analysis::{PlanAnalysis, Witness};
use rcs_dsl::interp;
use rcs_dsl::ir::{Controller, CtrlId, Ir, Type};
use rcs_runtime::driver::{Driven, Value};
use rcs_runtime::{Status, StatusBuffer};

const HANG_CASES: &[&str] = &[
    "../tests/data/err/3201_incomplete_state_parameter_gap.rcs",
    "../tests/data/err/3202_incomplete_state_enum_case_missing.rcs",
    "../tests/data/err/3203_incomplete_state_constant_var.rcs",
    "../tests/data/err/3204_incomplete_state_several_states.rcs",
    "../tests/data/err/3205_incomplete_state_left_to_dead_end_state.rcs",
    "../tests/data/err/3206_incomplete_state_timeout_for_some_values.rcs",
    "../tests/data/err/3207_incomplete_state_after_a_subordinate.rcs",
    "../tests/data/err/1309_unreachable_row_enum_contradiction.rcs",
    "../tests/data/err/1310_unreachable_row_float_contradiction.rcs",
    "../tests/data/err/2105_shadowed_row_by_implication.rcs",
    "../tests/data/err/2703_float_equality_literal_left.rcs",
];

const ENTRY_BOUND_CASES: &[&str] = &[
    "../tests/data/err/1311_unreachable_row_state_entered_with_other_values.rcs",
    "../tests/data/err/1312_unreachable_row_state_entered_with_one_variant.rcs",
    "../tests/data/err/1313_unreachable_row_entry_values_not_also_shadowed.rcs",
    "../tests/data/err/1314_unreachable_row_entry_values_through_states.rcs",
];

fn lower(case: &str) -> Ir {
    let sets = rcs_dsl::load_paths(&[case.into()]).unwrap();
    rcs_dsl::lower_unchecked(&sets[0]).expect(case)
}

/// A random value of type `t`, often at an edge (bounds, 0, ±1, NaN, ±∞).
fn random_value(ir: &Ir, t: &Type, rng: &mut TestRng) -> Value {
    match t {
        Type::Bool => Value::Bool(rng.random()),
        Type::Int(i) => {
            let (lo, hi) = i.range();
            let edges = [lo, hi, 0, 1, -1, 2, 5, 10, 100];
            if rng.random_range(0..3) == 0 {
                Value::Int(rng.random_range(lo..=hi))
            } else {
                Value::Int(edges[rng.random_range(0..edges.len())].clamp(lo, hi))
            }
        }
        Type::Float(f) => {
            let edges = [
                f64::NAN,
                f64::INFINITY,
                f64::NEG_INFINITY,
                0.0,
                -0.0,
                1.0,
                -1.0,
                5.0,
                10.0,
                99.0,
                100.0,
            ];
            let x = if rng.random_range(0..3) == 0 {
                rng.random_range(-1.0e3..1.0e3)
            } else {
                edges[rng.random_range(0..edges.len())]
            };
            Value::Float(rcs_dsl::arith::round(x, *f))
        }
        Type::Enum(e) => {
            Value::Enum(rng.random_range(0..ir.enums[e.index()].variants.len() as u32))
        }
        Type::Buffer(b) => Value::Buffer(
            ir.buffer_types[b.index()]
                .fields
                .iter()
                .map(|f| random_value(ir, &f.ty, rng))
                .collect(),
        ),
        Type::Array(e, n) => Value::Array((0..*n).map(|_| random_value(ir, e, rng)).collect()),
        Type::Status(c) => {
            Value::Status(rng.random_range(0..ir.controller(*c).statuses.len() as u16))
        }
        // No error or one of the declared codes.
        Type::ErrorCode(c) => {
            let n = ir.controller(*c).errors.len() as i128;
            match rng.random_range(0..=n) {
                0 => Value::Int(0),
                k => Value::Int(k + 1),
            }
        }
        Type::Unit => Value::Unit,
    }
}

/// Random values for every input of `c` that changes on its own: each
/// `reads` buffer, each hook's result, each subordinate's status (echoing
/// the last command, an older one, or not written at all this cycle).
fn random_inputs(ir: &Ir, c: &Controller, d: &mut interp::Driven, rng: &mut TestRng) {
    for b in &c.reads {
        let buffer = &ir.buffers[b.index()];
        let v = random_value(ir, &Type::Buffer(buffer.ty), rng);
        d.set_read(&buffer.name, &v).unwrap();
    }
    for h in &c.hooks {
        let v = random_value(ir, &h.ret, rng);
        d.set_hook(&h.name, &v).unwrap();
    }
    for &x in &c.subordinates {
        let name = &ir.controller(x).name;
        if rng.random_range(0..4) == 0 {
            continue;
        }
        let last = d.last_sent(name).unwrap();
        let echo = if rng.random_range(0..4) == 0 {
            last.wrapping_sub(1)
        } else {
            last
        };
        let statuses = ir.controller(x).statuses.len() as u16;
        let status = StatusBuffer {
            echo_serial: echo,
            status: Status(rng.random_range(0..statuses)),
            ..StatusBuffer::default()
        };
        d.write_sub_status(name, status).unwrap();
    }
}

/// One cycle's inputs from a witness, applied through the driver: reads
/// buffer fields, hook results, subordinate statuses (echoing the last
/// command sent). Parameters were given with the command; pinned vars hold
/// their values already; counters are not read by rows on a sure path.
fn apply_witness(
    ir: &Ir,
    c: &Controller,
    d: &mut interp::Driven,
    reads: &mut [Value],
    w: &Witness,
) {
    for (leaf, v) in &w.inputs {
        match leaf {
            Leaf::SubStatus(x) => {
                let name = &ir.controller(*x).name;
                let Value::Status(s) = v else { panic!("{v:?}") };
                let serial = d.last_sent(name).unwrap();
                let status = StatusBuffer {
                    echo_serial: serial,
                    status: Status(*s),
                    ..StatusBuffer::default()
                };
                d.write_sub_status(name, status).unwrap();
            }
            Leaf::Buffer(b, steps) => {
                let i = c.reads.iter().position(|r| r == b).expect("a reads buffer");
                let [Proj::Field(f)] = steps.as_slice() else {
                    panic!("{steps:?}")
                };
                if let Value::Buffer(fields) = &mut reads[i] {
                    fields[*f as usize] = v.clone();
                }
                d.set_read(&ir.buffers[b.index()].name, &reads[i]).unwrap();
            }
            Leaf::Call(h, _) => d.set_hook(&c.hooks[h.index()].name, v).unwrap(),
            _ => {}
        }
    }
}

/// The command's arguments: the pinned parameters, zero for the others.
fn arguments(ir: &Ir, c: &Controller, verb: usize, pinned: &[(Leaf, Value)]) -> Vec<Value> {
    c.commands[verb]
        .params
        .iter()
        .enumerate()
        .map(|(i, q)| {
            pinned
                .iter()
                .find_map(|(l, v)| match l {
                    Leaf::Param(p, s) if p.index() == i && s.is_empty() => Some(v.clone()),
                    _ => None,
                })
                .unwrap_or_else(|| interp::zero(ir, &q.ty))
        })
        .collect()
}

#[test]
fn every_hang_holds_on_the_interpreter() {
    let mut rng = TestRng::deterministic_rng(RngAlgorithm::ChaCha);
    let mut hangs = 0;
    for case in HANG_CASES {
        let ir = lower(case);
        let mut found = 0;
        for (ci, c) in ir.controllers.iter().enumerate() {
            let cid = CtrlId(ci as u32);
            for p in &c.plans {
                let a = PlanAnalysis::new(&ir, c, p);
                for hang in a.hangs() {
                    let state = &p.states[hang.state.index()].name;
                    // Replay the same hang several times, with fresh
                    // random inputs after the path.
                    for _ in 0..5 {
                        let pinned: Vec<(Leaf, Value)> = hang
                            .command
                            .iter()
                            .map(|(l, v)| (a.terms().leaves[*l].0.clone(), v.clone()))
                            .collect();
                        let verb = &c.commands[p.verb.index()];
                        let args = arguments(&ir, c, p.verb.index(), &pinned);
                        let mut d = interp::Driven::new(&ir, cid);
                        let mut reads: Vec<Value> = c
                            .reads
                            .iter()
                            .map(|b| interp::zero(&ir, &Type::Buffer(ir.buffers[b.index()].ty)))
                            .collect();
                        d.command(&verb.name, &args).unwrap();
                        for step in &hang.path {
                            let rec = match step {
                                Step::Fire { row, witness } => {
                                    apply_witness(&ir, c, &mut d, &mut reads, witness);
                                    let rec = d.cycle();
                                    assert_eq!(
                                        rec.fired,
                                        Some(*row as u16),
                                        "{case}: on the path to {state}, {}",
                                        witness.text()
                                    );
                                    rec
                                }
                                Step::Idle => {
                                    let rec = d.cycle();
                                    assert_eq!(rec.fired, None, "{case}: idle first cycle");
                                    rec
                                }
                            };
                            assert!(rec.error.is_none(), "{case}: {rec:?}");
                        }
                        for cycle in 0..40 {
                            random_inputs(&ir, c, &mut d, &mut rng);
                            let rec = d.cycle();
                            assert_eq!(
                                rec.fired, None,
                                "{case}: a row fired {cycle} cycles into the hang in {state}"
                            );
                            assert_eq!(rec.state, hang.state.0 as u16, "{case}: left {state}");
                        }
                    }
                    found += 1;
                }
            }
        }
        assert!(found > 0, "{case}: no hang found");
        hangs += found;
    }
    eprintln!("hang: {hangs} hangs replayed");
}

#[test]
fn rows_entered_only_with_other_values_never_fire() {
    let mut rng = TestRng::deterministic_rng(RngAlgorithm::ChaCha);
    for case in ENTRY_BOUND_CASES {
        let ir = lower(case);
        let mut rows = 0;
        for (ci, c) in ir.controllers.iter().enumerate() {
            let cid = CtrlId(ci as u32);
            for p in &c.plans {
                let a = PlanAnalysis::new(&ir, c, p);
                for bound in a.entry_bound_rows() {
                    rows += 1;
                    let mut visits = 0;
                    for _ in 0..300 {
                        let verb = &c.commands[p.verb.index()];
                        let args: Vec<Value> = verb
                            .params
                            .iter()
                            .map(|q| random_value(&ir, &q.ty, &mut rng))
                            .collect();
                        let mut d = interp::Driven::new(&ir, cid);
                        d.command(&verb.name, &args).unwrap();
                        for _ in 0..12 {
                            random_inputs(&ir, c, &mut d, &mut rng);
                            let before = d.interpreter().bookkeeping().state();
                            let rec = d.cycle();
                            if before as u32 == bound.state.0 {
                                visits += 1;
                            }
                            assert_ne!(
                                rec.fired,
                                Some(bound.row as u16),
                                "{case}: row {} fired with {args:?}",
                                p.rows[bound.row].display_name()
                            );
                        }
                    }
                    assert!(visits > 0, "{case}: the runs never visit the state");
                }
            }
        }
        assert!(rows > 0, "{case}: no row found");
    }
}

/// Random plans over four states, for the property test below: conditions
/// on the command's parameters, a var no job assigns, a var some jobs
/// assign, buffer fields, a hook, a subordinate's status, a counter and an
/// opaque comparison; rows between states, `same`, `Done` and `Error`.
mod random_plans {
    use proptest::prelude::*;

    pub const HEADER: &str = "enum Mode { A, B, C }
buffer In { b0: bool, b1: bool, i: i8 }
controller Q { command RUN plan RUN { *0 when new_command -> Done } }
controller P {
    subordinates Q
    command GO(p: i16, m: Mode)
    reads s: In
    var k: bool = false
    var w: i8 = 0
    hook g() -> bool
";

    fn atom() -> impl Strategy<Value = String> {
        let op = || prop::sample::select(vec!["==", "!=", "<", "<=", ">", ">="]);
        let mode = || prop::sample::select(vec!["Mode::A", "Mode::B", "Mode::C"]);
        prop_oneof![
            Just("s.b0".to_string()),
            Just("s.b1".to_string()),
            Just("g()".to_string()),
            Just("k".to_string()),
            Just("w > 0".to_string()),
            Just("Q.done".to_string()),
            Just("Q.error".to_string()),
            Just("state_cycles > 3".to_string()),
            Just("cmd.p + 1 > s.i as i16".to_string()),
            (op(), -2i32..=2).prop_map(|(o, k)| format!("s.i {o} {k}")),
            (op(), -2i32..=2).prop_map(|(o, k)| format!("cmd.p {o} {k}")),
            (op(), -2i32..=2).prop_map(|(o, k)| format!("cmd.p {o} {k}")),
            (prop::bool::ANY, mode())
                .prop_map(|(eq, m)| format!("cmd.m {} {m}", if eq { "==" } else { "!=" })),
            (prop::bool::ANY, mode())
                .prop_map(|(eq, m)| format!("cmd.m {} {m}", if eq { "==" } else { "!=" })),
        ]
    }

    fn condition() -> impl Strategy<Value = String> {
        atom().prop_recursive(2, 4, 2, |inner| {
            prop_oneof![
                inner.clone().prop_map(|c| format!("!({c})")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} && {b})")),
                (inner.clone(), inner).prop_map(|(a, b)| format!("({a} || {b})")),
            ]
        })
    }

    fn target() -> impl Strategy<Value = String> {
        prop::sample::select(vec![
            "S0", "S1", "S2", "S3", "same", "Done", "Error", "S1", "S2",
        ])
        .prop_map(str::to_string)
    }

    fn jobs() -> impl Strategy<Value = String> {
        prop::sample::select(vec!["", "", " { w = 1 }", " { w = 0 }", " { Q <- RUN }"])
            .prop_map(str::to_string)
    }

    pub fn plan() -> impl Strategy<Value = String> {
        (
            prop::collection::vec((condition(), target(), jobs()), 1..=2),
            prop::collection::vec(
                (
                    prop::sample::select(vec![
                        "*",
                        "S0",
                        "S1",
                        "S1",
                        "S2",
                        "S2",
                        "S3",
                        "S1 | S2",
                        "* except S1",
                    ]),
                    condition(),
                    target(),
                    jobs(),
                ),
                2..=7,
            ),
            prop::bool::weighted(0.15),
        )
            .prop_map(|(entries, rows, otherwise)| {
                let mut text = String::from(HEADER);
                text.push_str("    plan GO {\n");
                for (c, t, j) in &entries {
                    text.push_str(&format!("        * when new_command && {c} -> {t}{j}\n"));
                }
                for (from, c, t, j) in &rows {
                    text.push_str(&format!("        {from} when {c} -> {t}{j}\n"));
                }
                if otherwise {
                    text.push_str("        otherwise -> same\n");
                }
                text.push_str("    }\n}\n");
                text
            })
    }
}

/// Replay hang `hang` of plan `p` (controller `c`): the command, the path,
/// then random cycles. Panics with `text` when the interpreter disagrees.
fn replay_hang(
    ir: &Ir,
    cid: CtrlId,
    a: &PlanAnalysis,
    hang: &rcs_dsl::analysis::command::Hang,
    rng: &mut TestRng,
    text: &str,
) {
    let c = ir.controller(cid);
    let p = &c.plans[0];
    let pinned: Vec<(Leaf, Value)> = hang
        .command
        .iter()
        .map(|(l, v)| (a.terms().leaves[*l].0.clone(), v.clone()))
        .collect();
    let args = arguments(ir, c, p.verb.index(), &pinned);
    let mut d = interp::Driven::new(ir, cid);
    let mut reads: Vec<Value> = c
        .reads
        .iter()
        .map(|b| interp::zero(ir, &Type::Buffer(ir.buffers[b.index()].ty)))
        .collect();
    d.command(&c.commands[p.verb.index()].name, &args).unwrap();
    for step in &hang.path {
        match step {
            Step::Fire { row, witness } => {
                apply_witness(ir, c, &mut d, &mut reads, witness);
                let rec = d.cycle();
                assert_eq!(
                    rec.fired,
                    Some(*row as u16),
                    "path to {:?} with {args:?}: {} in\n{text}",
                    hang.state,
                    witness.text()
                );
            }
            Step::Idle => {
                let rec = d.cycle();
                assert_eq!(rec.fired, None, "idle first cycle with {args:?} in\n{text}");
            }
        }
    }
    for cycle in 0..30 {
        random_inputs(ir, c, &mut d, rng);
        let rec = d.cycle();
        assert_eq!(
            rec.fired, None,
            "hang in {:?} with {args:?}: a row fired after {cycle} cycles in\n{text}",
            hang.state
        );
        assert_eq!(rec.state, hang.state.0 as u16, "left the hang in\n{text}");
    }
}

/// Random runs of plan `p`: row `row` never fires.
fn never_fires(ir: &Ir, cid: CtrlId, row: usize, rng: &mut TestRng, text: &str) {
    let c = ir.controller(cid);
    let verb = &c.commands[c.plans[0].verb.index()];
    for _ in 0..60 {
        let args: Vec<Value> = verb
            .params
            .iter()
            .map(|q| random_value(ir, &q.ty, rng))
            .collect();
        let mut d = interp::Driven::new(ir, cid);
        d.command(&verb.name, &args).unwrap();
        for _ in 0..10 {
            random_inputs(ir, c, &mut d, rng);
            let rec = d.cycle();
            assert_ne!(
                rec.fired,
                Some(row as u16),
                "row {row} fired with {args:?} in\n{text}"
            );
        }
    }
}

#[test]
fn random_plans_hangs_replay_and_bound_rows_never_fire() {
    let mut runner = common::deterministic_runner("RCS_HANG_CASES", 300);
    let cases = runner.config().cases;
    let rng = std::sync::Mutex::new(TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let counts = std::sync::Mutex::new((0usize, 0usize));
    runner
        .run(&random_plans::plan(), |text| {
            let sets = rcs_dsl::PlanSet::from_texts("p", [("p.rcs", text.as_str())], None);
            let ir = rcs_dsl::lower_unchecked(&sets).expect("lowers");
            let cid = CtrlId(1);
            let c = ir.controller(cid);
            let a = PlanAnalysis::new(&ir, c, &c.plans[0]);
            let mut rng = rng.lock().unwrap();
            let mut counts = counts.lock().unwrap();
            for hang in a.hangs() {
                replay_hang(&ir, cid, &a, &hang, &mut rng, &text);
                counts.0 += 1;
            }
            for bound in a.entry_bound_rows() {
                never_fires(&ir, cid, bound.row, &mut rng, &text);
                counts.1 += 1;
            }
            Ok(())
        })
        .unwrap();
    let (hangs, bound) = *counts.lock().unwrap();
    eprintln!("hang: {cases} random plans; {hangs} hangs replayed, {bound} bound rows run");
    assert!(hangs >= cases as usize / 10, "only {hangs} hangs");
}
