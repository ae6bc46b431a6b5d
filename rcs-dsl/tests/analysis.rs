//! The analysis of conditions against the reference interpreter, on random
//! plans: every row the analysis says can never fire never fires, whatever
//! the inputs, and every row it says can fire does fire when its witness
//! is replayed. Plus the witnesses of a few hand-written plans.
//!
//! The random plans read a buffer of one field per kind of input (bools,
//! an enum, a small signed and an unsigned integer, an `f32`), a command
//! parameter and two hooks, through comparisons with constants near the
//! types' edges, `!`, `&&` and `||`, and an array element read by a
//! run-time index (`s.a[s.i]`, `s.a[cmd.p]`: out of range, the plan ends
//! with `INDEX_RANGE` and no row fires). Every row stays in `S0` (`-> same`), so
//! a witness — one cycle's inputs, on the command's first cycle or a later
//! one — can be replayed by issuing the command and running one or two
//! cycles.

mod common;

use proptest::prelude::*;
use proptest::test_runner::{RngAlgorithm, TestRng};
use rcs_dsl::analysis::terms::{Leaf, Step};
use rcs_dsl::analysis::{Answer, PlanAnalysis, Witness};
use rcs_dsl::interp;
use rcs_dsl::ir::{CtrlId, Ir, StateId};
use rcs_runtime::driver::{Driven, Value};
use std::sync::atomic::{AtomicUsize, Ordering};

const HEADER: &str = "enum Mode { A, B, C }
buffer In { b0: bool, b1: bool, m: Mode, i: i8, u: u8, f: f32, a: [i8; 4] }
controller P {
    command GO(p: i16)
    reads s: In
    hook h() -> Mode
    hook g() -> bool
";

/// One comparison or boolean input, as `.rcs` text.
fn atom() -> impl Strategy<Value = String> {
    let op = || prop::sample::select(vec!["==", "!=", "<", "<=", ">", ">="]);
    let mode = || prop::sample::select(vec!["Mode::A", "Mode::B", "Mode::C"]);
    prop_oneof![
        Just("s.b0".to_string()),
        Just("s.b1".to_string()),
        Just("g()".to_string()),
        (prop::bool::ANY, mode())
            .prop_map(|(eq, m)| format!("s.m {} {m}", if eq { "==" } else { "!=" })),
        (prop::bool::ANY, mode())
            .prop_map(|(eq, m)| format!("h() {} {m}", if eq { "==" } else { "!=" })),
        (
            op(),
            prop::sample::select(vec![-128i32, -127, -1, 0, 1, 5, 126, 127])
        )
            .prop_map(|(o, k)| format!("s.i {o} {k}")),
        (op(), prop::sample::select(vec![0u32, 1, 7, 200, 254, 255]))
            .prop_map(|(o, k)| format!("{k} {o} s.u")),
        (
            prop::sample::select(vec!["<", "<=", ">", ">="]),
            prop::sample::select(vec!["-1.5", "0.0", "1.0", "2.5"])
        )
            .prop_map(|(o, k)| format!("s.f {o} {k}")),
        (op(), -3i32..=3).prop_map(|(o, k)| format!("cmd.p {o} {k}")),
        (
            op(),
            prop::sample::select(vec!["s.i", "cmd.p"]),
            prop::sample::select(vec![-1i32, 0, 1, 5])
        )
            .prop_map(|(o, i, k)| format!("s.a[{i}] {o} {k}")),
    ]
}

/// A condition: atoms under `!`, `&&` and `||`, at most two levels deep.
fn condition() -> impl Strategy<Value = String> {
    atom().prop_recursive(2, 6, 2, |inner| {
        prop_oneof![
            inner.clone().prop_map(|c| format!("!({c})")),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} && {b})")),
            (inner.clone(), inner).prop_map(|(a, b)| format!("({a} || {b})")),
        ]
    })
}

/// A plan: one or two entry rows, then rows from `*`, `S0`, a state set
/// with or without `S0`, or `* except S1`, maybe an `otherwise`; every row
/// `-> same`. (`S1` and `S2`, named only in patterns, are never reached:
/// a row that leaves S0 out never fires.)
fn plan() -> impl Strategy<Value = String> {
    (
        prop::collection::vec(condition(), 1..=2),
        prop::collection::vec(
            (
                prop::sample::select(vec![
                    "*",
                    "S0",
                    "*",
                    "S0",
                    "S0 | S1",
                    "S1 | S2",
                    "* except S1",
                ]),
                condition(),
            ),
            1..=5,
        ),
        prop::bool::ANY,
    )
        .prop_map(|(entries, rows, otherwise)| {
            let mut text = String::from(HEADER);
            text.push_str("    plan GO {\n");
            for c in &entries {
                text.push_str(&format!("        * when new_command && {c} -> same\n"));
            }
            for (from, c) in &rows {
                text.push_str(&format!("        {from} when {c} -> same\n"));
            }
            if otherwise {
                text.push_str("        otherwise -> same\n");
            }
            text.push_str("    }\n}\n");
            text
        })
}

static NEVER: AtomicUsize = AtomicUsize::new(0);
static CAN: AtomicUsize = AtomicUsize::new(0);
static UNKNOWN: AtomicUsize = AtomicUsize::new(0);
/// Witnesses of a later cycle the plan never gets to (see [`replay`]).
static PAST_FIRST: AtomicUsize = AtomicUsize::new(0);

fn lower(text: &str) -> Ir {
    let set = rcs_dsl::PlanSet::from_texts("p", [("p.rcs", text)], None);
    rcs_dsl::lower_unchecked(&set).unwrap_or_else(|| panic!("does not lower:\n{text}"))
}

/// The inputs of one cycle, as the driver takes them.
#[derive(Clone, Debug)]
struct Inputs {
    fields: Vec<Value>,
    h: Value,
    g: Value,
}

impl Default for Inputs {
    fn default() -> Self {
        Inputs {
            fields: vec![
                Value::Bool(false),
                Value::Bool(false),
                Value::Enum(0),
                Value::Int(0),
                Value::Int(0),
                Value::Float(0.0),
                Value::Array(vec![Value::Int(0); 4]),
            ],
            h: Value::Enum(0),
            g: Value::Bool(false),
        }
    }
}

fn apply(d: &mut interp::Driven, inputs: &Inputs) {
    d.set_read("s", &Value::Buffer(inputs.fields.clone()))
        .unwrap();
    d.set_hook("h", &inputs.h).unwrap();
    d.set_hook("g", &inputs.g).unwrap();
}

/// Replay a witness: the command (with its parameter), then the witness's
/// inputs on the command's first cycle (`new_command`) or the next one.
/// The row that fires in that cycle; `Err` when the witness is for a later
/// cycle and every first cycle tried (default inputs, the witness's) ends
/// the plan with `INDEX_RANGE`: a witness is one cycle, and with this
/// parameter the plan may never get past its first.
fn replay(ir: &Ir, w: &Witness) -> Result<Option<u16>, ()> {
    let mut inputs = Inputs::default();
    let mut param = Value::Int(0);
    let mut new_command = false;
    for (leaf, v) in &w.inputs {
        match leaf {
            Leaf::NewCommand => new_command = *v == Value::Bool(true),
            Leaf::Param(_, steps) if steps.is_empty() => param = v.clone(),
            Leaf::Buffer(_, steps) => match steps.as_slice() {
                [Step::Field(f)] => inputs.fields[*f as usize] = v.clone(),
                other => panic!("unexpected buffer path {other:?}"),
            },
            Leaf::Call(h, _) => {
                if ir.controllers[0].hooks[h.index()].name == "h" {
                    inputs.h = v.clone();
                } else {
                    inputs.g = v.clone();
                }
            }
            // Not read by these plans' conditions: any consistent value.
            Leaf::StateCycles | Leaf::PlanCycles => {}
            other => panic!("unexpected leaf {other:?}"),
        }
    }
    if new_command {
        let mut d = interp::Driven::new(ir, CtrlId(0));
        d.command("GO", &[param]).unwrap();
        apply(&mut d, &inputs);
        return Ok(d.cycle().fired);
    }
    for first in [Inputs::default(), inputs.clone()] {
        let mut d = interp::Driven::new(ir, CtrlId(0));
        d.command("GO", &[param.clone()]).unwrap();
        apply(&mut d, &first);
        if d.cycle().error == rcs_runtime::ErrorCode::INDEX_RANGE {
            continue;
        }
        apply(&mut d, &inputs);
        return Ok(d.cycle().fired);
    }
    Err(())
}

/// Random inputs near the edges the plans compare with.
fn random_inputs(rng: &mut TestRng) -> (Inputs, Value) {
    fn pick<T: Clone>(rng: &mut TestRng, xs: &[T]) -> T {
        xs[rng.random_range(0..xs.len())].clone()
    }
    let ints = [-128i128, -127, -2, -1, 0, 1, 2, 4, 5, 6, 125, 126, 127];
    let uints = [0i128, 1, 2, 6, 7, 8, 199, 200, 201, 253, 254, 255];
    let floats = [
        f64::NAN,
        f64::NEG_INFINITY,
        -2.0,
        -1.5,
        -1.0,
        -0.0,
        0.0,
        0.5,
        1.0,
        2.0,
        2.5,
        3.0,
        f64::INFINITY,
    ];
    let elems = [-1i128, 0, 1, 5, 6];
    let inputs = Inputs {
        fields: vec![
            Value::Bool(rng.random()),
            Value::Bool(rng.random()),
            Value::Enum(rng.random_range(0..3)),
            Value::Int(pick(rng, &ints)),
            Value::Int(pick(rng, &uints)),
            Value::Float(pick(rng, &floats)),
            Value::Array((0..4).map(|_| Value::Int(pick(rng, &elems))).collect()),
        ],
        h: Value::Enum(rng.random_range(0..3)),
        g: Value::Bool(rng.random()),
    };
    let param = Value::Int(rng.random_range(-5..=5));
    (inputs, param)
}

/// Run `row`-never-fires against 200 random runs of a few cycles each.
fn never_fires(ir: &Ir, row: u16, rng: &mut TestRng, text: &str) {
    for _ in 0..200 {
        let (first, param) = random_inputs(rng);
        let mut d = interp::Driven::new(ir, CtrlId(0));
        d.command("GO", &[param]).unwrap();
        apply(&mut d, &first);
        let mut fired = vec![d.cycle().fired];
        for _ in 0..3 {
            let (inputs, _) = random_inputs(rng);
            apply(&mut d, &inputs);
            fired.push(d.cycle().fired);
        }
        assert!(
            !fired.contains(&Some(row)),
            "row {row} was proved never to fire, yet fired ({fired:?}) in\n{text}"
        );
    }
}

fn check_plan(text: &str, rng: &mut TestRng) {
    let ir = lower(text);
    let c = &ir.controllers[0];
    let p = &c.plans[0];
    let analysis = PlanAnalysis::new(&ir, c, p);
    for row in 0..p.rows.len() {
        let matches = analysis.can_match(row);
        let fires = analysis.can_fire_in(row, StateId::S0);
        if matches.is_never() {
            assert!(
                fires.is_never(),
                "row {row} cannot match but may fire:\n{text}"
            );
        }
        match fires {
            Answer::Never => {
                NEVER.fetch_add(1, Ordering::Relaxed);
                never_fires(&ir, row as u16, rng, text);
            }
            Answer::Can(w) => {
                CAN.fetch_add(1, Ordering::Relaxed);
                let Ok(fired) = replay(&ir, &w) else {
                    PAST_FIRST.fetch_add(1, Ordering::Relaxed);
                    continue;
                };
                assert_eq!(
                    fired,
                    Some(row as u16),
                    "the witness of row {row} ({}) does not fire it in\n{text}",
                    w.text()
                );
            }
            Answer::Unknown => {
                UNKNOWN.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
}

#[test]
fn never_means_never_and_witnesses_fire_their_rows() {
    let mut runner = common::deterministic_runner("RCS_ANALYSIS_CASES", 300);
    let cases = runner.config().cases;
    let rng = std::sync::Mutex::new(TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    runner
        .run(&plan(), |text| {
            check_plan(&text, &mut rng.lock().unwrap());
            Ok(())
        })
        .unwrap();
    let (never, can, unknown) = (
        NEVER.load(Ordering::Relaxed),
        CAN.load(Ordering::Relaxed),
        UNKNOWN.load(Ordering::Relaxed),
    );
    let past_first = PAST_FIRST.load(Ordering::Relaxed);
    eprintln!(
        "analysis: {cases} plans; rows never {never}, can {can} ({past_first} past a first \
         cycle that always ends the plan), unknown {unknown}"
    );
    assert!(
        past_first * 10 <= can,
        "too many witnesses not replayed: {past_first}"
    );
    // Not vacuous: both answers occur often on these plans.
    assert!(
        never >= cases as usize / 4,
        "only {never} rows proved never"
    );
    assert!(can >= cases as usize, "only {can} rows shown to fire");
    assert!(unknown * 20 <= never + can, "too many unknowns: {unknown}");
}

/// The witness of a hand-written plan, as the note shows it.
#[test]
fn witnesses_name_each_input_as_the_language_writes_it() {
    let text = "enum Mode { A, B }
buffer In { x: f64, m: Mode }
controller Q {
    subordinates T
    command GO(n: u8)
    reads s: In
    plan GO {
        E0: *0 when new_command -> S1 { T <- RUN }
        E1: S1 when cmd.n > 4 && s.x < 1.0 && T.done -> Done
        E2: S1 when s.m == Mode::B && T.status == AT_GOAL -> Done
    }
}
controller T {
    command RUN
    status AT_GOAL
    plan RUN { *0 when new_command -> Done }
}
";
    let ir = lower(text);
    let c = &ir.controllers[0];
    let a = PlanAnalysis::new(&ir, c, &c.plans[0]);
    let Answer::Can(w) = a.can_fire_in(1, StateId(1)) else {
        panic!("E1 can fire")
    };
    let text1 = w.text();
    assert!(text1.contains("cmd.n = 5"), "{text1}");
    assert!(text1.contains("s.x = 0.0"), "{text1}");
    assert!(text1.contains("T.status = DONE"), "{text1}");
    assert!(text1.contains("new_command = false"), "{text1}");
    let Answer::Can(w) = a.can_fire_in(2, StateId(1)) else {
        panic!("E2 can fire")
    };
    let text2 = w.text();
    assert!(text2.contains("s.m = Mode::B"), "{text2}");
    assert!(text2.contains("T.status = AT_GOAL"), "{text2}");
    // The entry row never fires outside S0.
    assert!(a.can_fire_in(0, StateId(1)).is_never());
}

/// Of two `otherwise` rows (an error, but the graph still asks), only the
/// first fires, as on the interpreter.
#[test]
fn only_the_first_otherwise_fires() {
    let text = "controller A {
    command GO
    var ready: bool = false
    plan GO {
        *0 when new_command -> S1
        S1 when ready -> Done
        otherwise -> same
        otherwise -> S1
    }
}
";
    let set = rcs_dsl::PlanSet::from_texts("p", [("p.rcs", text)], None);
    let ir = rcs_dsl::lower_unchecked(&set).expect("lowers");
    let c = &ir.controllers[0];
    let a = PlanAnalysis::new(&ir, c, &c.plans[0]);
    assert!(matches!(a.can_fire_in(2, StateId(1)), Answer::Can(_)));
    assert!(a.can_fire_in(3, StateId(1)).is_never());
}

/// Every `unhandled_error` stall the analysis proves in these plan sets is
/// replayed on the interpreter: the library's path to the state (rows
/// shown to fire, each replayed from its witness), then the stall's inputs
/// (the subordinate in ERROR) for 30 cycles: no row fires, the plan stays.
#[test]
fn stall_witnesses_hold_on_the_interpreter() {
    use rcs_dsl::analysis::run::replay;
    use rcs_dsl::ir::StatusId;
    let mut stalls = 0;
    for case in [
        "../tests/data/err/2911_unhandled_error_reference_submarine",
        "../tests/data/err/2912_unhandled_error_status_test.rcs",
        "../tests/data/err/2913_unhandled_error_one_of_two_subordinates.rcs",
        "../tests/data/err/5101_unhandled_error_watchdog_on_live_subordinate.rcs",
    ] {
        let sets = rcs_dsl::load_paths(&[case.into()]).unwrap();
        let ir = rcs_dsl::lower_unchecked(&sets[0]).expect(case);
        for (ci, c) in ir.controllers.iter().enumerate() {
            let cid = CtrlId(ci as u32);
            for p in &c.plans {
                let a = PlanAnalysis::new(&ir, c, p);
                let paths = a.paths();
                for s in 0..p.states.len() {
                    let state = StateId(s as u32);
                    for (&x, alive) in c.subordinates.iter().flat_map(|x| [(x, false), (x, true)]) {
                        let Some(stall) = a.stalls_in(state, x, StatusId::ERROR, alive) else {
                            continue;
                        };
                        let Some(run) = a.stall_run(&paths, state, &stall, 30) else {
                            continue;
                        };
                        if let Err(e) = replay(&ir, cid, &run) {
                            panic!("{case}: the stall in {}: {e}", p.states[s].name);
                        }
                        stalls += 1;
                    }
                }
            }
        }
    }
    assert!(stalls >= 6, "only {stalls} stalls replayed");
}
