//! `rcsc`: the command-line face of the rcsc libraries. A thin layer: it
//! parses arguments, calls `rcs-dsl` and `rcs-codegen`, prints what they
//! return and turns the outcome into an exit status:
//! 0 success (warnings allowed), 1 diagnostics with an error, 2 usage or I/O.

use clap::Parser;
use std::process::ExitCode;

/// `print!` for what a command reports on stdout, through
/// [`output::print_stdout`]: a reader that closed the pipe (`rcsc test |
/// head`) ends the report, never a panic.
macro_rules! out {
    ($($arg:tt)*) => {{
        let _ = $crate::output::print_stdout(&format!($($arg)*));
    }};
}

/// `println!` as [`out!`] does `print!`.
macro_rules! outln {
    ($($arg:tt)*) => {{
        let _ = $crate::output::print_stdout(&format!("{}\n", format_args!($($arg)*)));
    }};
}

mod args;
mod certs_cmd;
mod commands;
mod compiled;
mod completions;
#[cfg(feature = "console")]
mod console_cmd;
mod diff_cmd;
mod doc_cmd;
mod fmt_cmd;
mod lsp;
mod output;
mod renumber_cmd;
mod test_cmd;
mod trace_cmd;
mod witnesses;

use args::*;
use commands::*;
use output::*;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check(args) => check(args),
        Command::Build(args) => build(args),
        Command::Graph(args) => graph(args),
        Command::Ir(args) => ir(args),
        Command::Test(args) => test_cmd::test(args),
        Command::Diff(args) => diff_cmd::diff(args),
        Command::Doc(args) => doc_cmd::doc(args),
        Command::Fmt(args) => fmt_cmd::fmt(args),
        Command::Trace(args) => trace_cmd::trace(args),
        Command::Certs(args) => certs_cmd::certs(args),
        #[cfg(feature = "console")]
        Command::Console(args) => console_cmd::console(args),
        Command::Lsp => lsp::lsp(),
        Command::Completions(args) => completions::completions(args),
        Command::Man(args) => completions::man(args),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_lines_align_like_cargo() {
        // Only the layout is checked here; the binary tests cover the text.
        assert_eq!(format!("{:>12} x", "Checking"), "    Checking x");
        assert_eq!(plural(1, "file"), "1 file");
        assert_eq!(plural(3, "file"), "3 files");
    }

    /// The IR of a one-controller, one-plan set named `a`.
    pub(crate) fn one_controller() -> rcs_dsl::ir::Ir {
        let set = rcs_dsl::PlanSet::from_texts(
            "a",
            [("a.rcs", "controller A {\n    command GO\n    plan GO {\n        *0 when new_command -> Done\n    }\n}\n")],
            None,
        );
        rcs_dsl::check(&set, &rcs_dsl::Options::default())
            .ir
            .unwrap()
    }

    #[test]
    fn several_sets_with_one_name_are_refused() {
        let ir = one_controller();
        let set = rcs_dsl::PlanSet::default();
        let one = output_files(std::slice::from_ref(&set), std::slice::from_ref(&ir)).unwrap();
        assert!(one.iter().any(|f| f.path == "graphs/hierarchy.dot"));
        let member = rcs_dsl::PlanSet {
            workspace: Some("plans".into()),
            ..rcs_dsl::PlanSet::default()
        };
        let one = output_files(std::slice::from_ref(&member), std::slice::from_ref(&ir)).unwrap();
        assert!(one.iter().any(|f| f.path == "a/graphs/hierarchy.dot"));
        let two = [rcs_dsl::PlanSet::default(), rcs_dsl::PlanSet::default()];
        assert!(output_files(&two, &[ir.clone(), ir]).is_err());
    }
}
