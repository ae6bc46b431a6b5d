//! `rcsc console PATH [--connect ENDPOINT… --certs DIR]`: the operator's
//! console for a running system (issue 31). Without `--connect` it checks
//! the plan set and shows what the console shows of it (CPUs, hierarchy,
//! the verbs an operator may send to each root): a program built from the
//! plan set runs the console in-process (`cargo run -p submarine-example --
//! --console`). With `--connect` (feature `remote-console`) it attaches to
//! a distributed plan set's running processes over Zenoh as the identity
//! `operator` ([`rcs_console::remote`]), under the operator's
//! access-control policy generated from the plan set.

use std::path::PathBuf;
use std::process::ExitCode;

use rcs_console::Catalog;

use crate::output::fail;

pub(crate) const CONSOLE_HELP: &str = "\
Without --connect, checks the plan set and lists what the console shows of
it: the CPUs, the hierarchy, and the verbs an operator may send to each
root. A program built from the plan set can run the console in-process:
`cargo run -p submarine-example -- --console` (docs/console.md: the keys,
what it shows).

With --connect, attaches to the running processes of a distributed plan set
over Zenoh (rcsc built with the feature `remote-console`), as the identity
`operator`: mutual TLS with DIR/ca.pem, DIR/operator.pem and
DIR/operator.key (`rcsc certs DIR PLANS` makes development ones), under the
operator's access-control policy generated from the plan set. Give one
--connect per process (peers do not relay each other's samples). Each
process must serve the console (`Bridge::serve_console`); the operator may
watch, pause / step / resume executives and command the roots, nothing else.

Examples:
  rcsc console plans/submarine
  rcsc console examples/submarine-split/plans --connect tls/127.0.0.1:7447 \\
      --connect tls/127.0.0.1:7448 --certs /tmp/sub --trace session.mcap";

#[derive(clap::Args)]
pub(crate) struct ConsoleArgs {
    /// The plan set the running system was built from (a plan-set folder).
    pub(crate) path: PathBuf,
    /// Attach over Zenoh to the process listening at ENDPOINT
    /// (`tls/HOST:PORT`); repeat for each process.
    #[arg(long, value_name = "ENDPOINT")]
    pub(crate) connect: Vec<String>,
    /// The operator's certificates: DIR/ca.pem, DIR/operator.pem,
    /// DIR/operator.key.
    #[arg(long, value_name = "DIR")]
    pub(crate) certs: Option<PathBuf>,
    /// Connect without TLS or access control (`tcp/` endpoints), to
    /// processes run with `--insecure`.
    #[arg(long)]
    pub(crate) insecure: bool,
    /// Record the session to FILE (with --connect): MCAP when it ends in
    /// `.mcap`, else JSON lines; one message per controller whose figures
    /// changed, about ten times a second.
    #[arg(long, value_name = "FILE")]
    pub(crate) trace: Option<PathBuf>,
}

pub(crate) fn console(args: ConsoleArgs) -> ExitCode {
    let catalog = match Catalog::load(&args.path) {
        Ok(c) => c,
        Err(e) => return fail(e),
    };
    if !args.connect.is_empty() {
        return remote(&args, catalog);
    }
    if args.certs.is_some() || args.insecure || args.trace.is_some() {
        return fail("--certs, --insecure and --trace go with --connect ENDPOINT");
    }
    out!("{}", summary(&catalog));
    eprintln!(
        "note: `rcsc console PATH --connect ENDPOINT --certs DIR` attaches to a running \
         distributed system; `cargo run -p submarine-example -- --console` runs the console \
         in-process (docs/console.md)"
    );
    ExitCode::SUCCESS
}

#[cfg(not(feature = "remote-console"))]
fn remote(args: &ConsoleArgs, _catalog: Catalog) -> ExitCode {
    fail(format!(
        "attaching over Zenoh ({}) needs rcsc built with the feature `remote-console` \
         (cargo install rcsc --features remote-console)",
        args.connect.join(", ")
    ))
}

#[cfg(feature = "remote-console")]
fn remote(args: &ConsoleArgs, catalog: Catalog) -> ExitCode {
    use rcs_runtime::bridge::console::OPERATOR;
    use rcs_runtime::BridgeConfig;

    let mut config = BridgeConfig::new(&catalog.system, OPERATOR);
    for e in &args.connect {
        config = config.connect(e);
    }
    config =
        match (&args.certs, args.insecure) {
            (Some(dir), false) => config.certs(dir),
            (None, true) => config.insecure(),
            _ => return fail(
                "choose --certs DIR (the operator's certificate, mutual TLS and access control) \
                 or --insecure (neither)",
            ),
        };
    config.policy = match operator_policy(&args.path) {
        Ok(p) => Some(p),
        Err(e) => return fail(e),
    };
    let mut source = match rcs_console::remote::Remote::connect(catalog.clone(), &config) {
        Ok(s) => s,
        Err(e) => return fail(format!("cannot attach: {e}")),
    };
    let Some(path) = &args.trace else {
        return match rcs_console::run(catalog, &mut source) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => fail(format!("terminal: {e}")),
        };
    };
    let sink = match rcs_runtime::TraceSink::create(path) {
        Ok(s) => s,
        Err(e) => return fail(format!("cannot write {}: {e}", path.display())),
    };
    let mut recording = rcs_console::Recording::new(&mut source, sink, catalog.clone());
    let ran = rcs_console::run(catalog, &mut recording);
    let finished = recording.finish();
    match (ran, finished) {
        (Err(e), _) => fail(format!("terminal: {e}")),
        (Ok(()), Err(e)) => fail(format!("cannot finish {}: {e}", path.display())),
        (Ok(()), Ok((records, lost))) => {
            eprintln!(
                "recorded {records} message(s) to {}{}",
                path.display(),
                if lost > 0 {
                    format!(" ({lost} lost to write errors)")
                } else {
                    String::new()
                }
            );
            ExitCode::SUCCESS
        }
    }
}

/// The operator's access-control policy for the plan set at `path`.
#[cfg(feature = "remote-console")]
fn operator_policy(path: &std::path::Path) -> Result<String, String> {
    let set = rcs_dsl::load_folder(path)
        .map_err(|e| format!("cannot load the plan set {}: {e}", path.display()))?;
    let checked = rcs_dsl::check(&set, &rcs_dsl::Options::default());
    let ir = checked
        .ir
        .ok_or_else(|| format!("the plan set {} has errors", path.display()))?;
    let placement = rcs_dsl::placement::Placement::of(&ir);
    Ok(rcs_codegen::acl::operator_policy(&ir, &placement).to_string())
}

/// What the console would show of a plan set before it runs.
fn summary(catalog: &Catalog) -> String {
    let mut out = format!("system {}\n", catalog.system);
    for cpu in &catalog.cpus {
        out.push_str(&format!(
            "CPU {} | period {} ms | {}\n",
            cpu.name,
            cpu.period_ns as f64 / 1e6,
            cpu.controllers.join(", ")
        ));
    }
    out.push_str("hierarchy:\n");
    fn walk(catalog: &Catalog, name: &str, depth: usize, out: &mut String) {
        let Some(c) = catalog.controller(name) else {
            return;
        };
        let plans = c.verbs.iter().filter(|v| v.plan.is_some()).count();
        out.push_str(&format!("  {}{name} ({plans} plans)\n", "  ".repeat(depth)));
        if depth < 64 {
            for s in &c.subordinates {
                walk(catalog, s, depth + 1, out);
            }
        }
    }
    for root in catalog.roots() {
        walk(catalog, &root.name, 0, &mut out);
    }
    for root in catalog.roots() {
        let verbs: Vec<String> = root
            .verbs
            .iter()
            .map(|v| {
                let params: Vec<String> = v
                    .params
                    .iter()
                    .map(|(n, t)| format!("{n}: {}", t.name()))
                    .collect();
                format!("{}({})", v.name, params.join(", "))
            })
            .collect();
        out.push_str(&format!(
            "operator -> {}: {}\n",
            root.name,
            verbs.join(", ")
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_summary_lists_cpus_hierarchy_and_root_verbs() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("plans/submarine");
        let catalog = Catalog::load(&path).expect("the submarine plan set");
        assert_eq!(
            summary(&catalog),
            "system submarine\nCPU main | period 30 ms | SM, PR, TB\nhierarchy:\n  SM (2 plans)\n    PR (3 plans)\n      TB (4 plans)\noperator -> SM: INIT(), TRANSIT(speed: f64)\n"
        );
    }
}
