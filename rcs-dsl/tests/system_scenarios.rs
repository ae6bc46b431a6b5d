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

#[test]
fn every_system_scenario_of_the_plans_passes() {
    let mut ran = 0;
    for set in [
        "../plans/submarine",
        "../plans/rcs_ex",
        "../plans/packml",
        "../plans/fieldbus_drive",
        "../plans/bridgeport_io",
    ] {
        let ir = load(set);
        let mut paths: Vec<_> = std::fs::read_dir(Path::new(set).join("scenarios"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| {
                p.file_name()
                    .unwrap()
                    .to_str()
                    .unwrap()
                    .starts_with("system_")
            })
            .collect();
        paths.sort();
        for p in paths {
            let s = system(&ir, &std::fs::read_to_string(&p).unwrap())
                .unwrap_or_else(|(l, m)| panic!("{}:{l}: {m}", p.display()));
            let out = scenario::run_system(&ir, &s);
            assert!(out.failure.is_none(), "{}: {:?}", p.display(), out.failure);
            ran += 1;
        }
    }
    assert!(ran >= 3, "{ran}");
}
