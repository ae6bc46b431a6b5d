//! Differential test: the reference interpreter (`rcs_dsl::interp::Driven`)
//! and the generated Rust (`rcs_plan_sets::SETS`, compiled by build.rs with
//! the scenario driver) run every plan of every plan set of the repository
//! identically.
//!
//! For every plan set, every controller and every plan, 1,000 random input
//! sequences (proptest; fixed seeds and no failure persistence, so CI plays
//! the same sequences every time) are played against both backends through
//! the one `rcs_runtime::driver::Driven` interface. A sequence sets the
//! world's `reads` buffers, commands the plan's verb, then takes 1–30
//! steps; a step may send a new command (any verb, random typed arguments),
//! make an ill-formed driver call (unknown names, wrong arity, values of the
//! wrong type or out of range), change `reads` buffers (whole, or a few
//! scalars so that conditions met earlier stay met), set hook results and
//! answer for subordinates (DONE, ERROR, EXECUTING or any status of theirs,
//! echoing the serial last sent, an older one or a random one), then runs
//! one cycle — now and then 50–300, so that `state_cycles`, `plan_cycles`
//! and `stale_cycles` timeouts fire. Values follow the IR types: integers
//! favour 0, ±1, the type's bounds and the numeric literals of the
//! controller's own expressions (±1, negated), floats the literals, ±0 and
//! small numbers, so that row conditions come true.
//!
//! Both backends get exactly the same calls. Every call must give the same
//! `Ok`/`Err` on both, and after every cycle the two `Record`s must be the
//! same in full (fired row, state, status, error, verb, sent commands, vars,
//! `writes` buffers; floats compared as `{:?}` prints them, so NaN equals
//! NaN and -0.0 differs from 0.0). A divergence fails with the plan set,
//! controller, plan, step, both records and the calls so far, shrunk by
//! proptest to a small sequence.
//!
//! The test is not vacuous: every row of every plan must fire on both
//! backends in some sequence (a plan whose rows have not all fired after
//! 1,000 sequences gets up to four more rounds of 1,000), except the rows
//! listed in [`NEVER_FIRE`], each of which provably cannot fire (and must
//! indeed never fire); and `a_swapped_row_is_caught` shows that a code
//! generator that gets row precedence wrong is caught, as a divergence
//! rather than a crash.
//!
//! `cargo test -p rcs-plan-sets --test differential -- --nocapture` prints
//! a summary: plans, sequences, cycles, driver calls, rows fired, the rows
//! that fired least and the rows that cannot fire.

use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestError, TestRng, TestRunner};
use rcs_dsl::interp;
use rcs_dsl::ir::{Condition, Controller, CtrlId, ExprKind, From, Ir, Type};
use rcs_plan_sets::{PlanSet, SETS};
use rcs_runtime::driver::{DriveError, Driven, Value};
use rcs_runtime::{ErrorCode, Status, StatusBuffer};
use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Random sequences per plan.
const SEQUENCES: u32 = 1000;
/// Steps per sequence (after the first command).
const MAX_STEPS: usize = 30;

/// Rows that cannot fire whatever the inputs, as `(plan set, controller,
/// verb, row position, why)`: golden test cases written to exercise the
/// checker (shadowed rows, unreachable states, an `otherwise` after an
/// always-true row), not to run. Each must indeed never fire (so the list
/// stays true); every row not listed must fire on both backends.
const NEVER_FIRE: &[(&str, &str, &str, u32, &str)] = &[
    (OK_0009, "A", "ONE", 1, "`S1 when ready`: `ready` starts false and only TWO's `*3 otherwise` sets it, which never fires"),
    (OK_0009, "A", "ONE", 3, "`*3 when plan_cycles > 99`: ONE sits in S1 from its first cycle, so E2 (`state_cycles > 9`, earlier) ends it at plan cycle 10"),
    (OK_0009, "A", "TWO", 1, "`S0_wait when ready`: `ready` is never true (see ONE row 1)"),
    (OK_0009, "A", "TWO", 3, "`*3 otherwise`: TWO leaves S0 on its first cycle (new_command), and in S0_wait `ready` or `!ready` always matches"),
    (OK_0011, "A", "GO", 2, "`S2 when ready`: `ready` starts false and nothing sets it"),
    (OK_0011, "A", "GO", 4, "`otherwise`: `*3 when true` always matches first"),
    (OK_0017, "B", "RUN", 3, "`S2 when true -> Done`: shadowed by `S2 when true -> S1` (`#[allow(shadowed_row)]`)"),
    (OK_0017, "B", "RUN", 4, "`S9 when true`: nothing goes to S9 (`#[allow(unreachable_state)]`)"),
    (OK_0018, "A", "GO", 0, "`new_command && gear == Low`: `gear` starts High and is only ever set to High"),
    (OK_0018, "A", "GO", 2, "S1: reached only through row 0"),
    (OK_0018, "A", "GO", 3, "S2: reached only through row 0"),
    (OK_0018, "A", "GO", 4, "S3: reached only through row 0"),
    (OK_0018, "A", "GO", 5, "S4: reached only through row 0"),
    (OK_0018, "A", "GO", 6, "S5: reached only through row 0"),
    (OK_0018, "A", "GO", 7, "S6: reached only through row 0"),
    (OK_0018, "A", "GO", 8, "S7: reached only through row 0"),
    (OK_0018, "A", "GO", 9, "S8: reached only through row 0"),
    (OK_0018, "A", "GO", 10, "`*10 when state_cycles > 100`: row 1 ends every GO on its first cycle"),
    (OK_0018, "A", "GO", 11, "S1: reached only through row 0"),
    (OK_0107, "H", "ARGS", 2, "`reading(1) == Mid && reading(2) == Low`: the scripted hooks answer one value per hook, whatever the arguments"),
    (OK_0107, "H", "ARGS", 3, "`reading(2) == Low` after `reading(1) == Low`: one scripted value per hook (see row 2)"),
];
const OK_0009: &str = "tests/data/ok/0009_targets_and_otherwise.rcs";
const OK_0011: &str = "tests/data/ok/0011_otherwise_never_shadowed.rcs";
const OK_0017: &str = "tests/data/ok/0017_lint_levels";
const OK_0018: &str = "tests/data/ok/0018_allowed_lints_and_bare_initialisers.rcs";
const OK_0107: &str = "tests/data/ok/0107_analysis_hooks_and_arguments.rcs";

// ---------------------------------------------------------------- inputs

/// What a subordinate's status buffer echoes.
#[derive(Clone, Copy, Debug)]
enum Echo {
    /// The serial the controller last sent it.
    Last,
    /// That serial minus this (a stale answer to an older command).
    Older(u32),
    /// Any serial.
    Any(u32),
}

/// A subordinate writes its status buffer.
#[derive(Clone, Copy, Debug)]
struct Answer {
    echo: Echo,
    status: u16,
    error: u16,
}

/// A driver call both backends must refuse alike.
#[derive(Clone, Debug)]
enum Bad {
    Command(String, Vec<Value>),
    Read(String, Value),
    Hook(String, Value),
    Sub(String),
}

/// The world changes a `reads` buffer.
#[derive(Clone, Debug)]
enum Update {
    /// All of it.
    Whole(Value),
    /// A few of its scalars (index into the buffer's [`leaves`], value):
    /// sensors change a little at a time, so conditions met earlier stay
    /// met while the plan waits for the next one.
    Leaves(Vec<(usize, Value)>),
}

/// The paths (field and element indices) to every scalar of type `t`, with
/// their types.
fn leaves(ir: &Ir, t: &Type, path: &mut Vec<usize>, out: &mut Vec<(Vec<usize>, Type)>) {
    match t {
        Type::Buffer(b) => {
            for (i, f) in ir.buffer_types[b.index()].fields.iter().enumerate() {
                path.push(i);
                leaves(ir, &f.ty, path, out);
                path.pop();
            }
        }
        Type::Array(e, n) => {
            for i in 0..*n as usize {
                path.push(i);
                leaves(ir, e, path, out);
                path.pop();
            }
        }
        _ => out.push((path.clone(), t.clone())),
    }
}

/// The scalar of `v` at `path`.
fn at<'v>(v: &'v mut Value, path: &[usize]) -> &'v mut Value {
    match (path.split_first(), v) {
        (None, v) => v,
        (Some((i, rest)), Value::Buffer(xs) | Value::Array(xs)) => at(&mut xs[*i], rest),
        (Some(_), v) => panic!("no path into {v:?}"),
    }
}

/// One step of a sequence: inputs, then `cycles` cycles.
#[derive(Clone, Debug)]
struct Step {
    /// A new command: verb index and arguments.
    command: Option<(usize, Vec<Value>)>,
    bad: Option<Bad>,
    /// Per `reads` buffer, an update.
    reads: Vec<Option<Update>>,
    /// Per hook, a new result.
    hooks: Vec<Option<Value>>,
    /// Per subordinate, an answer.
    subs: Vec<Option<Answer>>,
    cycles: u32,
}

/// A sequence: the world's first `reads` values, the plan's verb with these
/// arguments, then the steps.
#[derive(Clone, Debug)]
struct Sequence {
    reads: Vec<Option<Value>>,
    args: Vec<Value>,
    steps: Vec<Step>,
}

/// Random values of the IR's types for one controller.
struct Values<'a> {
    ir: &'a Ir,
    /// Integer literals of the controller's expressions, ±1, negated.
    ints: Vec<i128>,
    /// Float literals (and the integer ones as floats), ±1, negated.
    floats: Vec<f64>,
}

impl<'a> Values<'a> {
    fn new(ir: &'a Ir, c: &Controller) -> Values<'a> {
        let mut ints = vec![0i128, 1, -1];
        // NaN and the infinities: rows must agree on them too (and some
        // rows fire only for them: a NaN matches no ordering comparison).
        let mut floats = vec![
            0.0f64,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -0.5,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut harvest = |e: &rcs_dsl::ir::Expr| match e.kind {
            ExprKind::Int(v) => {
                for x in [v, -v] {
                    ints.extend([x.saturating_sub(1), x, x.saturating_add(1)]);
                    floats.extend([x as f64 - 1.0, x as f64, x as f64 + 1.0]);
                }
            }
            ExprKind::Float(v) => {
                for x in [v, -v] {
                    floats.extend([x - 1.0, x, x + 1.0]);
                    let t = x.trunc() as i128;
                    ints.extend([t.saturating_sub(1), t, t.saturating_add(1)]);
                }
            }
            _ => {}
        };
        for p in &c.plans {
            for r in &p.rows {
                r.visit_exprs(&mut harvest);
            }
        }
        for v in &c.vars {
            if let Some(e) = &v.init {
                e.visit(&mut harvest);
            }
        }
        ints.sort_unstable();
        ints.dedup();
        floats.sort_by(f64::total_cmp);
        floats.dedup_by(|a, b| a.to_bits() == b.to_bits());
        Values { ir, ints, floats }
    }

    /// Values of type `t`.
    fn of(&self, t: &Type) -> BoxedStrategy<Value> {
        match t {
            Type::Bool => any::<bool>().prop_map(Value::Bool).boxed(),
            Type::Int(it) => {
                let (lo, hi) = it.range();
                let mut special: Vec<i128> = [lo, lo + 1, hi - 1, hi]
                    .into_iter()
                    .chain(self.ints.iter().copied())
                    .filter(|v| (lo..=hi).contains(v))
                    .collect();
                special.sort_unstable();
                special.dedup();
                prop_oneof![
                    4 => select(special).prop_map(Value::Int),
                    1 => (lo..=hi).prop_map(Value::Int),
                ]
                .boxed()
            }
            Type::Float(_) => {
                use proptest::num::f64 as f;
                prop_oneof![
                    4 => select(self.floats.clone()),
                    2 => -1000.0..1000.0f64,
                    1 => f::POSITIVE | f::NEGATIVE | f::NORMAL | f::SUBNORMAL | f::ZERO,
                ]
                .prop_map(Value::Float)
                .boxed()
            }
            Type::Enum(e) => {
                let n = self.ir.enums[e.index()].variants.len() as u32;
                (0..n).prop_map(Value::Enum).boxed()
            }
            Type::Status(c) => {
                let n = self.ir.controller(*c).statuses.len() as u16;
                (0..n).prop_map(Value::Status).boxed()
            }
            Type::Buffer(b) => self.ir.buffer_types[b.index()]
                .fields
                .iter()
                .map(|f| self.of(&f.ty))
                .collect::<Vec<_>>()
                .prop_map(Value::Buffer)
                .boxed(),
            Type::Array(e, n) => proptest::collection::vec(self.of(e), *n as usize)
                .prop_map(Value::Array)
                .boxed(),
            Type::Unit => Just(Value::Unit).boxed(),
        }
    }

    /// Arguments for command `verb` of `c`.
    fn args(&self, c: &Controller, verb: usize) -> BoxedStrategy<Vec<Value>> {
        c.commands[verb]
            .params
            .iter()
            .map(|p| self.of(&p.ty))
            .collect::<Vec<_>>()
            .boxed()
    }

    /// A value `t` refuses (out of range or of another shape).
    fn wrong(&self, t: &Type) -> Value {
        match t {
            Type::Int(it) => Value::Int(it.range().1 + 1),
            Type::Enum(e) => Value::Enum(self.ir.enums[e.index()].variants.len() as u32),
            Type::Float(_) => Value::Int(0),
            _ => Value::Unit,
        }
    }

    /// Ill-formed calls for `c`.
    fn bad_calls(&self, c: &Controller) -> Vec<Bad> {
        let ir = self.ir;
        let zeros = |k: &rcs_dsl::ir::Command| -> Vec<Value> {
            k.params.iter().map(|p| interp::zero(ir, &p.ty)).collect()
        };
        let mut bad = vec![
            Bad::Command("NO_SUCH_VERB".into(), Vec::new()),
            Bad::Read("no_such_buffer".into(), Value::Unit),
            Bad::Hook("no_such_hook".into(), Value::Unit),
            Bad::Sub("NO_SUCH_SUB".into()),
        ];
        for k in &c.commands {
            let mut more = zeros(k);
            more.push(Value::Unit);
            bad.push(Bad::Command(k.name.clone(), more));
            if let Some(p) = k.params.first() {
                bad.push(Bad::Command(k.name.clone(), Vec::new()));
                let mut wrong = zeros(k);
                wrong[0] = self.wrong(&p.ty);
                bad.push(Bad::Command(k.name.clone(), wrong));
            }
        }
        for b in &c.reads {
            bad.push(Bad::Read(ir.buffers[b.index()].name.clone(), Value::Unit));
        }
        for b in &c.writes {
            let buffer = &ir.buffers[b.index()];
            let zero = interp::zero(ir, &Type::Buffer(buffer.ty));
            bad.push(Bad::Read(buffer.name.clone(), zero));
        }
        for h in &c.hooks {
            let v = if h.ret == Type::Unit {
                Value::Bool(true)
            } else {
                self.wrong(&h.ret)
            };
            bad.push(Bad::Hook(h.name.clone(), v));
        }
        bad
    }

    /// Sequences for the plan of command `verb` of `c`.
    fn sequences(
        &self,
        c: &Controller,
        read_leaves: &[Vec<(Vec<usize>, Type)>],
        verb: usize,
    ) -> impl Strategy<Value = Sequence> {
        let ir = self.ir;
        let commands: Vec<_> = (0..c.commands.len())
            .map(|v| self.args(c, v).prop_map(move |a| (v, a)).boxed())
            .collect();
        let command = if commands.is_empty() {
            Just(None).boxed()
        } else {
            proptest::option::weighted(0.05, proptest::strategy::Union::new(commands)).boxed()
        };
        let bad = proptest::option::weighted(0.03, select(self.bad_calls(c)));
        let whole: Vec<_> = c
            .reads
            .iter()
            .map(|b| {
                proptest::option::weighted(0.75, self.of(&Type::Buffer(ir.buffers[b.index()].ty)))
            })
            .collect();
        let updates: Vec<_> = c
            .reads
            .iter()
            .zip(read_leaves)
            .map(|(b, ls)| {
                let all = self
                    .of(&Type::Buffer(ir.buffers[b.index()].ty))
                    .prop_map(Update::Whole);
                let update = if ls.is_empty() {
                    all.boxed()
                } else {
                    let one = proptest::strategy::Union::new(
                        ls.iter()
                            .enumerate()
                            .map(|(i, (_, t))| self.of(t).prop_map(move |v| (i, v)).boxed()),
                    );
                    let some = proptest::collection::vec(one, 1..=3).prop_map(Update::Leaves);
                    prop_oneof![all, some].boxed()
                };
                proptest::option::weighted(0.5, update)
            })
            .collect();
        let hooks: Vec<_> = c
            .hooks
            .iter()
            .map(|h| proptest::option::weighted(0.3, self.of(&h.ret)))
            .collect();
        let subs: Vec<_> = c
            .subordinates
            .iter()
            .map(|s| {
                let sub = ir.controller(*s);
                let statuses = sub.statuses.len() as u16;
                let errors = sub.errors.len() as u16 + ErrorCode::FIRST_CUSTOM;
                let echo = prop_oneof![
                    6 => Just(Echo::Last),
                    2 => (1u32..3).prop_map(Echo::Older),
                    1 => any::<u32>().prop_map(Echo::Any),
                ];
                let status = prop_oneof![
                    3 => Just(Status::DONE.0),
                    2 => Just(Status::ERROR.0),
                    2 => Just(Status::EXECUTING.0),
                    2 => 0..statuses,
                ];
                let answer = (echo, status, 0..errors).prop_map(|(echo, status, error)| Answer {
                    echo,
                    status,
                    error,
                });
                proptest::option::weighted(0.4, answer)
            })
            .collect();
        let cycles = prop_oneof![98 => Just(1u32), 2 => 50u32..=300];
        let step = (command, bad, updates, hooks, subs, cycles).prop_map(
            |(command, bad, reads, hooks, subs, cycles)| Step {
                command,
                bad,
                reads,
                hooks,
                subs,
                cycles,
            },
        );
        (
            whole,
            self.args(c, verb),
            proptest::collection::vec(step, 1..=MAX_STEPS),
        )
            .prop_map(|(reads, args, steps)| Sequence { reads, args, steps })
    }
}

// ---------------------------------------------------------------- running

/// One controller of one plan set: the interpreter runs `interp_ir` (the
/// mutation test alters it), the generated code comes from `set`, and the
/// inputs are drawn from `ir`.
struct Subject<'a> {
    set: &'a PlanSet,
    ir: &'a Ir,
    interp_ir: &'a Ir,
    ctrl: CtrlId,
    /// Per `reads` buffer, its scalars ([`leaves`]).
    leaves: Vec<Vec<(Vec<usize>, Type)>>,
}

impl<'a> Subject<'a> {
    fn new(set: &'a PlanSet, ir: &'a Ir, interp_ir: &'a Ir, ctrl: CtrlId) -> Subject<'a> {
        let leaves = ir
            .controller(ctrl)
            .reads
            .iter()
            .map(|b| {
                let mut out = Vec::new();
                leaves(
                    ir,
                    &Type::Buffer(ir.buffers[b.index()].ty),
                    &mut Vec::new(),
                    &mut out,
                );
                out
            })
            .collect();
        Subject {
            set,
            ir,
            interp_ir,
            ctrl,
            leaves,
        }
    }

    fn controller(&self) -> &Controller {
        self.ir.controller(self.ctrl)
    }
}

/// A driver call, applied to both backends alike.
#[derive(Clone, Debug)]
enum Call<'a> {
    Command(&'a str, &'a [Value]),
    /// The buffer as a whole: the world's copy after this step's update.
    SetRead(&'a str, Value),
    SetHook(&'a str, &'a Value),
    WriteSubStatus(&'a str, StatusBuffer),
    LastSent(&'a str),
}

impl Call<'_> {
    fn apply(&self, d: &mut dyn Driven) -> Result<u32, DriveError> {
        match *self {
            Call::Command(verb, args) => d.command(verb, args),
            Call::SetRead(buffer, ref v) => d.set_read(buffer, v).map(|()| 0),
            Call::SetHook(hook, v) => d.set_hook(hook, v).map(|()| 0),
            Call::WriteSubStatus(sub, s) => d.write_sub_status(sub, s).map(|()| 0),
            Call::LastSent(sub) => d.last_sent(sub),
        }
    }
}

/// What a sequence did, for the failure message.
enum Entry<'a> {
    Call(Call<'a>, Result<u32, DriveError>),
    Cycles(u32),
}

/// Totals and coverage over the sequences of one controller.
#[derive(Default)]
struct Stats {
    sequences: Cell<u64>,
    cycles: Cell<u64>,
    calls: Cell<u64>,
    /// How often each `(verb, row)` fired, per backend (interpreter, generated).
    fired: RefCell<[BTreeMap<(u16, u16), u64>; 2]>,
}

/// The two backends and what they were given.
struct Pair<'a> {
    subject: &'a Subject<'a>,
    verb: &'a str,
    interp: interp::Driven<'a>,
    generated: Box<dyn Driven>,
    log: Vec<Entry<'a>>,
    stats: &'a Stats,
}

impl<'a> Pair<'a> {
    fn call(&mut self, call: Call<'a>) -> Result<Result<u32, DriveError>, String> {
        let a = call.apply(&mut self.interp);
        let b = call.apply(self.generated.as_mut());
        self.stats.calls.set(self.stats.calls.get() + 1);
        if a == b {
            self.log.push(Entry::Call(call, a.clone()));
            Ok(a)
        } else {
            Err(self.divergence(&format!(
                "call {call:?}\n  interpreter: {a:?}\n  generated:   {b:?}"
            )))
        }
    }

    /// A well-formed call: both backends must accept it.
    fn ok(&mut self, call: Call<'a>) -> Result<u32, String> {
        let what = format!("{call:?}");
        self.call(call)?
            .map_err(|e| format!("the test's own call {what} was refused by both: {e}"))
    }

    /// An ill-formed call: both backends must refuse it.
    fn refused(&mut self, call: Call<'a>) -> Result<(), String> {
        let what = format!("{call:?}");
        match self.call(call)? {
            Err(_) => Ok(()),
            Ok(r) => Err(format!("both backends accepted the ill-formed {what}: {r}")),
        }
    }

    fn cycles(&mut self, step: usize, n: u32) -> Result<(), String> {
        self.log.push(Entry::Cycles(n));
        for k in 0..n {
            let a = self.interp.cycle();
            let b = self.generated.cycle();
            self.stats.cycles.set(self.stats.cycles.get() + 1);
            // Compared as printed: NaN equals NaN, -0.0 differs from 0.0.
            let (pa, pb) = (format!("{a:?}"), format!("{b:?}"));
            if pa != pb {
                return Err(self.divergence(&format!(
                    "step {step}, cycle {} of {n}\n  interpreter: {pa}\n  generated:   {pb}",
                    k + 1
                )));
            }
            let mut fired = self.stats.fired.borrow_mut();
            for (count, r) in fired.iter_mut().zip([&a, &b]) {
                if let (Some(v), Some(f)) = (r.verb, r.fired) {
                    *count.entry((v, f)).or_default() += 1;
                }
            }
        }
        Ok(())
    }

    fn divergence(&self, what: &str) -> String {
        let s = self.subject;
        let mut m = format!(
            "divergence between interpreter and generated code: {} {} (a sequence of plan {}), {what}\ncalls so far:\n",
            s.set.path,
            s.controller().name,
            self.verb
        );
        for e in &self.log {
            let _ = match e {
                Entry::Call(c, r) => writeln!(m, "  {c:?} -> {r:?}"),
                Entry::Cycles(n) => writeln!(m, "  cycle x{n}"),
            };
        }
        m
    }
}

/// Play one sequence of the plan of verb `verb` on both backends.
fn run_sequence(
    subject: &Subject<'_>,
    verb: usize,
    seq: &Sequence,
    stats: &Stats,
) -> Result<(), String> {
    let c = subject.controller();
    let ir = subject.ir;
    let generated = (subject.set.new_driver)(&c.name)
        .expect("the generated set has the controller")
        .expect("the generated controller sets up");
    let mut p = Pair {
        subject,
        verb: &c.commands[verb].name,
        interp: interp::Driven::new(subject.interp_ir, subject.ctrl),
        generated,
        log: Vec::new(),
        stats,
    };
    stats.sequences.set(stats.sequences.get() + 1);
    if p.interp.name() != p.generated.name() {
        return Err(p.divergence(&format!(
            "names: interpreter {:?}, generated {:?}",
            p.interp.name(),
            p.generated.name()
        )));
    }
    // The world's copy of each `reads` buffer (zero, as on both backends).
    let mut world: Vec<Value> = c
        .reads
        .iter()
        .map(|b| interp::zero(ir, &Type::Buffer(ir.buffers[b.index()].ty)))
        .collect();
    for ((b, v), w) in c.reads.iter().zip(&seq.reads).zip(&mut world) {
        if let Some(v) = v {
            *w = v.clone();
            p.ok(Call::SetRead(&ir.buffers[b.index()].name, v.clone()))?;
        }
    }
    p.ok(Call::Command(&c.commands[verb].name, &seq.args))?;
    for (i, step) in seq.steps.iter().enumerate() {
        if let Some((v, args)) = &step.command {
            p.ok(Call::Command(&c.commands[*v].name, args))?;
        }
        match &step.bad {
            None => {}
            Some(Bad::Command(v, args)) => p.refused(Call::Command(v, args))?,
            Some(Bad::Read(b, v)) => p.refused(Call::SetRead(b, v.clone()))?,
            Some(Bad::Hook(h, v)) => p.refused(Call::SetHook(h, v))?,
            Some(Bad::Sub(s)) => {
                p.refused(Call::LastSent(s))?;
                p.refused(Call::WriteSubStatus(s, StatusBuffer::default()))?;
            }
        }
        for (bi, u) in step.reads.iter().enumerate() {
            let Some(u) = u else { continue };
            let w = &mut world[bi];
            match u {
                Update::Whole(v) => *w = v.clone(),
                Update::Leaves(leaves) => {
                    for (leaf, v) in leaves {
                        *at(w, &subject.leaves[bi][*leaf].0) = v.clone();
                    }
                }
            }
            let name = &ir.buffers[c.reads[bi].index()].name;
            p.ok(Call::SetRead(name, w.clone()))?;
        }
        for (h, v) in c.hooks.iter().zip(&step.hooks) {
            if let Some(v) = v {
                p.ok(Call::SetHook(&h.name, v))?;
            }
        }
        for (s, a) in c.subordinates.iter().zip(&step.subs) {
            if let Some(a) = a {
                let name = &ir.controller(*s).name;
                let last = p.ok(Call::LastSent(name))?;
                let echo_serial = match a.echo {
                    Echo::Last => last,
                    Echo::Older(k) => last.wrapping_sub(k),
                    Echo::Any(x) => x,
                };
                let status = StatusBuffer {
                    echo_serial,
                    status: Status(a.status),
                    error: ErrorCode(a.error),
                    ..StatusBuffer::default()
                };
                p.ok(Call::WriteSubStatus(name, status))?;
            }
        }
        p.cycles(i, step.cycles)?;
    }
    Ok(())
}

/// A deterministic seed per plan (FNV-1a, spread by SplitMix64), so each
/// plan gets other sequences and every run the same ones.
fn seed(label: &str) -> [u8; 32] {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in label.bytes() {
        h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
    }
    let mut out = [0u8; 32];
    for chunk in out.chunks_mut(8) {
        h = h.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = h;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        chunk.copy_from_slice(&(z ^ (z >> 31)).to_le_bytes());
    }
    out
}

/// Run `SEQUENCES` sequences of the plan of `verb` on `subject`; `round`
/// picks other (but always the same) sequences.
fn run_plan(
    subject: &Subject<'_>,
    verb: usize,
    round: u32,
    stats: &Stats,
) -> Result<(), TestError<Sequence>> {
    let c = subject.controller();
    let label = format!(
        "{}/{}/{}/{round}",
        subject.set.path, c.name, c.commands[verb].name
    );
    let config = Config {
        cases: SEQUENCES,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner = TestRunner::new_with_rng(
        config,
        TestRng::from_seed(RngAlgorithm::ChaCha, &seed(&label)),
    );
    let values = Values::new(subject.ir, c);
    let strategy = values.sequences(c, &subject.leaves, verb);
    runner.run(&strategy, |seq| {
        run_sequence(subject, verb, &seq, stats).map_err(TestCaseError::fail)
    })
}

fn load(path: &str) -> Ir {
    let full = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path);
    let sets = rcs_dsl::load_paths(&[full]).unwrap_or_else(|e| panic!("{path}: {e}"));
    rcs_dsl::check(&sets[0], &rcs_dsl::Options::default())
        .ir
        .unwrap_or_else(|| panic!("{path}: the plan set checks clean"))
}

/// Whether row `position` of the plan of `verb` is listed in [`NEVER_FIRE`].
fn cannot_fire(set: &str, c: &Controller, verb: usize, position: u32) -> bool {
    NEVER_FIRE.iter().any(|(s, cn, v, pos, _)| {
        *s == set && *cn == c.name && *v == c.commands[verb].name && *pos == position
    })
}

/// What the sequences of one plan set showed.
#[derive(Default)]
struct Report {
    controllers: u64,
    plans: u64,
    rows: u64,
    sequences: u64,
    cycles: u64,
    calls: u64,
    /// Plans that needed more than one round, with the rounds.
    extra_rounds: Vec<String>,
    /// Divergences (at most one per plan: proptest stops at the first and shrinks it).
    divergences: Vec<String>,
    /// Rows in `NEVER_FIRE` that did not fire, as they should not.
    never: Vec<String>,
    /// Rows not in `NEVER_FIRE` that did not fire on both backends.
    unexpected: Vec<String>,
    /// Rows in `NEVER_FIRE` that fired.
    listed_but_fired: Vec<String>,
    /// Rows that fired on both, with how often (the fewer of the two).
    fired: Vec<(u64, String)>,
}

/// Every plan of `set`, through `SEQUENCES` sequences; while a row of the
/// plan (not in `NEVER_FIRE`) has not fired on both backends, more rounds
/// of `SEQUENCES`, at most `MAX_ROUNDS` in all (a deep chain of conjunctions
/// over inputs, e.g. 0004's, is reached only by a few sequences in a
/// thousand).
fn check_set(set: &PlanSet) -> Report {
    const MAX_ROUNDS: u32 = 5;
    let ir = load(set.path);
    let mut report = Report::default();
    for (ci, c) in ir.controllers.iter().enumerate() {
        report.controllers += 1;
        let subject = Subject::new(set, &ir, &ir, CtrlId(ci as u32));
        let stats = Stats::default();
        let missing = |verb: usize, p: &rcs_dsl::ir::Plan| {
            let fired = stats.fired.borrow();
            p.rows.iter().any(|r| {
                let key = (verb as u16, r.position as u16);
                let both = fired[0].contains_key(&key) && fired[1].contains_key(&key);
                !both && !cannot_fire(set.path, c, verb, r.position)
            })
        };
        for (verb, k) in c.commands.iter().enumerate() {
            let Some(p) = k.plan else { continue };
            report.plans += 1;
            let mut round = 0;
            while round < MAX_ROUNDS {
                if let Err(e) = run_plan(&subject, verb, round, &stats) {
                    report
                        .divergences
                        .push(format!("{} {} plan {}: {e}", set.path, c.name, k.name));
                    break;
                }
                round += 1;
                if !missing(verb, &c.plans[p.index()]) {
                    break;
                }
            }
            if round > 1 {
                report.extra_rounds.push(format!(
                    "{} {} plan {}: {round} rounds",
                    set.path, c.name, k.name
                ));
            }
        }
        report.sequences += stats.sequences.get();
        report.cycles += stats.cycles.get();
        report.calls += stats.calls.get();
        let fired = stats.fired.borrow();
        for (verb, k) in c.commands.iter().enumerate() {
            let Some(p) = k.plan else { continue };
            for r in &c.plans[p.index()].rows {
                report.rows += 1;
                let key = (verb as u16, r.position as u16);
                let times = [0, 1].map(|b| fired[b].get(&key).copied().unwrap_or(0));
                let name = format!(
                    "{} {} plan {} row {} ({})",
                    set.path,
                    c.name,
                    k.name,
                    r.position,
                    r.display_name()
                );
                match (
                    times.map(|t| t > 0),
                    cannot_fire(set.path, c, verb, r.position),
                ) {
                    ([true, true], false) => report.fired.push((times[0].min(times[1]), name)),
                    ([true, true], true) => report.listed_but_fired.push(name),
                    (_, true) => report.never.push(name),
                    (_, false) => report.unexpected.push(format!(
                        "{name}: fired {times:?} times (interpreter, generated)"
                    )),
                }
            }
        }
    }
    report
}

// ---------------------------------------------------------------- tests

#[test]
fn every_plan_runs_the_same_on_interpreter_and_generated_code() {
    let start = Instant::now();
    // The plan sets are independent: spread them over the cores.
    let next = AtomicUsize::new(0);
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get().min(4));
    let mut reports: Vec<(usize, Report)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(set) = SETS.get(i) else { break done };
                        done.push((i, check_set(set)));
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("a worker panicked"))
            .collect()
    });
    reports.sort_by_key(|(i, _)| *i);
    let mut all = Report::default();
    for (_, r) in reports {
        all.controllers += r.controllers;
        all.plans += r.plans;
        all.rows += r.rows;
        all.sequences += r.sequences;
        all.cycles += r.cycles;
        all.calls += r.calls;
        all.extra_rounds.extend(r.extra_rounds);
        all.divergences.extend(r.divergences);
        all.never.extend(r.never);
        all.unexpected.extend(r.unexpected);
        all.listed_but_fired.extend(r.listed_but_fired);
        all.fired.extend(r.fired);
    }
    println!(
        "differential: {} plan sets, {} controllers, {} plans, {} sequences, {} cycles, \
         {} driver calls; {}/{} rows fired on both backends; {} divergences; {:.1} s",
        SETS.len(),
        all.controllers,
        all.plans,
        all.sequences,
        all.cycles,
        all.calls,
        all.fired.len(),
        all.rows,
        all.divergences.len(),
        start.elapsed().as_secs_f64()
    );
    for r in &all.extra_rounds {
        println!("differential: more sequences: {r}");
    }
    all.fired.sort();
    for (t, name) in all.fired.iter().take(5) {
        println!("differential: rarely fired: {name}, {t} times");
    }
    for n in &all.never {
        println!("differential: never fired (cannot fire, see NEVER_FIRE): {n}");
    }
    assert!(
        all.divergences.is_empty(),
        "the interpreter and the generated code diverge:\n{}",
        all.divergences.join("\n\n")
    );
    assert!(
        all.unexpected.is_empty(),
        "rows that never fired on both backends (add inputs that reach them, \
         or list them in NEVER_FIRE with the reason):\n{}",
        all.unexpected.join("\n")
    );
    assert!(
        all.listed_but_fired.is_empty(),
        "rows listed in NEVER_FIRE that fired:\n{}",
        all.listed_but_fired.join("\n")
    );
    assert!(
        all.plans >= SETS.len() as u64 && all.sequences >= all.plans * u64::from(SEQUENCES),
        "every plan got its sequences"
    );
}

/// A broken code generator is caught: the interpreter runs figure13's RUN
/// plan with rows E2 (`S1 when ev.e2 -> S1`) and E3 (`S1 when ev.e3 -> S2`)
/// swapped — both can be true in S1, so precedence decides — against the
/// generated code of the plan as written. The rows keep their `position`,
/// so a fired id still names the row as written: only precedence differs.
#[test]
fn a_swapped_row_is_caught() {
    let set = SETS
        .iter()
        .find(|s| s.path == "plans/figure13")
        .expect("plans/figure13 is compiled");
    let ir = load(set.path);
    let ctrl = ir.controller_by_name("GX").expect("GX");
    let mut mutant = ir.clone();
    let c = &mut mutant.controllers[ctrl.index()];
    let verb = c
        .commands
        .iter()
        .position(|k| k.name == "RUN")
        .expect("RUN");
    let plan = &mut c.plans[c.commands[verb].plan.expect("a plan").index()];
    let e2 = plan
        .rows
        .iter()
        .position(|r| r.label == Some(2))
        .expect("E2");
    let e3 = plan
        .rows
        .iter()
        .position(|r| r.label == Some(3))
        .expect("E3");
    assert_eq!(e3, e2 + 1, "E2 and E3 are adjacent");
    assert_eq!(
        plan.rows[e2].from, plan.rows[e3].from,
        "E2 and E3 leave one state"
    );
    for r in [e2, e3] {
        assert!(
            matches!(plan.rows[r].cond, Condition::When(_)) && !plan.rows[r].is_dont_care(),
            "E2 and E3 are plain rows"
        );
        assert!(matches!(plan.rows[r].from, From::State(_)));
    }
    plan.rows.swap(e2, e3);

    let subject = Subject::new(set, &ir, &mutant, ctrl);
    let stats = Stats::default();
    match run_plan(&subject, verb, 0, &stats) {
        Ok(()) => panic!(
            "{} sequences of {} cycles missed the swapped rows",
            stats.sequences.get(),
            stats.cycles.get()
        ),
        Err(TestError::Fail(reason, minimal)) => {
            let reason = reason.message();
            println!("mutant caught; minimal sequence {minimal:?}\n{reason}");
            assert!(
                reason.starts_with("divergence between interpreter and generated code"),
                "caught as a divergence, not a crash: {reason}"
            );
            // Shrunk to the essentials: RUN, then at most a few steps.
            assert!(minimal.steps.len() <= 3, "shrunk: {minimal:?}");
        }
        Err(e) => panic!("not a divergence: {e}"),
    }
}
