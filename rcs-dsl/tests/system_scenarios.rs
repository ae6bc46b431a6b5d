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

/// A wrong expectation fails on its step's line, naming the step, the
/// controller and the key, expected against actual.
#[test]
fn a_wrong_expectation_names_step_controller_and_key() {
    let ir = load("../plans/submarine");
    let text = "system: true
steps:
  - command: INIT
  - expect:
      PR: { fired: E1, status: DONE }
      TB: { state: S1, status: DONE }
";
    let s = system(&ir, text).unwrap();
    let out = scenario::run_system(&ir, &s);
    let (line, report) = out.failure.expect("fails");
    assert_eq!(line, 4);
    assert_eq!(report, "step 2, TB: state: expected S1, got S0");
    // The rows of every controller are kept, for the report and coverage.
    let pr = &out
        .controllers
        .iter()
        .find(|(c, _)| ir.controller(*c).name == "PR")
        .unwrap()
        .1;
    assert_eq!(pr.fired_per_cycle().collect::<Vec<_>>(), ["E0", "E1"]);
}

#[test]
fn names_and_shapes_are_refused_with_their_line() {
    let sub = load("../plans/submarine");
    let pack = load("../plans/packml");
    let cases: &[(&rcs_dsl::ir::Ir, &str, usize, &str)] = &[
        (&sub, "controllers: [SM, PR]\nsteps: []\n", 1, "`TB` is a subordinate of `PR` but not in `controllers`"),
        (&sub, "controllers: [SM, NOPE]\nsteps: []\n", 1, "unknown controller `NOPE`"),
        (&sub, "controllers: [TB, TB]\nsteps: []\n", 1, "`TB` is named twice"),
        (&sub, "controllers: []\nsteps: []\n", 1, "names no controller"),
        (&sub, "controllers: TB\nsteps: []\n", 1, "a list of controller names"),
        (&sub, "system: false\nsteps: []\n", 1, "`system` is `true`"),
        (&sub, "system: true\ncontrollers: [TB]\nsteps: []\n", 1, "not both"),
        (&sub, "system: true\nsteps:\n  - expect:\n      XX: { state: S1 }\n", 4, "unknown controller `XX`"),
        (&sub, "controllers: [TB]\nsteps:\n  - expect:\n      PR: { state: S1 }\n", 4, "`PR` is not in this run"),
        (&sub, "system: true\nsteps:\n  - expect:\n      PR: { state: S9 }\n", 4, "no plan of `PR` has a state `S9`"),
        (&sub, "system: true\nsteps:\n  - expect:\n      PR: { sent: { SM: INIT } }\n", 4, "`SM` is not a subordinate of `PR`"),
        (&sub, "system: true\nsteps:\n  - reads: { drive: { engaged: true } }\n", 3, "`drive` is written by `TB`, which is in the run"),
        (&sub, "controllers: [TB]\nsteps:\n  - reads: { ship: { speed: 1.0 } }\n", 3, "no controller of the run reads `ship`"),
        (&sub, "system: true\nsteps:\n  - hooks: { required_rpm: 1.0 }\n", 3, "hooks are given per controller: `hooks: { PR: { required_rpm: … } }`"),
        (&sub, "system: true\nsteps:\n  - hooks: { PR: { nope: 1.0 } }\n", 3, "`PR` has no hook `nope`"),
        (&sub, "system: true\nsteps:\n  - hooks: { PR: { required_rpm: true } }\n", 3, "expected f64"),
        (&sub, "system: true\nsteps:\n  - command: AHEAD\n", 3, "`SM` has no command `AHEAD`"),
        (&sub, "system: true\nsteps:\n  - commands: { PR: INIT }\n", 3, "`PR` is not a root of this run"),
        (&sub, "system: true\nsteps:\n  - subordinates: { PR: DONE }\n", 3, "unknown field `subordinates`"),
        (&sub, "system: true\nsteps:\n  - cycles: 0\n", 3, "`cycles` is a whole number"),
        (&sub, "system: true\ninitial:\n  vars: { PR: { nope: 1 } }\nsteps: []\n", 3, "`PR` has no var `nope`"),
        (&pack, "controllers: [INFEED, FILLER]\nsteps:\n  - command: RESET\n", 3, "this run has 2 roots (INFEED, FILLER)"),
        (&pack, "controllers: [INFEED, FILLER]\nsteps:\n  - commands: { INFEED: RESET, INFEED: STOP }\n", 3, "given twice"),
    ];
    for (ir, text, line, needle) in cases {
        let Err((l, m)) = system(ir, text) else {
            panic!("accepted: {text}");
        };
        assert!(m.contains(needle), "{text}\n→ {m}");
        assert_eq!(l, *line, "{text}\n→ {m}");
    }
    // Several roots each take their command by name.
    let s = system(&pack, "controllers: [INFEED, FILLER]\nsteps:\n  - commands: { INFEED: RESET, FILLER: START }\n    expect:\n      INFEED: { fired: E0, state: S1 }\n      FILLER: { fired: E0, state: S1, writes: { filler_out: { run: true } } }\n").unwrap();
    let out = scenario::run_system(&pack, &s);
    assert!(out.failure.is_none(), "{:?}", out.failure);
}

/// The programmatic form (what cross-controller witnesses are written
/// as): built in code, written as a file, read back to the same script,
/// and run through that file.
#[test]
fn a_script_round_trips_through_its_file_and_runs() {
    use rcs_dsl::interp::Value;
    use scenario::{ControllerExpect, SystemScript, SystemStep};
    let ir = load("../plans/submarine");
    let expect = |c: &str, e: ControllerExpect| (c.to_string(), e);
    let script = SystemScript {
        name: "TRANSIT, \"built\" in code".to_string(),
        controllers: None,
        initial: SystemStep {
            reads: vec![(
                "ship".into(),
                Value::Buffer(vec![Value::Enum(0), Value::Float(0.1)]),
            )],
            hooks: vec![
                ("PR".into(), "required_rpm".into(), Value::Float(100.0)),
                ("PR".into(), "speed_error".into(), Value::Enum(1)),
            ],
            vars: vec![("PR".into(), "rpm".into(), Value::Float(1e-7))],
            ..SystemStep::default()
        },
        steps: vec![
            SystemStep {
                commands: vec![("SM".into(), "TRANSIT".into(), vec![Value::Float(10.0)])],
                cycles: 1,
                expect: vec![
                    expect(
                        "SM",
                        ControllerExpect {
                            fired: Some(Some("E0".into())),
                            state: Some("S1".into()),
                            sent: Some(vec![(
                                "PR".into(),
                                "AHEAD".into(),
                                vec![Value::Float(10.0)],
                            )]),
                            ..ControllerExpect::default()
                        },
                    ),
                    expect(
                        "TB",
                        ControllerExpect {
                            fired: Some(Some("E0".into())),
                            status: Some("EXECUTING".into()),
                            error: Some(None),
                            ..ControllerExpect::default()
                        },
                    ),
                ],
                ..SystemStep::default()
            },
            SystemStep {
                reads: vec![("turbine".into(), Value::Buffer(vec![Value::Float(100.0)]))],
                cycles: 4,
                expect: vec![
                    expect(
                        "PR",
                        ControllerExpect {
                            status: Some("AT_GOAL".into()),
                            vars: vec![
                                ("rpm".into(), Value::Float(100.0)),
                                ("ship_speed".into(), Value::Float(0.1)),
                            ],
                            sent: Some(vec![]),
                            ..ControllerExpect::default()
                        },
                    ),
                    expect(
                        "SM",
                        ControllerExpect {
                            fired: Some(None),
                            state: Some("S2".into()),
                            ..ControllerExpect::default()
                        },
                    ),
                ],
                ..SystemStep::default()
            },
        ],
    };
    let text = script.to_yaml(&ir);
    let back = SystemScript::from_yaml(&ir, &text, "x")
        .unwrap_or_else(|e| panic!("{}: {}\n{text}", e.line, e.message));
    assert_eq!(back, script, "{text}");
    let out = scenario::run_script(&ir, &script).unwrap();
    assert!(out.failure.is_none(), "{:?}\n{text}", out.failure);

    // A wrong expectation fails, naming step, controller and key.
    let mut wrong = script.clone();
    wrong.steps[1].expect[1].1.state = Some("S1".into());
    let (line, report) = scenario::run_script(&ir, &wrong)
        .unwrap()
        .failure
        .expect("fails");
    assert_eq!(report, "step 2, SM: state: expected S1, got S2");
    assert!(line > 1);

    // A subtree, and a file written by hand, read as a script and back.
    let path = "../plans/rcs_ex/scenarios/system_prim_servo_subtree.scenario.yaml";
    let ex = load("../plans/rcs_ex");
    let s = SystemScript::from_yaml(&ex, &std::fs::read_to_string(path).unwrap(), "x").unwrap();
    assert_eq!(
        s.controllers.as_deref(),
        Some(&["PRIM".to_string(), "SERVO".to_string()][..])
    );
    let again = SystemScript::from_yaml(&ex, &s.to_yaml(&ex), "x").unwrap();
    assert_eq!(again, s);
    assert!(scenario::run_script(&ex, &s).unwrap().failure.is_none());
}
