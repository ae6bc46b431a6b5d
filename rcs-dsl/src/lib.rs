//! `rcs-dsl`: the front end of rcsc.
//!
//! The pipeline is one way, one type per stage:
//!
//! ```text
//! paths ──load──▶ PlanSet ──parse──▶ ast::File ──expand──▶ ast::File ──lower──▶ ir::Ir ──checks──▶ findings
//!                                                                                 (asking analysis)
//! ```
//!
//! `expand` turns LANGUAGE.md §8's shared constructs (job lists, shared
//! rows, controller types) into plain rows, jobs and controllers, so that
//! no later stage knows them.
//!
//! A finding that something can happen carries a witness, and where a path
//! to it is found a run ([`analysis::run`]): replayed on the interpreter,
//! written as a scenario by `rcsc check --witnesses`.
//!
//! [`check`] runs it. Each stage reports all of its errors and the pipeline
//! stops after a stage that found any, so one mistake gives one diagnostic.
//! The IR is returned only when no error was found; it is the input of the
//! code generator, the graph writer and the interpreter.

// pest is used without its `std` feature (see the workspace Cargo.toml); its
// derive then names `alloc` from the crate root.
extern crate alloc;

pub mod analysis;
pub mod arith;
pub mod ast;
pub mod builtin;
mod checks;
pub mod diagnostic;
pub mod diff;
pub mod error_codes;
mod expand;
pub mod fmt;
pub mod interp;
pub mod ir;
pub mod lint;
pub mod load;
mod lower;
pub mod manifest;
mod parallel;
pub mod parser;
pub mod placement;
pub mod pretty;
pub mod render;
pub mod scenario;
pub mod source;
pub mod suggest;
pub mod time;
pub mod watchdog;
pub mod yaml;
mod yaml_layout;

pub use diagnostic::{Code, Diagnostic, Diagnostics, Severity};
pub use load::{load_folder, load_paths, LoadError, PlanSet};
pub use lower::type_name;

use lint::{LintLevels, LintOverride};

/// Settings that do not come from the plan set itself.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Command-line `-A/-W/-D` lint levels, in order.
    pub lint_flags: Vec<LintOverride>,
}

/// The result of checking one plan set.
#[derive(Debug)]
pub struct Checked {
    /// Present when no error was found (warnings allowed).
    pub ir: Option<ir::Ir>,
    /// The IR when only the checks of stage 3 rejected it (an unreachable
    /// or shadowed row, a lint set to deny): well-formed plans that run on
    /// the interpreter and compile like any other, which is what replaying
    /// a finding's own witness needs. `None` when `ir` is present or
    /// parsing or lowering failed.
    pub rejected_by_checks: Option<ir::Ir>,
    pub diagnostics: Vec<Diagnostic>,
}

impl Checked {
    pub fn has_errors(&self) -> bool {
        self.diagnostics
            .iter()
            .any(|d| d.severity == Severity::Error)
    }
}

/// Check a loaded plan set: parse, lower, validate.
pub fn check(set: &PlanSet, options: &Options) -> Checked {
    let mut diags = Diagnostics::new();
    let Some(mut parsed) = parse(set, &mut diags) else {
        return finish(None, diags, &expand::Origins::default());
    };
    let origins = expand::expand(&mut parsed.files, &mut diags);
    if diags.has_errors() {
        return finish(None, diags, &origins);
    }
    let Some(ir) = lower_files(set, parsed, &mut diags) else {
        return finish(None, diags, &origins);
    };
    let mut levels = LintLevels::default();
    for &(lint, level) in set.manifest.lints.iter().chain(&options.lint_flags) {
        levels.set(lint, level);
    }
    checks::run(&ir, &levels, &set.sources, &mut diags);
    if diags.has_errors() {
        let mut checked = finish(None, diags, &origins);
        checked.rejected_by_checks = Some(ir);
        return checked;
    }
    finish(Some(ir), diags, &origins)
}

/// Parse and lower a plan set without running the checks: the IR even of
/// plans a check rejects (a shadowed row, an unreachable one), `None` only
/// when parsing or lowering fails. For tools and tests that study such
/// plans; everything else wants [`check`].
pub fn lower_unchecked(set: &PlanSet) -> Option<ir::Ir> {
    front(set, &mut Diagnostics::new())
}

/// [`lower_unchecked`] with the errors that stopped it: the IR without
/// the checks, or the load, parse, expansion and lowering diagnostics.
/// For tools that rewrite plans a check rejects (`rcsc fmt --renumber`
/// fixes `row_number`) and must say why they could not.
pub fn lower_or_diagnostics(set: &PlanSet) -> Result<ir::Ir, Vec<Diagnostic>> {
    let mut diags = Diagnostics::new();
    match front(set, &mut diags) {
        Some(ir) => Ok(ir),
        None => Err(diags.into_vec()),
    }
}

/// Stages 0–2: the load diagnostics, parsing and lowering.
fn front(set: &PlanSet, diags: &mut Diagnostics) -> Option<ir::Ir> {
    let mut parsed = parse(set, diags)?;
    expand::expand(&mut parsed.files, diags);
    if diags.has_errors() {
        return None;
    }
    lower_files(set, parsed, diags)
}

/// The parsed files, in path order, and the worker that parsed each (so
/// that lowering frees each file's rows on the thread that built them).
struct Parsed {
    files: Vec<ast::File>,
    parsed_on: std::collections::BTreeMap<source::FileId, parallel::Worker>,
}

/// Stages 0 and 1: the load diagnostics and parsing; `None` on an error.
fn parse(set: &PlanSet, diags: &mut Diagnostics) -> Option<Parsed> {
    // Stage 0 (load and manifest) and stage 1 (parse) are independent, so
    // their errors are reported together.
    let unreadable: Vec<source::FileId> = set
        .diagnostics
        .iter()
        .map(|d| d.primary_span().file)
        .collect();
    for d in &set.diagnostics {
        diags.push(d.clone());
    }
    let start = diags.len();
    let todo: Vec<source::FileId> = set
        .rcs_files
        .iter()
        .copied()
        .filter(|id| !unreadable.contains(id))
        .collect();
    let mut files = Vec::with_capacity(todo.len());
    let mut parsed_on = std::collections::BTreeMap::new();
    for (id, (result, worker)) in todo.iter().zip(parse_all(set, &todo)) {
        match result {
            Ok(f) => {
                files.push(f);
                parsed_on.insert(*id, worker);
            }
            Err(ds) => ds.into_iter().for_each(|d| diags.push(d)),
        }
    }
    diags.sort_from(start, &set.sources);
    if diags.has_errors() {
        return None;
    }
    Some(Parsed { files, parsed_on })
}

/// Stage 2: lowering parsed files; `None` on an error.
fn lower_files(set: &PlanSet, parsed: Parsed, diags: &mut Diagnostics) -> Option<ir::Ir> {
    let system = set
        .manifest
        .system
        .as_ref()
        .map(|(s, _)| s.clone())
        .unwrap_or_else(|| sanitize(&set.name));
    let file_names = set
        .sources
        .files()
        .map(|(id, _)| set.relative_path(id))
        .collect();
    let ir = lower::lower(
        parsed.files,
        &parsed.parsed_on,
        file_names,
        &set.manifest,
        &system,
        &set.sources,
        diags,
    );
    ir.filter(|_| !diags.has_errors())
}

type ParseResult = Result<ast::File, Vec<Diagnostic>>;

/// Below this much `.rcs` text a thread costs more than it saves.
const PARALLEL_BYTES: usize = 256 * 1024;

fn rcs_bytes(set: &PlanSet) -> usize {
    set.rcs_files
        .iter()
        .map(|id| set.sources.get(*id).text.len())
        .sum()
}

/// Parse files, on both cores when there is enough text (files are
/// independent), returning results in the order of `ids`.
fn parse_all(set: &PlanSet, ids: &[source::FileId]) -> Vec<(ParseResult, parallel::Worker)> {
    parallel::map_ordered_on(ids, rcs_bytes(set) >= PARALLEL_BYTES, |id| {
        parser::parse_file(*id, &set.sources.get(*id).text)
    })
}

fn finish(ir: Option<ir::Ir>, diags: Diagnostics, origins: &expand::Origins) -> Checked {
    Checked {
        ir,
        rejected_by_checks: None,
        diagnostics: expand::attribute(diags.into_vec(), origins),
    }
}

/// A folder name as a Rust-friendly system name.
pub(crate) fn sanitize(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, '_');
    }
    s
}
