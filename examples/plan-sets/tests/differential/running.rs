//! The differential test's runner: one sequence played on the interpreter
//! and the generated code alike, the records compared after every cycle,
//! and the per-plan loop with its coverage.

use super::inputs::*;
use super::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestError, TestRng, TestRunner};
use rcs_dsl::interp;
use rcs_dsl::ir::{Controller, CtrlId, Ir, Type};
use rcs_plan_sets::PlanSet;
use rcs_runtime::driver::{DriveError, Driven, Value};
use rcs_runtime::{ErrorCode, Status, StatusBuffer};
use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::path::Path;

/// One controller of one plan set: the interpreter runs `interp_ir` (the
/// mutation test alters it), the generated code comes from `set`, and the
/// inputs are drawn from `ir`.
pub(crate) struct Subject<'a> {
    pub(crate) set: &'a PlanSet,
    pub(crate) ir: &'a Ir,
    pub(crate) interp_ir: &'a Ir,
    pub(crate) ctrl: CtrlId,
    /// Per `reads` buffer, its scalars ([`leaves`]).
    pub(crate) leaves: Vec<Vec<(Vec<usize>, Type)>>,
}

impl<'a> Subject<'a> {
    pub(crate) fn new(
        set: &'a PlanSet,
        ir: &'a Ir,
        interp_ir: &'a Ir,
        ctrl: CtrlId,
    ) -> Subject<'a> {
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

    pub(crate) fn controller(&self) -> &Controller {
        self.ir.controller(self.ctrl)
    }
}

/// A driver call, applied to both backends alike.
#[derive(Clone, Debug)]
pub(crate) enum Call<'a> {
    Command(&'a str, &'a [Value]),
    /// The buffer as a whole: the world's copy after this step's update.
    SetRead(&'a str, Value),
    SetHook(&'a str, &'a Value),
    /// A var or status field, before the first command.
    SetVar(&'a str, &'a Value),
    WriteSubStatus(&'a str, StatusBuffer),
    LastSent(&'a str),
    /// A subordinate publishes one of its status fields.
    WriteSubField(&'a str, &'a str, &'a Value),
}

impl Call<'_> {
    pub(crate) fn apply(&self, d: &mut dyn Driven) -> Result<u32, DriveError> {
        match *self {
            Call::Command(verb, args) => d.command(verb, args),
            Call::SetRead(buffer, ref v) => d.set_read(buffer, v).map(|()| 0),
            Call::SetHook(hook, v) => d.set_hook(hook, v).map(|()| 0),
            Call::SetVar(var, v) => d.set_var(var, v).map(|()| 0),
            Call::WriteSubStatus(sub, s) => d.write_sub_status(sub, s).map(|()| 0),
            Call::LastSent(sub) => d.last_sent(sub),
            Call::WriteSubField(sub, field, v) => d.write_sub_field(sub, field, v).map(|()| 0),
        }
    }
}

/// What a sequence did, for the failure message.
pub(crate) enum Entry<'a> {
    Call(Call<'a>, Result<u32, DriveError>),
    Cycles(u32),
}

/// Totals and coverage over the sequences of one controller.
#[derive(Default)]
pub(crate) struct Stats {
    pub(crate) sequences: Cell<u64>,
    pub(crate) cycles: Cell<u64>,
    pub(crate) calls: Cell<u64>,
    /// How often each `(verb, row)` fired, per backend (interpreter, generated).
    pub(crate) fired: RefCell<[BTreeMap<(u16, u16), u64>; 2]>,
}

/// The two backends and what they were given.
pub(crate) struct Pair<'a> {
    pub(crate) subject: &'a Subject<'a>,
    pub(crate) verb: &'a str,
    pub(crate) interp: interp::Driven<'a>,
    pub(crate) generated: Box<dyn Driven>,
    pub(crate) log: Vec<Entry<'a>>,
    pub(crate) stats: &'a Stats,
    /// The sequence started from random vars: a row of `NEVER_FIRE` (which
    /// cannot fire from the declared initial values) may fire, and is not
    /// counted.
    pub(crate) explore: bool,
}

impl<'a> Pair<'a> {
    pub(crate) fn call(&mut self, call: Call<'a>) -> Result<Result<u32, DriveError>, String> {
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
    pub(crate) fn ok(&mut self, call: Call<'a>) -> Result<u32, String> {
        let what = format!("{call:?}");
        self.call(call)?
            .map_err(|e| format!("the test's own call {what} was refused by both: {e}"))
    }

    /// An ill-formed call: both backends must refuse it.
    pub(crate) fn refused(&mut self, call: Call<'a>) -> Result<(), String> {
        let what = format!("{call:?}");
        match self.call(call)? {
            Err(_) => Ok(()),
            Ok(r) => Err(format!("both backends accepted the ill-formed {what}: {r}")),
        }
    }

    pub(crate) fn cycles(&mut self, step: usize, n: u32) -> Result<(), String> {
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
            let s = self.subject;
            for (count, r) in fired.iter_mut().zip([&a, &b]) {
                if let (Some(v), Some(f)) = (r.verb, r.fired) {
                    let listed =
                        || cannot_fire(s.set.path, s.controller(), usize::from(v), u32::from(f));
                    if !(self.explore && listed()) {
                        *count.entry((v, f)).or_default() += 1;
                    }
                }
            }
        }
        Ok(())
    }

    pub(crate) fn divergence(&self, what: &str) -> String {
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
pub(crate) fn run_sequence(
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
        explore: seq.vars.is_some(),
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
    if let Some(vars) = &seq.vars {
        for (var, v) in c.vars.iter().zip(vars) {
            p.ok(Call::SetVar(&var.name, v))?;
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
                p.refused(Call::WriteSubField(s, "status", &Value::Unit))?;
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
                let status = if a.refused {
                    StatusBuffer {
                        echo_serial: echo_serial.wrapping_sub(1),
                        status: Status(a.status),
                        refused_serial: echo_serial,
                        ..StatusBuffer::default()
                    }
                } else {
                    StatusBuffer {
                        echo_serial,
                        status: Status(a.status),
                        error: ErrorCode(a.error),
                        ..StatusBuffer::default()
                    }
                };
                p.ok(Call::WriteSubStatus(name, status))?;
                let sub = ir.controller(*s);
                for ((_, f), v) in sub.status_fields().zip(&a.fields) {
                    p.ok(Call::WriteSubField(name, &f.name, v))?;
                }
            }
        }
        if step.all_done {
            for s in &c.subordinates {
                let name = &ir.controller(*s).name;
                let echo_serial = p.ok(Call::LastSent(name))?;
                let status = StatusBuffer {
                    echo_serial,
                    status: Status::DONE,
                    ..StatusBuffer::default()
                };
                p.ok(Call::WriteSubStatus(name, status))?;
            }
        }
        if seq.live_reads {
            // A live writer: every buffer written again, as it stands,
            // before each cycle of the step.
            for _ in 0..step.cycles {
                for (b, w) in c.reads.iter().zip(&world) {
                    p.ok(Call::SetRead(&ir.buffers[b.index()].name, w.clone()))?;
                }
                p.cycles(i, 1)?;
            }
        } else {
            p.cycles(i, step.cycles)?;
        }
    }
    Ok(())
}

/// A deterministic seed per plan (FNV-1a, spread by SplitMix64), so each
/// plan gets other sequences and every run the same ones.
pub(crate) fn seed(label: &str) -> [u8; 32] {
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
/// picks other (but always the same) sequences. The error is boxed: it
/// holds the minimal sequence, which is large.
pub(crate) fn run_plan(
    subject: &Subject<'_>,
    verb: usize,
    round: u32,
    stats: &Stats,
) -> Result<(), Box<TestError<Sequence>>> {
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
    // The first round starts every sequence from the declared initial
    // values; later rounds (for rows still missing) explore further.
    let strategy = values.sequences(c, &subject.leaves, verb, round > 0);
    runner
        .run(&strategy, |seq| {
            run_sequence(subject, verb, &seq, stats).map_err(TestCaseError::fail)
        })
        .map_err(Box::new)
}

pub(crate) fn load(path: &str) -> Ir {
    let full = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path);
    let sets = rcs_dsl::load_paths(&[full]).unwrap_or_else(|e| panic!("{path}: {e}"));
    rcs_dsl::check(&sets[0], &rcs_dsl::Options::default())
        .ir
        .unwrap_or_else(|| panic!("{path}: the plan set checks clean"))
}

/// Whether row `position` of the plan of `verb` is listed in [`NEVER_FIRE`].
pub(crate) fn cannot_fire(set: &str, c: &Controller, verb: usize, position: u32) -> bool {
    NEVER_FIRE.iter().any(|(s, cn, v, pos, _)| {
        *s == set && *cn == c.name && *v == c.commands[verb].name && *pos == position
    })
}

/// What the sequences of one plan set showed.
#[derive(Default)]
pub(crate) struct Report {
    pub(crate) controllers: u64,
    pub(crate) plans: u64,
    pub(crate) rows: u64,
    pub(crate) sequences: u64,
    pub(crate) cycles: u64,
    pub(crate) calls: u64,
    /// Plans that needed more than one round, with the rounds.
    pub(crate) extra_rounds: Vec<String>,
    /// Divergences (at most one per plan: proptest stops at the first and shrinks it).
    pub(crate) divergences: Vec<String>,
    /// Rows in `NEVER_FIRE` that did not fire, as they should not.
    pub(crate) never: Vec<String>,
    /// Rows not in `NEVER_FIRE` that did not fire on both backends.
    pub(crate) unexpected: Vec<String>,
    /// Rows in `NEVER_FIRE` that fired.
    pub(crate) listed_but_fired: Vec<String>,
    /// Rows that fired on both, with how often (the fewer of the two).
    pub(crate) fired: Vec<(u64, String)>,
}

/// Every plan of `set`, through `SEQUENCES` sequences; while a row of the
/// plan (not in `NEVER_FIRE`) has not fired on both backends, more rounds
/// of `SEQUENCES`, at most `MAX_ROUNDS` in all (a deep chain of conjunctions
/// over inputs, e.g. 0004's, is reached only by a few sequences in a
/// thousand).
pub(crate) fn check_set(set: &PlanSet) -> Report {
    const MAX_ROUNDS: u32 = 8;
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
