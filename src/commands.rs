//! The subcommands that check and generate: `check`, `build`, `graph` and
//! `ir`, each a thin call into `rcs-dsl` and `rcs-codegen`.

use rcs_dsl::render::Format;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use crate::args::*;
use crate::output::*;
use crate::witnesses;

pub(crate) fn check(args: CheckArgs) -> ExitCode {
    let paths = default_paths(args.paths);
    let sets = match rcs_dsl::load_paths(&paths) {
        Ok(sets) => sets,
        Err(e) => return fail(e),
    };
    let mut found = witnesses::Witnesses::default();
    let gather = args.witnesses.is_some().then_some(&mut found);
    let result = check_sets(&sets, &args.common, false, None, gather);
    if let Some(dir) = &args.witnesses {
        if let Err(reason) = found.write(dir) {
            return fail(reason);
        }
        if args.common.format() != Format::Json && !args.common.quiet {
            eprintln!(
                "wrote {} to {}",
                plural(found.len(), "witness scenario"),
                rcs_dsl::render::escape_controls(&rcs_dsl::load::display(dir))
            );
        }
    }
    match result {
        Ok(_) => ExitCode::SUCCESS,
        Err(code) => code,
    }
}

/// Check every plan set, printing diagnostics (JSON to stdout unless
/// `stdout_busy`) and the summary line; with `status`, a `Checking` line
/// per set; with `witnesses`, the runs of the findings gathered. `Err` is
/// exit status 1 when any set has an error.
pub(crate) fn check_sets(
    sets: &[rcs_dsl::PlanSet],
    common: &Common,
    stdout_busy: bool,
    status: Option<&Status>,
    witnesses: Option<&mut witnesses::Witnesses>,
) -> Result<Vec<rcs_dsl::ir::Ir>, ExitCode> {
    match witnesses {
        Some(w) => check_sets_each(sets, common, stdout_busy, status, &mut |c| w.collect(c)),
        None => check_sets_each(sets, common, stdout_busy, status, &mut |_| {}),
    }
}

/// [`check_sets`] for running the plans (`rcsc test`): a set that only
/// the checks of stage 3 reject (an unreachable row, a lint at deny) still
/// runs — its diagnostics are printed, and its scenarios, a finding's own
/// witness among them, decide the outcome. A set that does not parse or
/// lower stops the run.
pub(crate) fn check_sets_to_run(
    sets: &[rcs_dsl::PlanSet],
    common: &Common,
) -> Result<Vec<rcs_dsl::ir::Ir>, ExitCode> {
    let options = common.options();
    let mut counts = Counts::default();
    let mut irs = Vec::with_capacity(sets.len());
    for set in sets {
        let checked = rcs_dsl::check(set, &options);
        print_diagnostics(set, &checked, common, false, &mut counts);
        irs.extend(checked.ir.or(checked.rejected_by_checks));
    }
    print_summary(common, &counts);
    if irs.len() != sets.len() {
        return Err(ExitCode::from(1));
    }
    Ok(irs)
}

/// [`check_sets`], showing each set's check result to `each` (in the
/// order of the sets) after its diagnostics are printed.
pub(crate) fn check_sets_each(
    sets: &[rcs_dsl::PlanSet],
    common: &Common,
    stdout_busy: bool,
    status: Option<&Status>,
    each: &mut dyn FnMut(&rcs_dsl::Checked),
) -> Result<Vec<rcs_dsl::ir::Ir>, ExitCode> {
    let options = common.options();
    let mut counts = Counts::default();
    let mut irs = Vec::with_capacity(sets.len());
    for set in sets {
        if let Some(status) = status {
            status.line(
                "Checking",
                format!(
                    "{} ({})",
                    set_name(set),
                    plural(set.rcs_files.len(), "file")
                ),
            );
        }
        let checked = rcs_dsl::check(set, &options);
        print_diagnostics(set, &checked, common, stdout_busy, &mut counts);
        each(&checked);
        irs.extend(checked.ir);
    }
    print_summary(common, &counts);
    if counts.errors > 0 || irs.len() != sets.len() {
        return Err(ExitCode::from(1));
    }
    Ok(irs)
}

pub(crate) fn build(args: BuildArgs) -> ExitCode {
    let start = Instant::now();
    let status = args.common.status();
    let paths = default_paths(args.paths);
    let sets = match rcs_dsl::load_paths(&paths) {
        Ok(sets) => sets,
        Err(e) => return fail(e),
    };
    // Check everything before writing anything.
    let irs = match check_sets(&sets, &args.common, false, Some(&status), None) {
        Ok(irs) => irs,
        Err(code) => return code,
    };

    let mut files = match output_files(&sets, &irs) {
        Ok(files) => files,
        Err(reason) => return fail(reason),
    };
    if !args.no_rustfmt {
        rcs_codegen::rustfmt::format_files(&mut files);
    }
    let mut blocked = |dir: &std::path::Path| {
        status.line(
            "Blocking",
            format!("waiting for file lock on {}", rcs_dsl::load::display(dir)),
        )
    };
    let report = match rcs_codegen::writer::write_tree(&args.out_dir, &files, &mut blocked) {
        Ok(report) => report,
        Err(e) => return write_failed(&e),
    };
    let mut message = format!(
        "{} ({} changed",
        plural(files.len(), "file"),
        report.written.len()
    );
    if !report.removed.is_empty() {
        message.push_str(&format!(", {} removed", report.removed.len()));
    }
    message.push(')');
    status.line("Generating", message);
    status.line(
        "Finished",
        format!("in {:.2}s", start.elapsed().as_secs_f64()),
    );
    ExitCode::SUCCESS
}

/// Every output of every plan set: the tree itself for one plan set named
/// alone, one `<system>/` folder per set for a workspace or several sets.
pub(crate) fn output_files(
    sets: &[rcs_dsl::PlanSet],
    irs: &[rcs_dsl::ir::Ir],
) -> Result<Vec<rcs_codegen::OutputFile>, rcs_codegen::SameSystem> {
    let irs: Vec<&rcs_dsl::ir::Ir> = irs.iter().collect();
    let shared = rcs_dsl::load::shares_output(sets);
    rcs_codegen::generate_sets(&irs, shared, &rcs_codegen::Options::default(), true)
}

/// Load and check plan sets for a command that prints a product on stdout
/// (`graph`, `ir`): diagnostics go to stderr. `Err` is the exit status when
/// the plans cannot be read (2) or have an error (1).
pub(crate) fn checked_irs(
    paths: Vec<PathBuf>,
    common: &Common,
) -> Result<Vec<(rcs_dsl::PlanSet, rcs_dsl::ir::Ir)>, ExitCode> {
    let sets = rcs_dsl::load_paths(&default_paths(paths)).map_err(fail)?;
    let irs = check_sets(&sets, common, true, None, None)?;
    Ok(sets.into_iter().zip(irs).collect())
}

/// Every `CTRL.VERB` with a plan, in declaration order.
pub(crate) fn plan_names(irs: &[(rcs_dsl::PlanSet, rcs_dsl::ir::Ir)]) -> Vec<String> {
    let mut names = Vec::new();
    for (_, ir) in irs {
        for c in &ir.controllers {
            for cmd in c.commands.iter().filter(|cmd| cmd.plan.is_some()) {
                names.push(format!("{}.{}", c.name, cmd.name));
            }
        }
    }
    names
}

pub(crate) fn graph(args: GraphArgs) -> ExitCode {
    let irs = match checked_irs(args.paths, &args.common) {
        Ok(irs) => irs,
        Err(code) => return code,
    };
    let dot = match &args.plan {
        Some((ctrl_name, verb)) => {
            let found: Vec<String> = irs
                .iter()
                .filter_map(|(_, ir)| {
                    let ctrl = ir.controller(ir.controller_by_name(ctrl_name)?);
                    let plan = ctrl.plan_of(verb)?;
                    Some(rcs_codegen::dot::plan_graph(ir, ctrl, plan))
                })
                .collect();
            match <[String; 1]>::try_from(found) {
                Ok([dot]) => dot,
                Err(found) if found.is_empty() => {
                    let names = plan_names(&irs);
                    let known = if names.is_empty() {
                        "there are no plans".to_string()
                    } else {
                        format!("the plans are: {}", names.join(", "))
                    };
                    return fail(format!("no plan `{ctrl_name}.{verb}`; {known}"));
                }
                Err(_) => {
                    return fail(format!(
                        "`{ctrl_name}.{verb}` is in several plan sets; name only the one to draw"
                    ))
                }
            }
        }
        None => match irs.as_slice() {
            [(_, ir)] => rcs_codegen::dot::hierarchy_graph(ir),
            [] => return fail("no plan set to draw"),
            _ => {
                return fail(
                    "--hierarchy draws one plan set, but several were named; name only one",
                )
            }
        },
    };
    let text = match args.format {
        GraphFormat::Dot => dot,
        GraphFormat::Svg => match render_svg(&dot) {
            Ok(svg) => mark_svg(&String::from_utf8_lossy(&svg)),
            Err(reason) => return fail(reason),
        },
    };
    let inputs = inputs_of(irs.iter().map(|(set, _)| set));
    emit(args.out.as_deref(), &text, &inputs)
}

/// Graphviz's SVG with the generated marker in its first line (an XML
/// comment, after the XML declaration when there is one: nothing may come
/// before that), so that the next `rcsc graph -o` may replace it.
fn mark_svg(svg: &str) -> String {
    let mark = format!(
        "<!-- {} (`rcsc graph`). Do not edit. -->",
        rcs_codegen::GENERATED
    );
    match svg.split_once('\n') {
        Some((first, rest)) if first.starts_with("<?xml") => format!("{first}{mark}\n{rest}"),
        _ => format!("{mark}\n{svg}"),
    }
}

/// DOT → SVG through Graphviz `dot`, the one program the CLI runs.
pub(crate) fn render_svg(dot: &str) -> Result<Vec<u8>, String> {
    use std::process::{Command, Stdio};
    let mut child = Command::new("dot")
        .arg("-Tsvg")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => "Graphviz `dot` not found: install the `graphviz` \
                package (e.g. apt-get install graphviz) or use --format dot"
                .to_string(),
            _ => format!("cannot run Graphviz `dot`: {e}"),
        })?;
    // Feed stdin from a thread so a large graph cannot deadlock on full pipes.
    let mut stdin = child.stdin.take().expect("stdin is piped");
    let input = dot.to_string();
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let output = child
        .wait_with_output()
        .map_err(|e| format!("cannot run Graphviz `dot`: {e}"))?;
    let written = writer
        .join()
        .unwrap_or_else(|e| std::panic::resume_unwind(e));
    if !output.status.success() {
        let why = String::from_utf8_lossy(&output.stderr);
        let why = why.lines().next().unwrap_or("").trim();
        return Err(format!(
            "Graphviz `dot -Tsvg` failed ({}): {why}",
            output.status
        ));
    }
    written.map_err(|e| format!("cannot feed Graphviz `dot`: {e}"))?;
    Ok(output.stdout)
}

pub(crate) fn ir(args: IrArgs) -> ExitCode {
    let irs = match checked_irs(args.paths, &args.common) {
        Ok(irs) => irs,
        Err(code) => return code,
    };
    let inputs = inputs_of(irs.iter().map(|(set, _)| set));
    let irs: Vec<&rcs_dsl::ir::Ir> = irs.iter().map(|(_, ir)| ir).collect();
    let text = match (args.format, irs.as_slice()) {
        (IrFormat::Json, [one]) => serde_json::to_string_pretty(one).map_err(|e| e.to_string()),
        (IrFormat::Json, all) => serde_json::to_string_pretty(all).map_err(|e| e.to_string()),
        (IrFormat::Yaml, [one]) => rcs_dsl::manifest::to_yaml(one).map_err(|e| e.to_string()),
        (IrFormat::Yaml, all) => rcs_dsl::manifest::to_yaml(&all).map_err(|e| e.to_string()),
    };
    match text {
        Ok(mut text) => {
            if !text.ends_with('\n') {
                text.push('\n');
            }
            emit(args.out.as_deref(), &mark_ir(args.format, text), &inputs)
        }
        Err(e) => fail(format!("cannot serialise the IR: {e}")),
    }
}

/// The IR with the generated marker in its first line, so that the next
/// `rcsc ir -o` may replace it: a YAML comment; in JSON, which has no
/// comments, a `"//"` member opening the object (of the first object, for
/// a list of plan sets), which readers of the IR ignore.
fn mark_ir(format: IrFormat, text: String) -> String {
    let about = format!("{} (`rcsc ir`). Do not edit.", rcs_codegen::GENERATED);
    match format {
        IrFormat::Yaml => format!("# {about}\n{text}"),
        IrFormat::Json => {
            let member = format!("{{\"//\": \"{about}\",\n");
            if let Some(rest) = text.strip_prefix("{\n") {
                format!("{member}{rest}")
            } else if let Some(rest) = text.strip_prefix("[\n  {\n") {
                format!("[{member}{rest}")
            } else {
                text
            }
        }
    }
}
