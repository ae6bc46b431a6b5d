//! `rcsc console PATH [--connect LOCATOR]`: the operator's console for a
//! running system (issue 31). The console itself (the `rcs-console`
//! crate) attaches in-process today: a program built from the plan set
//! runs it on its own terminal (`cargo run -p submarine-example --
//! --console`). Attaching from a process of its own, over the Zenoh
//! transport, is phase 2: until then this command checks the plan set,
//! shows what the console would show of it (CPUs, hierarchy, the verbs an
//! operator may send to each root) and says how to get the live console.

use std::path::PathBuf;
use std::process::ExitCode;

use rcs_console::Catalog;

use crate::output::fail;

pub(crate) const CONSOLE_HELP: &str = "\
Today the console attaches in-process: a program built from the plan set
runs it on its terminal, its executives on their threads. The submarine
example does: `cargo run -p submarine-example -- --console` (docs/console.md:
the keys, what it shows). Attaching to a running system from a process of
its own (--connect, over the Zenoh transport) arrives in phase 2; until then
`rcsc console PATH` checks the plan set and lists what the console shows of
it: the CPUs, the hierarchy, and the verbs an operator may send to each
root.

Examples:
  rcsc console plans/submarine
  cargo run -p submarine-example -- --console";

#[derive(clap::Args)]
pub(crate) struct ConsoleArgs {
    /// The plan set the running system was built from (a plan-set folder).
    pub(crate) path: PathBuf,
    /// Attach to a running system over Zenoh at LOCATOR (phase 2: not yet).
    #[arg(long, value_name = "LOCATOR")]
    pub(crate) connect: Option<String>,
}

pub(crate) fn console(args: ConsoleArgs) -> ExitCode {
    let catalog = match Catalog::load(&args.path) {
        Ok(c) => c,
        Err(e) => return fail(e),
    };
    if let Some(locator) = args.connect {
        return fail(format!(
            "attaching to a running system over Zenoh ({locator}) arrives in phase 2 of the \
             console (issue 31); today run the program with its in-process console, e.g. \
             `cargo run -p submarine-example -- --console`"
        ));
    }
    print!("{}", summary(&catalog));
    eprintln!(
        "note: `rcsc console` attaches to a running system from another process in phase 2 \
         (issue 31); today the console runs in-process: \
         `cargo run -p submarine-example -- --console` (docs/console.md)"
    );
    ExitCode::SUCCESS
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
