//! Stage 3a, after the analysis: a finding made reproducible. A [`Run`]
//! drives a fresh controller — the command, then steps of inputs held for
//! some cycles, each with what must be seen — until the finding happens on
//! the reference interpreter. Built by [`super::path`] from the analysis's
//! witnesses, attached to diagnostics by the checks, replayed by
//! [`replay`] and written by [`scenario_text`] as a `*.scenario.yaml` that
//! `rcsc test` runs (the CLI's `check --witnesses`).
//!
//! One model serves every "can happen" lint: a hang or stall is a step
//! where no row fires ([`Expect::Stays`]); an oscillation is a step where a
//! sequence of rows fires over and over ([`Expect::Repeats`]); a command
//! storm is the same with one row ([`RunStep::fires_each_cycle`]).
//!
//! A run holds only what a scenario can set: `reads` buffers, hook results,
//! subordinate statuses and their status fields. Vars, counters and
//! `new_command` follow from the steps; a run that needs other values of
//! them is not built. Values
//! are kept as a scenario writes them (JSON), so the diagnostic's JSON, the
//! scenario file and the replay read the same thing.

use crate::interp;
use crate::ir::{CtrlId, Ir, Type};
use crate::source::SourceFile;
use rcs_runtime::driver::Value;
use serde::Serialize;
use serde_json::Value as Json;
use std::collections::BTreeMap;

/// A way to make a finding happen, from a fresh controller.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Run {
    pub controller: String,
    /// The command issued before the first step's first cycle.
    pub command: String,
    /// Its parameters, by name (a JSON object; empty for none).
    pub params: BTreeMap<String, Json>,
    pub steps: Vec<RunStep>,
}

/// Inputs set before a step's first cycle (and held after it, until set
/// again), how many cycles it runs, and what those cycles must show.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RunStep {
    /// `reads` buffers, each whole, by name.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub reads: BTreeMap<String, Json>,
    /// Hook results, by hook name.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub hooks: BTreeMap<String, Json>,
    /// Subordinate statuses (echoing the last command sent), by name.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub subordinates: BTreeMap<String, String>,
    /// Subordinates' status fields, by subordinate then field name: each
    /// published from this step on, until set again.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub status_fields: BTreeMap<String, BTreeMap<String, Json>>,
    pub cycles: u32,
    pub expect: Expect,
    /// A new command issued before the step's first cycle (a run of
    /// several commands: `read_before_assign`); the run's own command
    /// goes before the first step.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command: Option<RunCommand>,
    /// Vars the step's last cycle must leave, each whole, by name (a
    /// wrapped or zero-divided value that the scenario then checks).
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub expect_vars: BTreeMap<String, Json>,
}

/// A command and its parameters, by name.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RunCommand {
    pub verb: String,
    pub params: BTreeMap<String, Json>,
}

impl RunCommand {
    /// As a scenario writes it: `VERB`, or `{ VERB: { param: value } }`.
    fn json(&self) -> Json {
        if self.params.is_empty() {
            return Json::String(self.verb.clone());
        }
        let params: serde_json::Map<String, Json> = self.params.clone().into_iter().collect();
        let mut m = serde_json::Map::new();
        m.insert(self.verb.clone(), Json::Object(params));
        Json::Object(m)
    }
}

/// What the cycles of a step must show. Rows go by their display name
/// (`E3`, `*2`, `otherwise`, `#4`), states by name.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Expect {
    /// No row fires until the last cycle (waiting for a counter), where
    /// `row` fires and leaves the plan in `state`.
    Fires { row: String, state: String },
    /// No row fires on any cycle: the plan stays in `state` (a hang, or a
    /// stall on a subordinate's status).
    Stays { state: String },
    /// On cycle `i` of the step, `rows[i % rows.len()]` fires and leaves
    /// the plan in its state: an oscillation, or with one row a command
    /// storm.
    Repeats { rows: Vec<Firing> },
    /// No row fires until the last cycle, where an index by a value falls
    /// outside its array and the plan ends with `INDEX_RANGE`: in `row`'s
    /// jobs, or (`None`) in a condition, no row firing.
    IndexRange { row: Option<String> },
}

impl Default for Expect {
    fn default() -> Self {
        Expect::Stays { state: "S0".into() }
    }
}

/// A row that fires and the state it leaves the plan in.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Firing {
    pub row: String,
    pub state: String,
}

impl Expect {
    /// What must fire on cycle `i` of a step of `cycles` cycles (`None`:
    /// no row).
    fn fired_on(&self, i: u32, cycles: u32) -> Option<&str> {
        match self {
            Expect::Fires { row, .. } => (i + 1 == cycles).then_some(row.as_str()),
            Expect::IndexRange { row } => row.as_deref().filter(|_| i + 1 == cycles),
            Expect::Stays { .. } => None,
            Expect::Repeats { rows } if rows.is_empty() => None,
            Expect::Repeats { rows } => Some(rows[i as usize % rows.len()].row.as_str()),
        }
    }

    /// The rows this expectation fires, without repeats.
    pub fn fired_rows(&self) -> Vec<&str> {
        let mut rows: Vec<&str> = match self {
            Expect::Fires { row, .. } => vec![row],
            Expect::IndexRange { row } => row.iter().map(String::as_str).collect(),
            Expect::Stays { .. } => Vec::new(),
            Expect::Repeats { rows } => rows.iter().map(|f| f.row.as_str()).collect(),
        };
        rows.dedup();
        rows
    }

    /// The row fired on the last cycle and the state after it (`None`:
    /// the plan ended with `INDEX_RANGE`, in no state a scenario names).
    fn last(&self, cycles: u32) -> (Option<&str>, Option<&str>) {
        let (fired, state) = match self {
            Expect::IndexRange { row } => return (row.as_deref(), None),
            _ => self.last_in_state(cycles),
        };
        (fired, Some(state))
    }

    fn last_in_state(&self, cycles: u32) -> (Option<&str>, &str) {
        match self {
            Expect::IndexRange { .. } => (None, "S0"),
            Expect::Fires { row, state } => (Some(row), state),
            Expect::Stays { state } => (None, state),
            Expect::Repeats { rows } => {
                match rows.get((cycles.max(1) as usize - 1) % rows.len().max(1)) {
                    Some(f) => (Some(&f.row), &f.state),
                    None => (None, "S0"),
                }
            }
        }
    }
}

impl RunStep {
    /// This step with its inputs held while `row` fires on each of its
    /// cycles, leaving the plan in `state`: a command storm.
    pub fn fires_each_cycle(self, row: String, state: String) -> RunStep {
        RunStep {
            expect: Expect::Repeats {
                rows: vec![Firing { row, state }],
            },
            ..self
        }
    }
}

impl Run {
    /// Row names (`None`: no row) cycle by cycle, over the whole run.
    fn fired_per_cycle(&self) -> Vec<Option<&str>> {
        let mut out = Vec::new();
        for s in &self.steps {
            for i in 0..s.cycles {
                out.push(s.expect.fired_on(i, s.cycles));
            }
        }
        out
    }
}

/// `run` as a `*.scenario.yaml` named `name`: the command on the first
/// step, each step's inputs, and its expectations after its last cycle.
/// A comment says which finding it reproduces (`about`).
pub fn scenario_text(run: &Run, name: &str, about: &str) -> Result<String, String> {
    #[derive(Serialize)]
    struct File<'a> {
        name: &'a str,
        controller: &'a str,
        steps: Vec<StepFile<'a>>,
    }
    #[derive(Serialize)]
    struct StepFile<'a> {
        #[serde(skip_serializing_if = "Option::is_none")]
        command: Option<Json>,
        #[serde(skip_serializing_if = "BTreeMap::is_empty")]
        reads: &'a BTreeMap<String, Json>,
        #[serde(skip_serializing_if = "BTreeMap::is_empty")]
        hooks: &'a BTreeMap<String, Json>,
        #[serde(skip_serializing_if = "BTreeMap::is_empty")]
        subordinates: BTreeMap<String, Json>,
        cycles: u32,
        expect: ExpectFile<'a>,
    }
    #[derive(Serialize)]
    struct ExpectFile<'a> {
        fired: &'a str,
        #[serde(skip_serializing_if = "Option::is_none")]
        state: Option<&'a str>,
        #[serde(skip_serializing_if = "Option::is_none")]
        status: Option<&'a str>,
        #[serde(skip_serializing_if = "Option::is_none")]
        error: Option<&'a str>,
        #[serde(skip_serializing_if = "BTreeMap::is_empty")]
        vars: &'a BTreeMap<String, Json>,
    }
    let command = RunCommand {
        verb: run.command.clone(),
        params: run.params.clone(),
    }
    .json();
    // A run holds a subordinate's status until set again, answering each
    // new command; a scenario step's answer binds only that step, so every
    // step repeats the answers in force.
    let mut held: BTreeMap<String, String> = BTreeMap::new();
    let held_per_step: Vec<BTreeMap<String, String>> = run
        .steps
        .iter()
        .map(|s| {
            held.extend(s.subordinates.clone());
            held.clone()
        })
        .collect();
    let steps = run
        .steps
        .iter()
        .zip(&held_per_step)
        .enumerate()
        .map(|(i, (s, subordinates))| {
            let (fired, state) = s.expect.last(s.cycles);
            let ended = matches!(s.expect, Expect::IndexRange { .. });
            let mut subordinates: BTreeMap<String, Json> = subordinates
                .iter()
                .map(|(x, status)| (x.clone(), Json::String(status.clone())))
                .collect();
            // A subordinate whose status fields the step sets: its status
            // in force (or, never set, the scene's start: NOT_READY with
            // echo 0) and the fields, in one setting.
            for (x, fields) in &s.status_fields {
                let mut m = serde_json::Map::new();
                match subordinates.get(x) {
                    Some(status) => {
                        m.insert("status".into(), status.clone());
                    }
                    None => {
                        m.insert("status".into(), Json::String("NOT_READY".into()));
                        m.insert("echo".into(), Json::from(0));
                    }
                }
                m.extend(fields.clone());
                subordinates.insert(x.clone(), Json::Object(m));
            }
            StepFile {
                command: if i == 0 {
                    Some(command.clone())
                } else {
                    s.command.as_ref().map(RunCommand::json)
                },
                reads: &s.reads,
                hooks: &s.hooks,
                subordinates,
                cycles: s.cycles.max(1),
                expect: ExpectFile {
                    fired: fired.unwrap_or("none"),
                    state,
                    status: ended.then_some("ERROR"),
                    error: ended.then_some("INDEX_RANGE"),
                    vars: &s.expect_vars,
                },
            }
        })
        .collect();
    let file = File {
        name,
        controller: &run.controller,
        steps,
    };
    let body = crate::yaml::to_string(&file).map_err(|e| e.to_string())?;
    let mut out = String::new();
    for line in about.lines() {
        out.push_str("# ");
        out.push_str(line);
        out.push('\n');
    }
    out.push_str(&body);
    Ok(out)
}

/// Replay `run` on the reference interpreter, controller `ctrl` fresh:
/// `Err` says what did not happen as the run says, cycle by cycle.
pub fn replay(ir: &Ir, ctrl: CtrlId, run: &Run) -> Result<(), String> {
    replay_on(ir, ctrl, run).map(|_| ())
}

/// [`replay`], returning the interpreter as the run leaves it (the path
/// search reads vars and counters from it). The run goes through its
/// scenario text, so what `rcsc test` runs is what is replayed here.
pub(crate) fn replay_on<'ir>(
    ir: &'ir Ir,
    ctrl: CtrlId,
    run: &Run,
) -> Result<interp::Driven<'ir>, String> {
    if ir.controller_by_name(&run.controller) != Some(ctrl) {
        return Err(format!("the run drives `{}`", run.controller));
    }
    let text = scenario_text(run, "witness", "")?;
    let file = SourceFile::new("witness.scenario.yaml", text);
    let scenario = crate::scenario::parse(ir, &file, "witness")
        .map_err(|e| format!("line {}: {}", e.line, e.message))?;
    let mut driven = interp::Driven::new(ir, ctrl);
    let outcome = crate::scenario::run_on(ir, &scenario, &mut driven);
    if let Some((line, report)) = outcome.failure {
        return Err(format!("line {line}: {report}"));
    }
    let want = run.fired_per_cycle();
    if want.len() as u64 != outcome.cycles() {
        return Err(format!(
            "{} cycles run, {} expected",
            outcome.cycles(),
            want.len()
        ));
    }
    for (cycle, (w, got)) in want.iter().zip(outcome.fired_per_cycle()).enumerate() {
        let w = w.unwrap_or("-");
        if w != got {
            return Err(format!(
                "cycle {}: expected {w} to fire, got {got}",
                cycle + 1
            ));
        }
    }
    Ok(driven)
}

/// A run-time value as a scenario writes it; `None` for what a scenario
/// cannot write (NaN and infinities, statuses inside buffers, integers
/// past 64 bits).
pub fn json_of(ir: &Ir, ty: &Type, v: &Value) -> Option<Json> {
    Some(match (ty, v) {
        (_, Value::Bool(b)) => Json::Bool(*b),
        (_, Value::Int(i)) => match (i64::try_from(*i), u64::try_from(*i)) {
            (Ok(i), _) => Json::from(i),
            (_, Ok(u)) => Json::from(u),
            _ => return None,
        },
        (_, Value::Float(f)) => Json::Number(serde_json::Number::from_f64(*f)?),
        (Type::Enum(e), Value::Enum(i)) => {
            Json::String(ir.enums[e.index()].variants.get(*i as usize)?.name.clone())
        }
        (Type::Buffer(b), Value::Buffer(fields)) => {
            let bt = &ir.buffer_types[b.index()];
            let mut m = serde_json::Map::new();
            for (f, v) in bt.fields.iter().zip(fields) {
                m.insert(f.name.clone(), json_of(ir, &f.ty, v)?);
            }
            Json::Object(m)
        }
        (Type::Array(e, _), Value::Array(xs)) => Json::Array(
            xs.iter()
                .map(|x| json_of(ir, e, x))
                .collect::<Option<_>>()?,
        ),
        _ => return None,
    })
}

/// A row as a run and a scenario name it: `E3`, its position, as
/// everywhere else.
pub fn row_name(row: &crate::ir::Row) -> String {
    format!("E{}", row.position)
}
