//! Job lists (LANGUAGE.md §8) are inlined by the expand stage
//! (`rcs-dsl/src/expand/jobs.rs`), each parameter replaced by its
//! argument. These tests run the expanded plans on the interpreter and
//! check that a call means what passing the arguments' values would mean,
//! also when an argument names another parameter of the list or a var that
//! has a parameter's name (the parameters are replaced all at once, never
//! one after the other).

use rcs_dsl::scenario;
use rcs_dsl::source::SourceFile;
use rcs_dsl::{check, Options, PlanSet};

/// Check `plans` (which must be clean) and run `scenario` on them.
fn run(plans: &str, scenario_text: &str) {
    let set = PlanSet::from_texts("t", [("t.rcs", plans)], None);
    let checked = check(&set, &Options::default());
    let ir = checked
        .ir
        .unwrap_or_else(|| panic!("the plans check clean: {:?}", checked.diagnostics));
    let file = SourceFile::new("t.scenario.yaml", scenario_text.to_string());
    let s = scenario::parse(&ir, &file, "t").unwrap_or_else(|e| panic!("{}", e.message));
    let outcome = scenario::run(&ir, &s);
    assert!(
        outcome.failure.is_none(),
        "{:?}; fired {:?}",
        outcome.failure,
        outcome.fired
    );
}

#[test]
fn arguments_that_name_the_lists_own_parameters_are_not_replaced_again() {
    // `outer(x, y)` calls `inner(y, x)`: inner's `x` is outer's `y`.
    let plans = "controller A {
    command GO(p: u8, q: u8)
    var v: u8 = 0
    var w: u8 = 0
    jobs inner(x: u8, y: u8) { v = x; w = y }
    jobs outer(x: u8, y: u8) { inner(y, x) }
    jobs shifted(x: u8) { inner(x + 1, x) }
    plan GO {
        E0: *0 when new_command && cmd.p == 0 -> Done { outer(cmd.p, cmd.q) }
        E1: *1 when new_command -> Done { shifted(cmd.q) }
    }
}
";
    let steps = "controller: A
steps:
  - command: { GO: { p: 0, q: 5 } }
    expect: { fired: E0, vars: { v: 5, w: 0 } }
  - command: { GO: { p: 1, q: 7 } }
    expect: { fired: E1, vars: { v: 8, w: 7 } }
";
    run(plans, steps);
}

#[test]
fn a_var_with_a_parameters_name_passed_as_an_argument_keeps_its_value() {
    // The var `y` is passed for parameter `x`; the list's own `y` is 3.
    let plans = "controller A {
    command GO
    var y: u8 = 9
    var v: u8 = 0
    var w: u8 = 0
    jobs put(x: u8, y: u8) { v = x; w = y }
    plan GO {
        E0: *0 when new_command -> Done { put(y, 3) }
    }
}
";
    let steps = "controller: A
steps:
  - command: GO
    expect: { fired: E0, vars: { v: 9, w: 3 } }
";
    run(plans, steps);
}
