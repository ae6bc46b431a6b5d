//! What the scenario tests share: a plan set checked from text, and a
//! scenario read from text and run on the reference interpreter, with the
//! failure (file line and report) or the pass asserted.

use rcs_dsl::ir::Ir;
use rcs_dsl::scenario::{self, Outcome};
use rcs_dsl::source::SourceFile;
use rcs_dsl::{check, Options, PlanSet};

/// The IR of one plan file, which must check without errors.
pub fn ir_of(plans: &str) -> Ir {
    let set = PlanSet::from_texts("t", [("t.rcs", plans)], None);
    let out = check(&set, &Options::default());
    out.ir.unwrap_or_else(|| panic!("{:?}", out.diagnostics))
}

/// Read a scenario: its error's line and message when it is not valid.
pub fn parse(ir: &Ir, text: &str) -> Result<scenario::Scenario, (usize, String)> {
    scenario::parse(ir, &SourceFile::new("t.scenario.yaml", text), "t")
        .map_err(|e| (e.line, e.message))
}

/// Run a valid scenario on the interpreter.
pub fn run(ir: &Ir, text: &str) -> Outcome {
    let s = parse(ir, text).unwrap_or_else(|e| panic!("{e:?}\n{text}"));
    scenario::run(ir, &s)
}

/// The scenario passes.
pub fn passes(ir: &Ir, text: &str) {
    let o = run(ir, text);
    assert!(
        o.failure.is_none(),
        "{:?}; fired {:?}\n{text}",
        o.failure,
        o.fired
    );
}

/// The scenario fails: its report.
pub fn failure(ir: &Ir, text: &str) -> String {
    run(ir, text)
        .failure
        .map(|f| f.1)
        .unwrap_or_else(|| panic!("passes:\n{text}"))
}
