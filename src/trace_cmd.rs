//! `rcsc trace FILE…`: read runtime traces (the JSON lines or MCAP
//! recordings of `rcs_runtime::TraceSink`, `rcsc test --trace`, the
//! examples' `--trace`; docs/trace-format.md), told apart by MCAP's magic
//! bytes, not by name, and print per plan how many cycles fired each row
//! and how many ended in each state. The counting is shared with
//! `rcsc doc --trace`, which draws the same numbers on the graphs.

use crate::args::Common;
use crate::commands::checked_irs;
use crate::output::*;
use rcs_codegen::site::RunCounts;
use std::path::PathBuf;
use std::process::ExitCode;

pub(crate) const TRACE_HELP: &str = "\
A trace is what an executive's trace sink writes (one JSON line per
controller per cycle, after a header line, or an MCAP recording;
docs/trace-format.md), what `rcsc test --trace FILE` writes for scenario
runs (MCAP when FILE ends in .mcap), or what
`cargo run -p submarine-example -- --fast --trace FILE` writes. Either
encoding is read, told apart by its first bytes. Several files are summed.

Without --plans, verbs are shown by id and rows as E<position>. With
--plans, the plans are checked first and rows, states and the rows that
never fired are named.

Examples:
  rcsc trace run.jsonl
  rcsc trace run.jsonl --plans plans/submarine
  rcsc test plans/submarine --trace t.jsonl && rcsc trace t.jsonl --plans plans/submarine
  rcsc test plans/submarine --trace t.mcap && rcsc trace t.mcap --plans plans/submarine";

#[derive(clap::Args)]
pub(crate) struct TraceArgs {
    /// Trace files (JSON lines or MCAP).
    #[arg(required = true)]
    pub(crate) files: Vec<PathBuf>,
    /// The plan set(s) the traces ran, to name rows and states.
    #[arg(long, value_name = "PATH")]
    pub(crate) plans: Vec<PathBuf>,
    #[command(flatten)]
    pub(crate) common: Common,
}

/// Why a trace file cannot be summed: what, and for a file that is no
/// readable trace, a code and what to do.
pub(crate) struct TraceFileError {
    message: String,
    coded: Option<(&'static str, &'static str)>,
}

impl TraceFileError {
    /// Print it (`error[code]: …` and `= help: …`) and exit 2.
    pub(crate) fn fail(&self) -> ExitCode {
        match self.coded {
            None => fail(&self.message),
            Some((code, help)) => {
                let shown = rcs_dsl::render::escape_controls(&self.message);
                eprintln!("error[{code}]: {shown}");
                eprintln!("  = help: {help}");
                ExitCode::from(2)
            }
        }
    }
}

/// Row hits and cycles per state summed over trace files. `Err`: a file
/// that cannot be read or is not a trace, with its line (JSON lines) or
/// what is wrong in it (MCAP).
pub(crate) fn counts_from_traces(files: &[PathBuf]) -> Result<RunCounts, TraceFileError> {
    let mut counts = RunCounts {
        source: if files.len() == 1 {
            format!("the trace {}", rcs_dsl::load::display(&files[0]))
        } else {
            format!("{} traces", files.len())
        },
        ..RunCounts::default()
    };
    for f in files {
        let shown = rcs_dsl::load::display(f);
        let bytes = std::fs::read(f).map_err(|e| TraceFileError {
            message: format!("cannot read the trace {shown}: {e}"),
            coded: None,
        })?;
        let records = rcs_runtime::read_trace_bytes(&bytes).map_err(|e| TraceFileError {
            message: format!("{shown}: {e}"),
            coded: Some((e.code(), e.help())),
        })?;
        for r in records {
            let Some(verb) = r.verb else { continue };
            if let Some(state) = r.state {
                counts.add_state(&r.controller, verb.into(), state.into(), 1);
            }
            if let Some(row) = r.fired {
                counts.add_row(&r.controller, verb.into(), row.into(), 1);
            }
        }
    }
    Ok(counts)
}

pub(crate) fn trace(args: TraceArgs) -> ExitCode {
    let counts = match counts_from_traces(&args.files) {
        Ok(c) => c,
        Err(e) => return e.fail(),
    };
    let irs = if args.plans.is_empty() {
        Vec::new()
    } else {
        match checked_irs(args.plans, &args.common) {
            Ok(irs) => irs,
            Err(code) => return code,
        }
    };
    let mut text = format!("rows fired and cycles per state, from {}\n", counts.source);
    if irs.is_empty() {
        text.push_str(&counts.summary(None));
    }
    for (_, ir) in &irs {
        text.push_str(&counts.summary(Some(ir)));
    }
    // Controller names come from the trace files: no control character
    // of theirs reaches the terminal.
    let text = rcs_dsl::render::escape_controls(&text);
    emit(None, &text, &Default::default())
}
