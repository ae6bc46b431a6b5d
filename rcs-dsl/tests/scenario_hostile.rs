//! The scenario reader and runner under hostile input: the project's
//! scenarios (one-controller and system ones) with pieces of YAML spliced in anywhere are either refused
//! with a line inside the file or run to an outcome — never a panic.
//! `RCS_SCENARIO_CASES` raises the number of cases for a long run.

use proptest::prelude::*;
use rcs_dsl::scenario;
use rcs_dsl::source::SourceFile;
use rcs_dsl::{check, load_folder, Options};
use std::path::Path;

const PIECES: &[&str] = &[
    "0",
    "-1",
    "4294967296",
    "99999999999999999999",
    "1e400",
    ".nan",
    "ON",
    "NO",
    "y",
    "~",
    "null",
    "[",
    "]",
    "{",
    "}",
    ":",
    ",",
    "\n",
    "\r",
    "\t",
    " ",
    "\"",
    "'",
    "E99",
    "#9",
    "*",
    "&a ",
    "*a",
    "!!binary ",
    "- ",
    "? ",
    "cycles: 0",
    "cycles: 10000001",
    "{ 3: 1.5 }",
    "[1.0, 2.0]",
    "echo: previous",
    "silent: true",
    "hooks_called: { x: 1 }",
    "\u{feff}",
    "é",
    // System scenarios' keys (the submarine's system scenario is among the files).
    "system: true\n",
    "controllers: [TB]\n",
    "controllers: [PR]\n",
    "commands: { SM: INIT }",
    "commands: { PR: INIT }",
    "PR: { state: S1 }",
    "TB: { fired: E9 }",
    "hooks: { PR: 1 }",
    "{ PR: { required_rpm: x } }",
    "reads: { drive: {} }",
];

fn scenarios() -> Vec<String> {
    let dir = Path::new("../plans/submarine/scenarios");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .expect("scenarios")
        .map(|e| e.expect("entry").path())
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| std::fs::read_to_string(p).expect("text"))
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("RCS_SCENARIO_CASES").ok().and_then(|n| n.parse().ok()).unwrap_or(256)
    ))]

    #[test]
    fn spliced_scenarios_are_refused_with_a_line_or_run(
        which in any::<prop::sample::Index>(),
        cuts in prop::collection::vec((any::<prop::sample::Index>(), prop::sample::select(PIECES), 0usize..4), 1..4),
    ) {
        let all = scenarios();
        splice_and_run(all[which.index(all.len())].clone(), cuts)?;
    }

    #[test]
    fn spliced_system_scenarios_are_refused_with_a_line_or_run(
        cuts in prop::collection::vec((any::<prop::sample::Index>(), prop::sample::select(PIECES), 0usize..4), 1..4),
    ) {
        let text = std::fs::read_to_string(
            "../plans/submarine/scenarios/system_init_then_transit.scenario.yaml",
        )
        .expect("the submarine's system scenario");
        splice_and_run(text, cuts)?;
    }
}

/// Splice `cuts` (where, what, how many bytes it replaces) into `text`,
/// then read it: refused with a line inside the file, or run.
fn splice_and_run(
    mut text: String,
    cuts: Vec<(prop::sample::Index, &str, usize)>,
) -> Result<(), TestCaseError> {
    let set = load_folder(Path::new("../plans/submarine")).expect("plans");
    let ir = check(&set, &Options::default()).ir.expect("clean");
    for (at, piece, removed) in cuts {
        let mut i = at.index(text.len() + 1);
        while !text.is_char_boundary(i) {
            i -= 1;
        }
        let mut end = (i + removed).min(text.len());
        while !text.is_char_boundary(end) {
            end += 1;
        }
        text.replace_range(i..end, piece);
    }
    // Lines as the reader counts them: a lone `\r` ends a line too.
    let file = SourceFile::new("t.scenario.yaml", text.clone());
    let lines = file.line_starts().len();
    match scenario::parse_any(&ir, &file, "t") {
        Err(e) => prop_assert!(
            e.line >= 1 && e.line <= lines + 1,
            "line {} of {lines}: {}\n{text}",
            e.line,
            e.message
        ),
        Ok(s) => {
            // Keep the run short: a splice may ask for millions of cycles.
            if !text.contains("cycles: 1000") && !text.contains("99999") {
                match s {
                    scenario::AnyScenario::One(s) => {
                        let _ = scenario::run(&ir, &s);
                    }
                    scenario::AnyScenario::System(s) => {
                        let _ = scenario::run_system(&ir, &s);
                    }
                }
            }
        }
    }
    Ok(())
}

/// The case CI found: a lone `\r` splits a line (YAML and our reader agree
/// on that, `str::lines` does not) and an unterminated quote runs to the end.
#[test]
fn a_lone_carriage_return_and_an_open_quote_point_inside_the_file() {
    let set = load_folder(Path::new("../plans/submarine")).expect("plans");
    let ir = check(&set, &Options::default()).ir.expect("clean");
    let text = "name: t\ncontroller: SM\nsteps:\n  - command: INIT\n    expect: { sent: {\r PR: INIT } }\n\"  - cycles: 1\n";
    let file = SourceFile::new("t.scenario.yaml", text);
    let Err(e) = scenario::parse(&ir, &file, "t") else {
        panic!("an open quote was read")
    };
    assert!(
        e.line >= 1 && e.line <= file.line_starts().len(),
        "line {} of {}: {}",
        e.line,
        file.line_starts().len(),
        e.message
    );
}
