//! System scenarios (docs/scenarios.md, "System scenarios") on the
//! reference interpreter: a whole plan set or a subtree on its schedule.

use rcs_dsl::scenario::{self, AnyScenario};
use rcs_dsl::source::SourceFile;
use rcs_dsl::{check, load_folder, Options};
use std::path::Path;

fn load(set: &str) -> rcs_dsl::ir::Ir {
    let set = load_folder(Path::new(set)).expect("plans");
    check(&set, &Options::default()).ir.expect("clean")
}

fn system(ir: &rcs_dsl::ir::Ir, text: &str) -> Result<scenario::SystemScenario, (usize, String)> {
    match scenario::parse_any(ir, &SourceFile::new("t.scenario.yaml", text), "t") {
        Ok(AnyScenario::System(s)) => Ok(s),
        Ok(AnyScenario::One(_)) => panic!("read as a one-controller scenario"),
        Err(e) => Err((e.line, e.message)),
    }
}

#[test]
fn the_submarine_runs_whole() {
    let ir = load("../plans/submarine");
    let path = "../plans/submarine/scenarios/system_init_then_transit.scenario.yaml";
    let s = system(&ir, &std::fs::read_to_string(path).unwrap()).unwrap();
    let out = scenario::run_system(&ir, &s);
    assert!(out.failure.is_none(), "{:?}", out.failure);
}
