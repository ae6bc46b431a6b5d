//! The property test of the cross-controller analysis, on generated code:
//! the random hierarchies of `rcs-dsl/tests/common/hierarchy.rs` that the
//! build compiled (`RANDOM_HIERARCHIES`: those whose checks found a
//! cross-controller finding with a system run) are checked again here, and
//! every finding's system run — the scenario `rcsc check --witnesses`
//! writes — passes on the interpreter and on the generated code with the
//! same record for every controller cycle. The hierarchies also run whole
//! at random on both. (`rcs-dsl/tests/hierarchies.rs` checks the same
//! property on the interpreter over many more hierarchies, and that no
//! row the analysis calls unreachable fires.)

use super::systems::{both_backends, random_runs};
use rcs_dsl::scenario::{self, AnyScenario};
use rcs_dsl::source::SourceFile;
use rcs_plan_sets::RANDOM_HIERARCHIES;

#[test]
fn random_hierarchy_findings_reproduce_on_generated_code() {
    let (mut findings, mut cycles) = (0, 0);
    for set in RANDOM_HIERARCHIES {
        let sets = rcs_dsl::load_paths(&[set.path.into()]).unwrap_or_else(|e| panic!("{e}"));
        let checked = rcs_dsl::check(&sets[0], &rcs_dsl::Options::default());
        let ir = checked.ir.as_ref().expect("compiled, so it checks clean");
        for d in &checked.diagnostics {
            let Some(script) = d.witness.as_ref().and_then(|w| w.system.as_ref()) else {
                continue;
            };
            let text = script.to_yaml(ir);
            let what = format!("{}: {} system run", set.path, d.code.name());
            let file = SourceFile::new("witness.scenario.yaml", text.clone());
            let s = match scenario::parse_any(ir, &file, "witness") {
                Ok(AnyScenario::System(s)) => s,
                other => panic!(
                    "{what}: not read back as a system scenario: {:?}\n{text}",
                    other.err()
                ),
            };
            cycles += both_backends(ir, set, &s, &what).unwrap_or_else(|e| panic!("{e}\n{text}"));
            findings += 1;
        }
        random_runs(set, ir).unwrap_or_else(|e| panic!("{}: {e}", set.path));
    }
    println!(
        "differential: {} random hierarchies, {findings} findings' system runs, {cycles} controller cycles compared",
        RANDOM_HIERARCHIES.len()
    );
    assert!(
        RANDOM_HIERARCHIES.len() >= 4 && findings >= RANDOM_HIERARCHIES.len(),
        "the compiled hierarchies carry findings ({findings})"
    );
}
