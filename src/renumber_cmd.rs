//! `rcsc fmt --renumber`: for each plan set named, every row label `EN`
//! and numbered don't-care `*N` set to its row's position and the `fired:`
//! of the set's own scenarios with them ([`rcs_dsl::fmt::renumber`]), then
//! every `.rcs` file laid out as `rcsc fmt` does ([`crate::fmt_cmd`]).
//!
//! All or nothing: every set is renumbered and formatted in memory first;
//! if any file cannot be read, parsed or lowered, nothing is written and
//! the status is 2. Otherwise the files are rewritten through the writer's
//! in-place rewrite (staged beside each file and renamed over it), or with
//! `--check` only shown as a diff. What it could not decide (a label on
//! two rows, a scenario name two plans number differently) is a warning
//! with its file and line, and is left as written.

use rcs_dsl::fmt::{renumber, RenumberError, Renumbered};
use rcs_dsl::render::{self, Format};
use rcs_dsl::PlanSet;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::fmt_cmd::{format_file, unified_diff, FmtArgs};
use crate::output::{fail, plural, write_failed, Status};

/// A file to rewrite: its old and new text and what changed in it.
struct Rewrite {
    path: PathBuf,
    old: String,
    new: String,
    /// `Renumbered` (its numbers changed), `Formatted`, or `Updated` (a scenario).
    verb: &'static str,
    /// The numbers changed, `E3 → E4, …`.
    changes: String,
}

pub(crate) fn fmt_renumber(args: &FmtArgs) -> ExitCode {
    let paths = crate::output::default_paths(args.paths.clone());
    let sets = match rcs_dsl::load_paths(&paths) {
        Ok(sets) => sets,
        Err(e) => return fail(e),
    };
    let color = args.color();
    let mut rewrites = Vec::new();
    let mut refused = 0usize;
    for set in &sets {
        match plan_set(set, args.quiet, color) {
            Some(mut r) => rewrites.append(&mut r),
            None => refused += 1,
        }
    }
    if refused > 0 {
        eprintln!(
            "error: {} could not be renumbered; no file was written",
            plural(refused, "plan set")
        );
        return ExitCode::from(2);
    }
    rewrites.retain(|r| r.new != r.old);
    if args.check {
        for r in &rewrites {
            let shown = rcs_dsl::load::display(&r.path);
            crate::output::print_stdout(&unified_diff(&shown, &r.old, &r.new, "renumbered"))
                .unwrap_or_else(|e| eprintln!("error: cannot write to stdout: {e}"));
        }
        if rewrites.is_empty() {
            return ExitCode::SUCCESS;
        }
        if !args.quiet {
            eprintln!(
                "{} would change (run `rcsc fmt --renumber` without --check)",
                plural(rewrites.len(), "file")
            );
        }
        return ExitCode::from(1);
    }
    write_all(&rewrites, args.quiet, color)
}

/// Rewrite each file in place; status 2 if any write failed.
fn write_all(rewrites: &[Rewrite], quiet: bool, color: bool) -> ExitCode {
    let status = Status { color, quiet };
    let mut failed = false;
    for r in rewrites {
        let shown = rcs_dsl::load::display(&r.path);
        let mut blocked = |dir: &Path| {
            status.line(
                "Blocking",
                format!("waiting for file lock on {}", rcs_dsl::load::display(dir)),
            )
        };
        match rcs_codegen::writer::rewrite_source(&r.path, &r.new, &mut blocked) {
            Ok(_) if r.changes.is_empty() => status.line(r.verb, &shown),
            Ok(_) => status.line(r.verb, format!("{shown} ({})", r.changes)),
            Err(e) => {
                let _ = write_failed(&e);
                failed = true;
            }
        }
    }
    if failed {
        ExitCode::from(2)
    } else {
        ExitCode::SUCCESS
    }
}

/// One set renumbered and formatted in memory: every file that may change
/// (unchanged ones included), or `None` with the reasons printed.
fn plan_set(set: &PlanSet, quiet: bool, color: bool) -> Option<Vec<Rewrite>> {
    let scenarios = read_scenarios(set)?;
    let renumbered = match renumber(set, &scenarios) {
        Ok(r) => r,
        Err(RenumberError::Diagnostics(diags)) => {
            for d in &diags {
                eprint!(
                    "{}",
                    render::render(d, &set.sources, Format::Human { color })
                );
            }
            eprintln!(
                "error: plan set `{}` has errors; it was not renumbered",
                render::escape_controls(crate::output::set_name(set))
            );
            return None;
        }
        Err(e @ RenumberError::Changed(_)) => {
            eprintln!(
                "error: plan set `{}`: {e}",
                render::escape_controls(crate::output::set_name(set))
            );
            return None;
        }
    };
    if !quiet {
        for u in &renumbered.undecided {
            eprintln!(
                "warning: {}:{}: {}",
                render::escape_controls(&u.path),
                u.line,
                render::escape_controls(&u.message)
            );
        }
    }
    let mut out = Vec::new();
    let mut ok = true;
    for id in &set.rcs_files {
        let file = set.sources.get(*id);
        let changed = renumbered.rcs_files.iter().find(|f| f.path == file.path);
        let text = changed.map_or(&file.text, |f| &f.text);
        let path = PathBuf::from(&file.path);
        match format_file(&path, text, color) {
            Some(new) => out.push(Rewrite {
                path,
                old: file.text.clone(),
                new,
                verb: if changed.is_some() {
                    "Renumbered"
                } else {
                    "Formatted"
                },
                changes: changes_in(&renumbered, &file.path, false),
            }),
            None => ok = false,
        }
    }
    for s in &renumbered.scenarios {
        let old = scenarios
            .iter()
            .find(|(p, _)| *p == s.path)
            .map(|(_, t)| t.clone())
            .unwrap_or_default();
        out.push(Rewrite {
            path: PathBuf::from(&s.path),
            old,
            new: s.text.clone(),
            verb: "Updated",
            changes: changes_in(&renumbered, &s.path, true),
        });
    }
    ok.then_some(out)
}

/// The set's own scenario files as (path as shown, text); `None`, said
/// why, when one cannot be read.
fn read_scenarios(set: &PlanSet) -> Option<Vec<(String, String)>> {
    match crate::test_cmd::own_scenario_texts(set) {
        Ok(files) => Some(
            files
                .into_iter()
                .map(|(path, text)| (rcs_dsl::load::display(&path), text))
                .collect(),
        ),
        Err(reason) => {
            eprintln!("error: {}", render::escape_controls(&reason));
            None
        }
    }
}

/// `E1 → E2, E2 → E3`: the numbers changed in one file.
fn changes_in(r: &Renumbered, path: &str, scenario: bool) -> String {
    let list = if scenario { &r.renamed } else { &r.relabelled };
    list.iter()
        .filter(|c| c.path == path)
        .map(|c| format!("{} → {}", c.old, c.new))
        .collect::<Vec<_>>()
        .join(", ")
}
