//! Every witness of the golden corpus (`tests/data/{ok,err}`), replayed on
//! the reference interpreter:
//!
//! - every diagnostic that carries a run happens as the run says;
//! - on every state a path reaches, every row the analysis says can fire
//!   there fires when its witness is replayed at the end of the path: the
//!   witness of `can_fire_in` itself when it agrees with what the path
//!   fixes (vars, counters, parameters, `new_command`), else the witness
//!   asked with those pinned. A witness a scenario cannot give (a NaN, one
//!   hook with two results) is counted apart; one that it can give and
//!   that does not fire is a failure.
//!
//! Minimum counts keep the test from passing on an empty corpus.

use rcs_dsl::analysis::path::RunError;
use rcs_dsl::analysis::run::{replay, Expect};
use rcs_dsl::analysis::{Answer, PlanAnalysis, Witness};
use rcs_dsl::ir::{Ir, StateId, Target};
use rcs_runtime::driver::Value;
use std::path::{Path, PathBuf};

fn cases() -> Vec<PathBuf> {
    let mut out = Vec::new();
    for kind in ["ok", "err"] {
        let dir = Path::new("../tests/data").join(kind);
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            if name.as_bytes()[0].is_ascii_digit()
                && (p.is_dir() || p.extension().is_some_and(|e| e == "rcs"))
            {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

#[derive(Default)]
struct Counts {
    runs: usize,
    /// States a path reaches, of all states.
    reached: usize,
    states: usize,
    fired: usize,
    unwritable: usize,
    failures: Vec<String>,
}

/// Whether `w` agrees with the pinned leaves.
fn agrees(a: &PlanAnalysis, w: &Witness, pins: &[(usize, Value)]) -> bool {
    w.inputs.iter().all(|(leaf, v)| {
        let Some(l) = a.terms().find(leaf) else {
            return true;
        };
        pins.iter().all(|(p, pv)| *p != l || pv == v)
    })
}

fn rows_fire(ir: &Ir, case: &str, counts: &mut Counts) {
    for c in &ir.controllers {
        for p in &c.plans {
            let a = PlanAnalysis::new(ir, c, p);
            let paths = a.paths();
            counts.states += paths.len();
            counts.reached += paths.iter().filter(|p| p.is_some()).count();
            for (s, prefix) in paths.iter().enumerate() {
                let Some(prefix) = prefix else { continue };
                let state = StateId(s as u32);
                let Some(pins) = a.pins_after(prefix, 0) else {
                    counts.failures.push(format!(
                        "{case}: the path to {} does not replay",
                        p.states[s].name
                    ));
                    continue;
                };
                for (r, row) in p.rows.iter().enumerate() {
                    let Answer::Can(free) = a.can_fire_in(r, state) else {
                        continue;
                    };
                    let w = if agrees(&a, &free, &pins) {
                        free
                    } else {
                        match a.can_fire_in_given(r, state, &pins) {
                            Answer::Can(w) => w,
                            _ => continue,
                        }
                    };
                    let after = match row.to {
                        Target::State(t) => p.states[t.index()].name.clone(),
                        Target::Same => p.states[s].name.clone(),
                        // The plan ends: the record keeps the state it was in.
                        Target::Done | Target::Error(_) | Target::ErrorOf(_) => {
                            p.states[s].name.clone()
                        }
                    };
                    let expect = Expect::Fires {
                        row: rcs_dsl::analysis::run::row_name(row),
                        state: after,
                    };
                    match a.try_extend(prefix, &w, 1, expect) {
                        Ok(_) => counts.fired += 1,
                        Err(RunError::Unwritable) => counts.unwritable += 1,
                        Err(RunError::Replay(e)) => counts.failures.push(format!(
                            "{case}: {}.{} row {} in {} ({}): {e}",
                            c.name,
                            c.commands[p.verb.index()].name,
                            row.display_name(),
                            p.states[s].name,
                            w.text()
                        )),
                    }
                }
            }
        }
    }
}

#[test]
fn every_witness_of_the_golden_corpus_replays() {
    let mut counts = Counts::default();
    for case in cases() {
        let name = case.display().to_string();
        let Ok(sets) = rcs_dsl::load_paths(std::slice::from_ref(&case)) else {
            continue;
        };
        for set in &sets {
            let Some(ir) = rcs_dsl::lower_unchecked(set) else {
                continue;
            };
            let checked = rcs_dsl::check(set, &rcs_dsl::Options::default());
            for d in &checked.diagnostics {
                let Some(run) = d.witness.as_ref().and_then(|w| w.run.as_ref()) else {
                    continue;
                };
                let Some(ctrl) = ir.controller_by_name(&run.controller) else {
                    counts
                        .failures
                        .push(format!("{name}: no controller {}", run.controller));
                    continue;
                };
                match replay(&ir, ctrl, run) {
                    Ok(()) => counts.runs += 1,
                    Err(e) => counts.failures.push(format!("{name}: {}: {e}", d.message)),
                }
            }
            rows_fire(&ir, &name, &mut counts);
        }
    }
    assert!(
        counts.failures.is_empty(),
        "{} failures:\n{}",
        counts.failures.len(),
        counts.failures.join("\n")
    );
    eprintln!(
        "{} runs of findings; {} of {} states reached by a path; {} rows fired from \
         witnesses, {} witnesses a scenario cannot give",
        counts.runs, counts.reached, counts.states, counts.fired, counts.unwritable
    );
    assert!(counts.runs >= 20, "only {} runs replayed", counts.runs);
    assert!(
        counts.reached >= 450,
        "only {} states reached by a path",
        counts.reached
    );
    assert!(
        counts.fired >= 300,
        "only {} witnesses replayed",
        counts.fired
    );
}
