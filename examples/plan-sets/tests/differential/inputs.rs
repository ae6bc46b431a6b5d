//! The differential test's inputs: random values of the IR's types, driver
//! calls both backends must refuse alike, and the random sequences of
//! steps played on both.

use super::*;
use proptest::sample::select;
use rcs_dsl::interp;
use rcs_dsl::ir::{Controller, ExprKind, Ir, SubProp, Type};
use rcs_runtime::driver::Value;
use rcs_runtime::{ErrorCode, Status};

/// What a subordinate's status buffer echoes.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Echo {
    /// The serial the controller last sent it.
    Last,
    /// That serial minus this (a stale answer to an older command).
    Older(u32),
    /// Any serial.
    Any(u32),
}

/// A subordinate writes its status buffer.
#[derive(Clone, Debug)]
pub(crate) struct Answer {
    pub(crate) echo: Echo,
    pub(crate) status: u16,
    pub(crate) error: u16,
    /// The answered serial is refused (the echo stays one before it).
    pub(crate) refused: bool,
    /// The subordinate's status fields (`status NAME: TYPE`), in order.
    pub(crate) fields: Vec<Value>,
}

/// A driver call both backends must refuse alike.
#[derive(Clone, Debug)]
pub(crate) enum Bad {
    Command(String, Vec<Value>),
    Read(String, Value),
    Hook(String, Value),
    Sub(String),
}

/// The world changes a `reads` buffer.
#[derive(Clone, Debug)]
pub(crate) enum Update {
    /// All of it.
    Whole(Value),
    /// A few of its scalars (index into the buffer's [`leaves`], value):
    /// sensors change a little at a time, so conditions met earlier stay
    /// met while the plan waits for the next one.
    Leaves(Vec<(usize, Value)>),
}

/// The paths (field and element indices) to every scalar of type `t`, with
/// their types.
pub(crate) fn leaves(ir: &Ir, t: &Type, path: &mut Vec<usize>, out: &mut Vec<(Vec<usize>, Type)>) {
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
pub(crate) fn at<'v>(v: &'v mut Value, path: &[usize]) -> &'v mut Value {
    match (path.split_first(), v) {
        (None, v) => v,
        (Some((i, rest)), Value::Buffer(xs) | Value::Array(xs)) => at(&mut xs[*i], rest),
        (Some(_), v) => panic!("no path into {v:?}"),
    }
}

/// One step of a sequence: inputs, then `cycles` cycles.
#[derive(Clone, Debug)]
pub(crate) struct Step {
    /// A new command: verb index and arguments.
    pub(crate) command: Option<(usize, Vec<Value>)>,
    pub(crate) bad: Option<Bad>,
    /// Per `reads` buffer, an update.
    pub(crate) reads: Vec<Option<Update>>,
    /// Per hook, a new result.
    pub(crate) hooks: Vec<Option<Value>>,
    /// Per subordinate, an answer.
    pub(crate) subs: Vec<Option<Answer>>,
    /// Then every subordinate answers its latest command with DONE (a
    /// supervisor waiting for all of them is otherwise rarely answered).
    pub(crate) all_done: bool,
    pub(crate) cycles: u32,
}

/// A sequence: the world's first `reads` values, perhaps a world model to
/// start from, the plan's verb with these arguments, then the steps.
#[derive(Clone, Debug)]
pub(crate) struct Sequence {
    pub(crate) reads: Vec<Option<Value>>,
    /// One value per var (status fields included), set before the first
    /// command as a scenario's `initial: vars` does; `None` starts from
    /// the declared initial values.
    pub(crate) vars: Option<Vec<Value>>,
    pub(crate) args: Vec<Value>,
    pub(crate) steps: Vec<Step>,
    /// Every `reads` buffer is written again before every cycle, as a live
    /// writer (a fieldbus master) does, so its watchdog stays at 0 through a
    /// long step; otherwise a buffer is written only by the steps that
    /// update it.
    pub(crate) live_reads: bool,
}

/// Random values of the IR's types for one controller.
pub(crate) struct Values<'a> {
    pub(crate) ir: &'a Ir,
    /// Integer literals of the controller's expressions, ±1, negated.
    pub(crate) ints: Vec<i128>,
    /// Float literals (and the integer ones as floats), ±1, negated.
    pub(crate) floats: Vec<f64>,
}

impl<'a> Values<'a> {
    pub(crate) fn new(ir: &'a Ir, c: &Controller) -> Values<'a> {
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
            // An array indexed by a value: its last index and the first
            // ones past it, so that both in-range and out-of-range indices
            // (INDEX_RANGE) come up (0 and -1 are always there).
            ExprKind::IndexBy(ref base, _) => {
                if let Type::Array(_, n) = base.ty {
                    let n = i128::from(n);
                    ints.extend([n - 1, n, n + 1]);
                }
            }
            _ => {}
        };
        for p in &c.plans {
            for r in &p.rows {
                r.visit_exprs(&mut harvest);
            }
        }
        for b in c.pre.iter().chain(c.post.iter()) {
            b.visit_exprs(&mut harvest);
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
    pub(crate) fn of(&self, t: &Type) -> BoxedStrategy<Value> {
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
            // No error, a built-in code, or one the controller declares.
            Type::ErrorCode(c) => {
                let declared = self.ir.controller(*c).errors.len() as u16;
                let codes: Vec<Value> = [0u16]
                    .into_iter()
                    .chain(rcs_dsl::error_codes::BUILTIN.iter().map(|(_, k)| k.0))
                    .chain((0..declared).map(|i| rcs_runtime::ErrorCode::custom(i).0))
                    .map(|k| Value::Int(i128::from(k)))
                    .collect();
                select(codes).boxed()
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
    pub(crate) fn args(&self, c: &Controller, verb: usize) -> BoxedStrategy<Vec<Value>> {
        c.commands[verb]
            .params
            .iter()
            .map(|p| self.of(&p.ty))
            .collect::<Vec<_>>()
            .boxed()
    }

    /// A value `t` refuses (out of range or of another shape).
    pub(crate) fn wrong(&self, t: &Type) -> Value {
        match t {
            Type::Int(it) => Value::Int(it.range().1 + 1),
            Type::Enum(e) => Value::Enum(self.ir.enums[e.index()].variants.len() as u32),
            Type::Float(_) => Value::Int(0),
            _ => Value::Unit,
        }
    }

    /// Ill-formed calls for `c`.
    pub(crate) fn bad_calls(&self, c: &Controller) -> Vec<Bad> {
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

    /// Sequences for the plan of command `verb` of `c`. With `explore`,
    /// one sequence in two starts from a world model of random values, and
    /// about one step in three ends with every subordinate answering DONE: a plan
    /// valid only in some states of its vars, waiting each time for all
    /// its subordinates (a PackML unit's commands), is reached no other
    /// way in thirty steps; and one sequence in two has a live writer for
    /// its `reads` buffers (see [`Sequence::live_reads`]): a state timeout
    /// longer than a frame watchdog on the buffer (a drive's 500 ms move
    /// under a 10 ms watchdog) is reached no other way. Without it every
    /// sequence starts from the declared initial values, no step is added
    /// and no buffer is live, and no randomness is drawn for any of them,
    /// so the sequences stay what they were.
    pub(crate) fn sequences(
        &self,
        c: &Controller,
        read_leaves: &[Vec<(Vec<usize>, Type)>],
        verb: usize,
        explore: bool,
    ) -> impl Strategy<Value = Sequence> {
        let ir = self.ir;
        let vars = if explore && !c.vars.is_empty() {
            let each: Vec<_> = c.vars.iter().map(|v| self.of(&v.ty)).collect();
            proptest::option::weighted(0.5, each).boxed()
        } else {
            Just(None).boxed()
        };
        let live_reads = if explore && !c.reads.is_empty() {
            proptest::bool::weighted(0.5).boxed()
        } else {
            Just(false).boxed()
        };
        let all_done = if explore && !c.subordinates.is_empty() {
            proptest::bool::weighted(0.3).boxed()
        } else {
            Just(false).boxed()
        };
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
                let fields: Vec<_> = sub.status_fields().map(|(_, v)| self.of(&v.ty)).collect();
                // A subordinate that can refuse (`accept when`) now
                // and then refuses the command it answers.
                let refused = if sub.can_refuse() {
                    proptest::bool::weighted(0.2).boxed()
                } else {
                    Just(false).boxed()
                };
                // A supervisor that reads `X.error_code` also meets X's
                // built-in codes (an unchanged strategy for the others, so
                // their sequences stay the same).
                let reads_code = c.plans.iter().flat_map(|p| &p.rows).any(|r| {
                    let mut found = false;
                    r.visit_exprs(&mut |e| {
                        found |= matches!(e.kind, ExprKind::Sub(x, SubProp::ErrorCode) if x == *s)
                    });
                    found
                });
                let error = if reads_code {
                    prop_oneof![
                        3 => 0..errors,
                        1 => select(vec![
                            ErrorCode::UNKNOWN_COMMAND.0,
                            ErrorCode::INDEX_RANGE.0,
                            ErrorCode::HOOK_PANIC.0,
                        ]),
                    ]
                    .boxed()
                } else {
                    (0..errors).boxed()
                };
                let answer = (echo, status, error, fields, refused).prop_map(
                    |(echo, status, error, fields, refused)| Answer {
                        echo,
                        status,
                        error,
                        fields,
                        refused,
                    },
                );
                proptest::option::weighted(0.4, answer)
            })
            .collect();
        let cycles = prop_oneof![98 => Just(1u32), 2 => 50u32..=300];
        let step = (command, bad, updates, hooks, subs, all_done, cycles).prop_map(
            |(command, bad, reads, hooks, subs, all_done, cycles)| Step {
                command,
                bad,
                reads,
                hooks,
                subs,
                all_done,
                cycles,
            },
        );
        (
            whole,
            vars,
            self.args(c, verb),
            proptest::collection::vec(step, 1..=MAX_STEPS),
            live_reads,
        )
            .prop_map(|(reads, vars, args, steps, live_reads)| Sequence {
                reads,
                vars,
                args,
                steps,
                live_reads,
            })
    }
}
