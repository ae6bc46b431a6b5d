//! Scenarios on the reference interpreter: every scenario under
//! `plans/*/scenarios/` passes, a wrong expectation fails naming its line,
//! expected against actual, and the rows fired so far, and a scenario that
//! names something the plans do not have is refused with its line.

use rcs_dsl::scenario;
use rcs_dsl::source::SourceFile;
use rcs_dsl::{check, load_folder, Options};
use std::path::Path;

fn submarine() -> rcs_dsl::ir::Ir {
    let set = load_folder(Path::new("../plans/submarine")).expect("plans");
    check(&set, &Options::default()).ir.expect("clean")
}

fn scenario_file(path: &str) -> SourceFile {
    SourceFile::new(path, std::fs::read_to_string(path).expect(path))
}

#[test]
fn every_plan_scenario_passes() {
    let mut ran = 0;
    for set in [
        "../plans/submarine",
        "../plans/figure13",
        "../plans/rcs_ex",
        "../plans/bridgeport_io",
        "../plans/packml",
        "../plans/fieldbus_drive",
    ] {
        let loaded = load_folder(Path::new(set)).expect("plans");
        let ir = check(&loaded, &Options::default()).ir.expect("clean");
        let dir = Path::new(set).join("scenarios");
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        let mut paths: Vec<_> = entries.map(|e| e.unwrap().path()).collect();
        paths.sort();
        for p in paths {
            let file = scenario_file(p.to_str().unwrap());
            let s = scenario::parse_any(&ir, &file, "s")
                .unwrap_or_else(|e| panic!("{}:{}: {}", p.display(), e.line, e.message));
            match s {
                scenario::AnyScenario::One(s) => {
                    let out = scenario::run(&ir, &s);
                    assert!(
                        out.failure.is_none(),
                        "{}: {:?}; fired {:?}",
                        p.display(),
                        out.failure,
                        out.fired
                    );
                }
                scenario::AnyScenario::System(s) => {
                    let out = scenario::run_system(&ir, &s);
                    assert!(out.failure.is_none(), "{}: {:?}", p.display(), out.failure);
                }
            }
            ran += 1;
        }
    }
    assert!(ran >= 1, "no scenario found");
}

#[test]
fn a_wrong_expectation_fails_with_its_line_and_the_rows_so_far() {
    let ir = submarine();
    let file = scenario_file("../tests/data/scenarios/wrong_expectation.scenario.yaml");
    let s = scenario::parse(&ir, &file, "wrong_expectation").expect("well-formed");
    assert_eq!(s.name, "wrong_expectation");
    let out = scenario::run(&ir, &s);
    let (line, report) = out.failure.clone().expect("fails");
    assert_eq!(line, 10, "the failing step's line");
    assert_eq!(report, "fired: expected E2, got none");
    assert_eq!(out.fired_per_cycle().collect::<Vec<_>>(), ["E0", "-"]);
}

#[test]
fn names_the_plans_lack_are_refused_with_their_line() {
    let ir = submarine();
    let cases = [
        ("controller: XX\nsteps: []\n", 1, "unknown controller `XX`"),
        (
            "controller: PR\nsteps:\n  - command: FLY\n",
            3,
            "`PR` has no command `FLY`",
        ),
        (
            "controller: PR\nsteps:\n  - command: { AHEAD: { knots: 3.0 } }\n",
            3,
            "command `AHEAD` of `PR` has no parameter `knots`",
        ),
        (
            "controller: PR\nsteps:\n  - command: { AHEAD: { speed: fast } }\n",
            3,
            "`speed`: expected f64",
        ),
        (
            "controller: PR\nsteps:\n  - expect: { fired: E9 }\n",
            3,
            "no row of `PR` is called `E9`",
        ),
        (
            "controller: PR\nsteps:\n  - hooks: { speed_error: Sideways }\n",
            3,
            "`speed_error`: expected SpeedError",
        ),
        (
            "controller: PR\nsteps:\n  - reads: { ship: { heading: 3 } }\n",
            3,
            "buffer type `Ship` has no field `heading`",
        ),
        (
            "controller: PR\nsteps:\n  - subordinates: { SM: DONE }\n",
            3,
            "`SM` is not a subordinate of `PR`",
        ),
        (
            "controller: PR\nsteps:\n  - expect: { vars: { speed: 1.0 } }\n",
            3,
            "`PR` has no var `speed`",
        ),
    ];
    // Block layout: each mistake is reported on the line of its own key,
    // not on the first line of its step.
    let block = [
        (
            "controller: PR\nsteps:\n  - command: INIT\n    expect:\n      state: S1\n      fired: E9\n",
            6,
            "no row of `PR` is called `E9`",
        ),
        (
            "controller: PR\nsteps:\n  - command: INIT\n    expect:\n      fired: E0\n      state: S7\n",
            6,
            "no plan of `PR` has a state `S7`",
        ),
        (
            "controller: PR\nsteps:\n  - command: INIT\n    expect:\n      status: EXECUTING\n\n      error: MELTED\n",
            7,
            "`PR` has no error code `MELTED`",
        ),
        (
            "controller: PR\nsteps:\n  - command: INIT\n    expect:\n      status: AT_REST\n",
            5,
            "`PR` has no status `AT_REST`",
        ),
        (
            "controller: PR\nsteps:\n  - command: INIT\n    hooks:\n      required_rpm: 3.0\n      warp: 9\n",
            6,
            "`PR` has no hook `warp`",
        ),
        (
            "controller: PR\nsteps:\n  - command: INIT\n  - subordinates:\n      TB: DONE\n      SM: DONE\n",
            6,
            "`SM` is not a subordinate of `PR`",
        ),
        (
            "controller: PR\nsteps:\n  - command: INIT\n  - subordinates:\n      TB:\n        status: SPINNING\n",
            5,
            "`TB` has no status `SPINNING`",
        ),
        (
            "controller: PR\nsteps:\n  - command: INIT\n    expect:\n      fired: E0\n      sent:\n        TB: FLY\n",
            7,
            "`TB` has no command `FLY`",
        ),
        (
            "controller: PR\nsteps:\n  - command: INIT\n    expect:\n      vars:\n        rpm: 0.0\n        speed: 1.0\n",
            7,
            "`PR` has no var `speed`",
        ),
        (
            "controller: TB\nsteps:\n  - command: INIT\n    expect:\n      writes:\n        drive: {}\n        brake: {}\n",
            7,
            "`TB` writes no buffer `brake`",
        ),
        (
            "controller: PR\ninitial:\n  reads:\n    ship: {}\n    sea: {}\nsteps: []\n",
            5,
            "`PR` reads no buffer `sea`",
        ),
        (
            "controller: PR\nsteps:\n  - command: INIT\n\n\n  - command:\n      AHEAD: { knots: 1.0 }\n",
            7,
            "command `AHEAD` of `PR` has no parameter `knots`",
        ),
        (
            "controller: PR\nsteps:\n  - hooks:\n      required_rpm: 1.0\n      required_rpm: 2.0\n",
            5,
            "required_rpm",
        ),
        (
            "controller: PR\nsteps:\n  - command: INIT\n    hooks: [required_rpm]\n",
            4,
            "mapping",
        ),
    ];
    for (text, line, message) in cases.into_iter().chain(block) {
        let file = SourceFile::new("t.scenario.yaml", text);
        let e = scenario::parse(&ir, &file, "t")
            .err()
            .unwrap_or_else(|| panic!("accepted: {text}"));
        assert_eq!(e.line, line, "{text}");
        assert!(e.message.contains(message), "{text}: {}", e.message);
    }
}
