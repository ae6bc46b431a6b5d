//! Reading a scenario: the first part of `rcsc test` after the plans are
//! checked. The YAML (through [`crate::yaml`], booleans only `true` and
//! `false`, so that `command: ON` is a verb) is read into raw types, then
//! every name is resolved against the controller of the IR and every value
//! typed ([`super::values`]), so that a scenario that runs names only what
//! exists. Every problem is a [`ScenarioError`] with its line.
//!
//! This module reads the file and its steps in order ([`parse`]) with a
//! [`Resolver`] of the controller; what the resolver reads sits beside:
//! `step` a step's settings (`command`, `reads`, `hooks`, `cycles`,
//! `silent`) and `initial:`, `subordinate` how a subordinate answers,
//! `expect` a step's `expect:`, `entries` the YAML shapes both this reader
//! and the system reader (`super::system_read`) take.

mod entries;
mod expect;
mod step;
mod subordinate;

pub(super) use entries::{entries, line_of, silent_names, Entries, Entry};
pub(super) use expect::RawExpect;

use super::{err, Scenario, ScenarioError};
use crate::ir::*;
use crate::source::SourceFile;
use crate::yaml::{self, Spanned};
use serde::Deserialize;
use serde_json::Value as Json;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    name: Option<String>,
    controller: Spanned<String>,
    initial: Option<RawSettings>,
    steps: Vec<Spanned<RawStep>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSettings {
    reads: Option<Entries>,
    hooks: Option<Entries>,
    subordinates: Option<Entries>,
    vars: Option<Entries>,
    writes: Option<Entries>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStep {
    command: Option<Spanned<Json>>,
    reads: Option<Entries>,
    hooks: Option<Entries>,
    subordinates: Option<Entries>,
    /// `silent: [B, …]`: `reads` buffers held unwritten (LANGUAGE.md §8).
    silent: Option<Spanned<Json>>,
    cycles: Option<Spanned<Json>>,
    expect: Option<RawExpect>,
}

/// A scenario of either kind: one controller, or a run of several
/// (`system: true`, `controllers: [...]`).
pub enum AnyScenario {
    One(Scenario),
    System(super::SystemScenario),
}

impl AnyScenario {
    pub fn name(&self) -> &str {
        match self {
            AnyScenario::One(s) => &s.name,
            AnyScenario::System(s) => &s.name,
        }
    }
}

/// Read and resolve a scenario of either kind: a file with `system:` or
/// `controllers:` at the top is a system scenario.
pub fn parse_any(ir: &Ir, file: &SourceFile, stem: &str) -> Result<AnyScenario, ScenarioError> {
    if super::system_read::is_system(&file.text) {
        super::system_read::parse_system(ir, &file.text, stem).map(AnyScenario::System)
    } else {
        parse(ir, file, stem).map(AnyScenario::One)
    }
}

/// Read and resolve a one-controller scenario. `stem` names it when it has
/// no `name:`. A system scenario is refused: read it with [`parse_any`].
pub fn parse(ir: &Ir, file: &SourceFile, stem: &str) -> Result<Scenario, ScenarioError> {
    if super::system_read::is_system(&file.text) {
        return Err(err(
            1,
            "a system scenario (`system:` or `controllers:`), not one of one controller",
        ));
    }
    let raw: RawScenario = yaml::from_str_names(&file.text)
        .map_err(|e| err(e.location.map_or(1, |l| l.line() as usize), e.message))?;
    let cline = line_of(&raw.controller);
    let ctrl = ir
        .controller_by_name(&raw.controller.value)
        .ok_or_else(|| {
            err(
                cline,
                format!("unknown controller `{}`", raw.controller.value),
            )
        })?;
    let r = Resolver {
        ir,
        c: ir.controller(ctrl),
    };
    let s = raw.initial.unwrap_or_default();
    let mut initial = r.step(cline, None, s.reads, s.hooks, s.subordinates, None, None)?;
    initial.vars = r.vars(&s.vars)?;
    initial.writes = r.writes(&s.writes)?;
    let mut steps = Vec::new();
    for s in raw.steps {
        let line = line_of(&s);
        let v = s.value;
        let silent = v.silent.as_ref().map(|s| r.silent(s)).transpose()?;
        let mut step = r.step(
            line,
            v.command,
            v.reads,
            v.hooks,
            v.subordinates,
            v.cycles,
            v.expect,
        )?;
        if let Some((at, silent)) = silent {
            if let Some((i, _)) = step.reads.iter().find(|(i, _)| silent.contains(i)) {
                let name = &ir.buffers[r.c.reads[*i].index()].name;
                return Err(err(
                    at,
                    format!("`{name}` is both written (`reads:`) and `silent:` in one step; write it again in a later step"),
                ));
            }
            step.silent = silent;
        }
        steps.push(step);
    }
    Ok(Scenario {
        name: raw.name.unwrap_or_else(|| stem.to_string()),
        controller: ctrl,
        initial,
        steps,
    })
}

pub(super) struct Resolver<'a> {
    pub(super) ir: &'a Ir,
    pub(super) c: &'a Controller,
}
