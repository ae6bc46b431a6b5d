//! `rcsc doc`: check the plan sets, gather what the site shows beside the
//! plans (the check's findings; with `--coverage` the scenarios' row hits,
//! with `--trace` the traces'), render every graph with Graphviz, and write
//! the pages `rcs_codegen::site` makes through the one output writer.
//!
//! Without Graphviz the site is still written, each drawing replaced by a
//! notice saying how to install it, and a warning is printed: the tables,
//! source and findings are worth having without the pictures.

use crate::args::Common;
use crate::commands::{check_sets_each, render_svg};
use crate::output::*;
use crate::{diff_cmd, test_cmd, trace_cmd};
use rcs_codegen::site::{self, GraphSource, RunCounts, SetDoc, Site, Svgs};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

pub(crate) const DOC_HELP: &str = "\
Writes a static site that works offline (plain HTML, one stylesheet, one
small script; no fonts or scripts from elsewhere) into DIR: index.html with
each plan set's controller hierarchy and buffers, a page per controller
(commands, statuses, buffers with every reader and writer, vars, hooks,
subordinates) and a page per plan (its state graph, states, state table
with the rows' doc comments and the findings of `rcsc check` on the rows
they concern, and its source). Every edge and node of a graph links to its
table row, every row to its edge and source line, and back. A search box
finds controllers, verbs, buffers and states. A graph is shrunk to the
page's width but never so far that its text is under 10 px (its box
scrolls instead); its “Full size” button, or a click on its background,
shows it at natural size to pan (drag) and zoom (wheel, pinch, buttons).

The graphs are drawn by Graphviz `dot` (package `graphviz`). Without it the
site is written with a notice in place of each drawing, and a warning.

--coverage runs each plan set's scenarios (as `rcsc test --coverage`) and
--trace reads traces (as `rcsc trace`; JSON lines or MCAP): every row then shows how many
cycles fired it, edges are drawn heavier the more they fired, rows that
never fired are marked, and each state shows the cycles spent in it.

--diff OLD adds a Changes page (diff-changes.html) comparing the plans with
OLD, a git revision of the current repository or a path, as `rcsc diff OLD`
does: per changed plan its diff-coloured state graph (rows added green,
removed red and dashed, changed orange, moved in precedence marked ⇅), its
changed rows, states and moves, and a link to its page; the declarations
changed; the findings the change introduced or removed. The index links to
it, and each changed controller and plan shows a “changed in this diff”
badge linking to its part of it.

Sets of more than 60 controllers are documented cluster by cluster: the
index draws one node per cluster (a CPU of the schedule, or a connected
part of at most 60 controllers of a CPU's hierarchy) with the command links
between clusters, each cluster has a page drawing its controllers and
their neighbours, and the controllers and buffers are listed on pages of
their own (list-controllers.html, list-buffers.html; 250 rows a page). Every page loads the
search index only when the search box is first used.

The output is the same, byte for byte, for the same plans and inputs.
Generated files of an earlier run that are no longer produced are removed.

Examples:
  rcsc doc plans/ -o target/doc --open
  rcsc doc plans/submarine --coverage
  rcsc doc plans/submarine --trace run.jsonl
  rcsc doc plans/ --diff HEAD~1
  rcsc doc plans/submarine --diff old/submarine";

#[derive(clap::Args)]
pub(crate) struct DocArgs {
    /// Plan-set folders (using their rcs.yaml) or .rcs files [default: .]
    pub(crate) paths: Vec<PathBuf>,
    /// Where to write the site.
    #[arg(
        short = 'o',
        long = "out-dir",
        value_name = "DIR",
        default_value = "target/rcs-doc"
    )]
    pub(crate) out_dir: PathBuf,
    /// Open index.html in a browser afterwards.
    #[arg(long)]
    pub(crate) open: bool,
    /// Show the row hits of each plan set's scenarios.
    #[arg(long, conflicts_with = "trace")]
    pub(crate) coverage: bool,
    /// Show the row hits of these traces (JSON lines or MCAP).
    #[arg(long, value_name = "FILE", num_args = 1..)]
    pub(crate) trace: Vec<PathBuf>,
    /// Add a Changes page against OLD: a git revision or a path.
    #[arg(long, value_name = "OLD")]
    pub(crate) diff: Option<String>,
    #[command(flatten)]
    pub(crate) common: Common,
}

pub(crate) fn doc(args: DocArgs) -> ExitCode {
    let start = Instant::now();
    let status = args.common.status();
    let paths = default_paths(args.paths);
    let sets = match rcs_dsl::load_paths(&paths) {
        Ok(sets) => sets,
        Err(e) => return fail(e),
    };
    let mut findings: Vec<Vec<rcs_dsl::Diagnostic>> = Vec::new();
    let mut keep = |c: &rcs_dsl::Checked| findings.push(c.diagnostics.clone());
    let irs = match check_sets_each(&sets, &args.common, false, Some(&status), &mut keep) {
        Ok(irs) => irs,
        Err(code) => return code,
    };
    let runs: Vec<RunCounts> = if args.coverage {
        match test_cmd::scenario_counts(&sets, &irs) {
            Ok(r) => r,
            Err(reason) => return fail(reason),
        }
    } else if !args.trace.is_empty() {
        match trace_cmd::counts_from_traces(&args.trace) {
            Ok(r) => vec![r; irs.len()],
            Err(e) => return e.fail(),
        }
    } else {
        Vec::new()
    };
    // Read before the site is built, so a bad OLD fails early; kept (with
    // its temporary folder) until the diff is made.
    let old = match &args.diff {
        Some(old) => match diff_cmd::old_side(old, &paths) {
            Ok(o) => Some(o),
            Err(reason) => return fail(reason),
        },
        None => None,
    };
    let changes = match &old {
        Some(old) => match diff_against(old, &irs, &findings, &args.common) {
            Ok(d) => Some(d),
            Err(reason) => return fail(reason),
        },
        None => None,
    };
    drop(old);
    let site = Site {
        changes: changes.as_ref().map(|(diff, against)| site::Changes {
            diff,
            against: against.clone(),
        }),
        shared: rcs_dsl::load::shares_output(&sets),
        sets: sets
            .iter()
            .zip(&irs)
            .zip(&findings)
            .enumerate()
            .map(|(i, ((set, ir), found))| SetDoc {
                ir,
                sources: set.sources.files().map(|(_, f)| f.text.as_str()).collect(),
                findings: found,
                runs: runs.get(i),
            })
            .collect(),
    };
    let graphs = site::graphs(&site);
    status.line("Drawing", plural(graphs.len(), "graph"));
    let svgs = match render_all(&graphs) {
        Ok(Some(svgs)) => svgs,
        Ok(None) => {
            if !args.common.quiet {
                eprintln!("warning: Graphviz `dot` not found: the site has no drawings (install the `graphviz` package, e.g. apt-get install graphviz)");
            }
            Svgs::new()
        }
        Err(reason) => return fail(reason),
    };
    let files = site::pages(&site, &svgs);
    let mut blocked = |dir: &Path| {
        status.line(
            "Blocking",
            format!("waiting for file lock on {}", rcs_dsl::load::display(dir)),
        )
    };
    let report = match rcs_codegen::writer::write_tree(&args.out_dir, &files, &mut blocked) {
        Ok(r) => r,
        Err(e) => return write_failed(&e),
    };
    status.line(
        "Generating",
        format!(
            "{} ({} changed)",
            plural(files.len(), "file"),
            report.written.len()
        ),
    );
    let index = args.out_dir.join("index.html");
    status.line(
        "Finished",
        format!(
            "in {:.2}s: {}",
            start.elapsed().as_secs_f64(),
            rcs_dsl::load::display(&index)
        ),
    );
    if args.open {
        open(&index);
    }
    ExitCode::SUCCESS
}

/// The diff of the documented plans against the old side, checked as
/// `rcsc diff` checks it, and the old side's name.
fn diff_against(
    old: &diff_cmd::OldSide,
    irs: &[rcs_dsl::ir::Ir],
    findings: &[Vec<rcs_dsl::Diagnostic>],
    common: &Common,
) -> Result<(rcs_dsl::diff::PlanSetDiff, String), String> {
    let options = common.options();
    let mut checked = Vec::new();
    for set in &old.sets {
        match rcs_dsl::diff::check_side(set, &options) {
            (Some(ir), diags) => checked.push((ir, diags)),
            (None, _) => {
                return Err(format!(
                    "{} does not parse; nothing to compare (`rcsc diff {}` shows why)",
                    old.name, old.name
                ))
            }
        }
    }
    let old_sides: Vec<rcs_dsl::diff::Side> = checked
        .iter()
        .map(|(ir, diagnostics)| rcs_dsl::diff::Side { ir, diagnostics })
        .collect();
    let new_sides: Vec<rcs_dsl::diff::Side> = irs
        .iter()
        .zip(findings)
        .map(|(ir, diagnostics)| rcs_dsl::diff::Side { ir, diagnostics })
        .collect();
    Ok((
        rcs_dsl::diff::diff(&old_sides, &new_sides),
        old.name.clone(),
    ))
}

/// Whether Graphviz `dot` can be run.
fn dot_installed() -> bool {
    std::process::Command::new("dot")
        .arg("-V")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok()
}

/// Graphs per `dot` process. Fixed, not derived from the number of CPUs:
/// Graphviz draws the first graph of its input with other element ids than
/// the later ones, so the batches must not depend on the machine (or its
/// load) for the site to be the same from run to run.
const GRAPHS_PER_DOT: usize = 16;

/// Every graph as SVG by key, or `None` when Graphviz is missing. The
/// graphs go to a few `dot` processes at once, many graphs each (one
/// process per graph costs more than drawing a small graph).
fn render_all(graphs: &[GraphSource]) -> Result<Option<Svgs>, String> {
    if graphs.is_empty() {
        return Ok(Some(Svgs::new()));
    }
    if !dot_installed() {
        return Ok(None);
    }
    // A graph with clusters (a hierarchy) gets a `dot` of its own: after
    // other graphs in one process, Graphviz 2.43 writes clusters in an
    // order that changes from run to run (seen on `plans/`' site).
    let mut batches: Vec<&[GraphSource]> = Vec::new();
    let mut start = 0;
    for (i, g) in graphs.iter().enumerate() {
        if g.dot.contains("subgraph \"cluster") {
            if start < i {
                batches.extend(graphs[start..i].chunks(GRAPHS_PER_DOT));
            }
            batches.push(&graphs[i..=i]);
            start = i + 1;
        }
    }
    batches.extend(graphs[start..].chunks(GRAPHS_PER_DOT));
    let workers = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .clamp(1, 8)
        .min(batches.len());
    // Worker `w` draws batches w, w + workers, …; the results are put back
    // in batch order, so only the speed depends on the number of workers.
    let mut results: Vec<Option<Result<Vec<String>, String>>> = vec![None; batches.len()];
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..workers)
            .map(|w| {
                let batches = &batches;
                s.spawn(move || {
                    (w..batches.len())
                        .step_by(workers)
                        .map(|i| (i, render_batch(batches[i])))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for h in handles {
            let done = h.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
            for (i, r) in done {
                results[i] = Some(r);
            }
        }
    });
    let mut svgs = Svgs::new();
    for (chunk, svg) in batches.into_iter().zip(results) {
        let svg = svg.ok_or_else(|| "a batch of graphs was not drawn".to_string())?;
        for (g, svg) in chunk.iter().zip(svg?) {
            svgs.insert(g.key.clone(), svg);
        }
    }
    Ok(Some(svgs))
}

/// Several graphs through one `dot -Tsvg`: it draws each graph of its
/// input in turn, one SVG document after another.
fn render_batch(graphs: &[GraphSource]) -> Result<Vec<String>, String> {
    let input: String = graphs.iter().map(|g| g.dot.as_str()).collect();
    let out = render_svg(&input)?;
    let text =
        String::from_utf8(out).map_err(|_| "Graphviz wrote SVG that is not UTF-8".to_string())?;
    let mut docs = Vec::with_capacity(graphs.len());
    let mut rest = text.as_str();
    while let Some(end) = rest.find("</svg>") {
        let end = end + "</svg>".len();
        docs.push(rest[..end].trim_start().to_string());
        rest = &rest[end..];
    }
    if docs.len() != graphs.len() {
        return Err(format!(
            "Graphviz drew {} of {} graphs",
            docs.len(),
            graphs.len()
        ));
    }
    Ok(docs)
}

/// Open a file in the desktop's browser, if there is one: `$BROWSER`
/// first (as `cargo doc --open` does), else the desktop's opener. Without
/// a browser (a server, a container, no `xdg-open` or none that works),
/// one line says which file to open; the site is built, so this is no
/// failure and the exit status stays 0. The opener's own complaints are
/// not shown: the line says all the user can act on.
fn open(path: &Path) {
    let shown = rcs_dsl::load::display(path);
    let browser = std::env::var_os("BROWSER").filter(|b| !b.is_empty());
    let opener = browser.clone().unwrap_or_else(|| {
        if cfg!(target_os = "macos") {
            "open".into()
        } else if cfg!(windows) {
            "explorer".into()
        } else {
            "xdg-open".into()
        }
    });
    let ran = std::process::Command::new(&opener)
        .arg(path)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status();
    // `explorer` exits 1 even when it opened the file.
    let opened = match ran {
        Ok(status) => status.success() || (cfg!(windows) && browser.is_none()),
        Err(_) => false,
    };
    if !opened {
        let how = match &browser {
            Some(b) => format!("`$BROWSER` ({}) could not open it", b.to_string_lossy()),
            None => format!("no browser found (`{}`)", opener.to_string_lossy()),
        };
        eprintln!("note: {how}: open {shown} in a browser");
    }
}
