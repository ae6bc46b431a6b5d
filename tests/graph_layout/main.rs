//! Every graph rcsc draws, rendered by Graphviz and checked as a reader
//! would look at it (issue 29): the state graph of every plan and the
//! hierarchy of every plan set in `plans/` and `tests/data/ok/`, the
//! `rcsc diff --graphs` picture of every case in `tests/data/diff/`, and
//! plans made to be hard to draw (long conditions, many self-loops, many
//! `*N` rows, state sets, a long chain). Each is rendered with
//! `dot -Tjson` and `dot -Tsvg` and must pass [`geometry::Drawing::problems`]:
//! no two texts overlap, no text lies on another node or under an edge's
//! line, nothing leaves the canvas, and the smallest text is at least
//! 10 px when the site shows the graph at its page width.
//!
//! `prim_goto_as_drawn_before_is_caught` keeps the drawing of `rcs_ex`
//! PRIM.GOTO as rcsc wrote it before this layout (`prim_goto_before.dot`)
//! and asserts the check rejects it, so the check is known to bite.
//!
//! Without `dot` the tests skip with a note, except on CI.

use std::path::{Path, PathBuf};
use std::process::Command;

mod geometry;
#[path = "../tools/mod.rs"]
mod tools;

use geometry::Drawing;

/// A graph to check: a name for messages and its DOT.
struct Graph {
    name: String,
    dot: String,
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rcsc-graph-layout-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Render with Graphviz and read the drawing.
fn render(dot: &str, dir: &Path, n: usize) -> Result<Drawing, String> {
    let input = dir.join(format!("{n}.dot"));
    let (json, svg) = (dir.join(format!("{n}.json")), dir.join(format!("{n}.svg")));
    std::fs::write(&input, dot).map_err(|e| e.to_string())?;
    let out = Command::new("dot")
        .arg("-Tjson")
        .arg("-o")
        .arg(&json)
        .arg("-Tsvg")
        .arg("-o")
        .arg(&svg)
        .arg(&input)
        .output()
        .map_err(|e| format!("dot: {e}"))?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() || !stderr.trim().is_empty() {
        return Err(format!("dot: {}: {}", out.status, stderr.trim()));
    }
    let read = |p: &Path| std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()));
    Drawing::parse(&read(&json)?, &read(&svg)?)
}

/// Render every graph (two at a time) and fail listing each illegible one.
fn check_all(what: &str, graphs: &[Graph]) {
    assert!(!graphs.is_empty(), "no graphs for {what}");
    let dir = scratch(what);
    let results: Vec<(usize, Result<Drawing, String>)> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..2)
            .map(|w| {
                let dir = &dir;
                s.spawn(move || {
                    graphs
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| i % 2 == w)
                        .map(|(i, g)| (i, render(&g.dot, dir, i)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect()
    });
    let mut failures = Vec::new();
    let mut smallest = f64::INFINITY;
    for (i, r) in results {
        let problems = match r {
            Ok(d) => {
                smallest = smallest.min(d.scale());
                d.problems()
            }
            Err(e) => vec![e],
        };
        if !problems.is_empty() {
            let more = problems.len().saturating_sub(6);
            let mut msg = format!(
                "{} ({i}.dot):\n  {}",
                graphs[i].name,
                problems[..problems.len().min(6)].join("\n  ")
            );
            if more > 0 {
                msg.push_str(&format!("\n  … and {more} more"));
            }
            failures.push(msg);
        }
    }
    // `GRAPH_LAYOUT_KEEP=1`: keep the renderings (N.dot/json/svg) to look at.
    if std::env::var_os("GRAPH_LAYOUT_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&dir);
    } else {
        eprintln!("renderings kept in {}", dir.display());
    }
    assert!(
        failures.is_empty(),
        "{} of {} {what} graphs are not legible:\n\n{}",
        failures.len(),
        graphs.len(),
        failures.join("\n\n")
    );
    eprintln!(
        "{what}: {} graphs legible (smallest page scale {smallest:.2})",
        graphs.len()
    );
}

fn entries(dir: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            !name.starts_with('.')
                && name != "snapshots"
                && (p.is_dir() || p.extension().is_some_and(|e| e == "rcs"))
        })
        .collect();
    out.sort();
    out
}

/// Every plan's state graph and the hierarchy of the plan set at `path`.
fn graphs_of(path: &Path, unchecked: bool) -> Vec<Graph> {
    let sets = rcs_dsl::load_paths(&[path.to_path_buf()])
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut out = Vec::new();
    for set in &sets {
        let checked = rcs_dsl::check(set, &rcs_dsl::Options::default());
        let ir = match checked.ir {
            Some(ir) => ir,
            None if unchecked => rcs_dsl::lower_unchecked(set)
                .unwrap_or_else(|| panic!("{}: does not lower", path.display())),
            None => panic!(
                "{}: does not check: {:?}",
                path.display(),
                checked.diagnostics
            ),
        };
        for ctrl in &ir.controllers {
            for plan in &ctrl.plans {
                out.push(Graph {
                    name: format!("{} {}.{}", path.display(), ctrl.name, ctrl.plan_title(plan)),
                    dot: rcs_codegen::dot::plan_graph(&ir, ctrl, plan),
                });
            }
        }
        out.push(Graph {
            name: format!("{} hierarchy", path.display()),
            dot: rcs_codegen::dot::hierarchy_graph(&ir),
        });
    }
    out
}

#[test]
fn every_plan_and_hierarchy_of_plans_is_legible() {
    if !tools::dot_available("the layout of the graphs of plans/") {
        return;
    }
    let graphs: Vec<Graph> = entries("plans")
        .iter()
        .flat_map(|p| graphs_of(p, false))
        .collect();
    check_all("plans", &graphs);
}

/// As the doc site draws them with `--coverage`/`--trace` and findings:
/// every row's name followed by its hits (some never fired, some in the
/// millions) and a mark on rows with a finding.
#[test]
fn marked_graphs_of_plans_are_legible() {
    if !tools::dot_available("the layout of the marked graphs of plans/") {
        return;
    }
    let mut graphs = Vec::new();
    for path in entries("plans") {
        for set in rcs_dsl::load_paths(std::slice::from_ref(&path)).expect("loads") {
            let ir = rcs_dsl::check(&set, &rcs_dsl::Options::default())
                .ir
                .expect("checks");
            for ctrl in &ir.controllers {
                for plan in &ctrl.plans {
                    let mut marks = rcs_codegen::dot::RowMarks::default();
                    let hits = plan
                        .rows
                        .iter()
                        .map(|r| (r.display_name(), u64::from(r.position % 3) * 1_234_567))
                        .collect();
                    marks.hits = Some(hits);
                    for r in plan.rows.iter().filter(|r| r.position % 2 == 1) {
                        marks.findings.insert(r.display_name(), "warning");
                    }
                    graphs.push(Graph {
                        name: format!(
                            "{} {}.{} marked",
                            path.display(),
                            ctrl.name,
                            ctrl.plan_title(plan)
                        ),
                        dot: rcs_codegen::dot::plan_graph_marked(&ir, ctrl, plan, &marks),
                    });
                }
            }
        }
    }
    check_all("plans marked", &graphs);
}

#[test]
fn every_graph_of_the_golden_ok_cases_is_legible() {
    if !tools::dot_available("the layout of the graphs of tests/data/ok/") {
        return;
    }
    let cases: Vec<PathBuf> = entries("tests/data/ok")
        .into_iter()
        .filter(|p| p.file_name().unwrap().to_string_lossy().as_bytes()[0].is_ascii_digit())
        .collect();
    let graphs: Vec<Graph> = cases.iter().flat_map(|p| graphs_of(p, false)).collect();
    check_all("ok", &graphs);
}

#[test]
fn every_diff_graph_is_legible() {
    if !tools::dot_available("the layout of the diff graphs") {
        return;
    }
    let mut graphs = Vec::new();
    for case in entries("tests/data/diff") {
        let side = |which: &str| {
            let sets = rcs_dsl::load_paths(&[case.join(which)]).unwrap();
            sets.iter()
                .map(|s| rcs_dsl::diff::check_side(s, &rcs_dsl::Options::default()))
                .collect::<Vec<_>>()
        };
        let (old, new) = (side("old"), side("new"));
        let diff = rcs_dsl::diff::diff(&sides(&old), &sides(&new));
        for p in diff
            .systems
            .iter()
            .flat_map(|s| &s.controllers)
            .flat_map(|c| &c.plans)
        {
            graphs.push(Graph {
                name: format!("{} {}", case.display(), p.name()),
                dot: rcs_codegen::diff::diff_dot(p, "old..new"),
            });
        }
    }
    check_all("diff", &graphs);
}

type Checked = (Option<rcs_dsl::ir::Ir>, Vec<rcs_dsl::Diagnostic>);

/// The sides of a diff that lowered.
fn sides(checked: &[Checked]) -> Vec<rcs_dsl::diff::Side<'_>> {
    checked
        .iter()
        .filter_map(|(ir, d)| {
            Some(rcs_dsl::diff::Side {
                ir: ir.as_ref()?,
                diagnostics: d,
            })
        })
        .collect()
}

#[test]
fn adversarial_plans_are_legible() {
    if !tools::dot_available("the layout of adversarial plans") {
        return;
    }
    let dir = scratch("adversarial-sources");
    let mut graphs = Vec::new();
    for (name, text) in adversarial::plans() {
        let path = dir.join(format!("{name}.rcs"));
        std::fs::write(&path, &text).unwrap();
        for mut g in graphs_of(&path, true) {
            g.name = format!("adversarial {name}: {}", g.name);
            graphs.push(g);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    check_all("adversarial", &graphs);
}

#[test]
fn prim_goto_as_drawn_before_is_caught() {
    if !tools::dot_available("the regression case of the layout check") {
        return;
    }
    let dir = scratch("before");
    let before = include_str!("prim_goto_before.dot");
    let problems = render(before, &dir, 0).unwrap().problems();
    let _ = std::fs::remove_dir_all(&dir);
    let all = problems.join("\n");
    // What a reviewer saw: row labels printed over each other.
    assert!(
        problems.iter().any(|p| p.contains("overlaps text")),
        "the old PRIM.GOTO drawing passed the check:\n{all}"
    );
}

mod adversarial;
