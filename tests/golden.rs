//! Data-driven golden tests of the front end, over `tests/data/`:
//!
//! - `ok/NNNN_name.rcs` (or a folder with `rcs.yaml`): must check with no
//!   diagnostic at all and yield an IR.
//! - `err/NNNN_name.rcs` (or a folder): the first line of the (first) `.rcs`
//!   file says which codes it must produce, `// expect: code, code`; the set
//!   of codes produced must be exactly that. The full human and JSON
//!   renderings are kept as insta snapshots in `err/snapshots/`.
//!
//! One walker serves every case; add a case by adding a file. The catalogue
//! coverage test fails until every diagnostic code has at least two cases.

use rcs_dsl::lint::Lint;
use rcs_dsl::render::{self, Format};
use rcs_dsl::{Code, Options};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn cases(kind: &str) -> Vec<PathBuf> {
    let dir = Path::new("tests/data").join(kind);
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("readable entry").path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            name.as_bytes()[0].is_ascii_digit()
                && (p.is_dir() || p.extension().is_some_and(|e| e == "rcs"))
        })
        .collect();
    out.sort();
    assert!(!out.is_empty(), "no cases under {}", dir.display());
    out
}

fn first_rcs(case: &Path) -> PathBuf {
    if case.is_file() {
        return case.to_path_buf();
    }
    let mut files: Vec<PathBuf> = Vec::new();
    let mut stack = vec![case.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rcs") {
                files.push(p);
            }
        }
    }
    files.sort();
    files
        .into_iter()
        .next()
        .unwrap_or_else(|| panic!("{}: no .rcs file", case.display()))
}

/// The codes a case declares on its first line: `// expect: a, b`.
fn expected_codes(case: &Path) -> BTreeSet<String> {
    let file = first_rcs(case);
    // Lossy: a case may hold invalid UTF-8 on purpose (after its first line).
    let text = String::from_utf8_lossy(&std::fs::read(&file).unwrap()).into_owned();
    let first = text
        .trim_start_matches('\u{feff}')
        .lines()
        .next()
        .unwrap_or("");
    let list = first.strip_prefix("// expect:").unwrap_or_else(|| {
        panic!(
            "{}: first line must be `// expect: CODE, …`",
            file.display()
        )
    });
    list.split(',')
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect()
}

fn case_name(case: &Path) -> String {
    case.file_stem().unwrap().to_string_lossy().into_owned()
}

/// Check one case: every plan set it holds (a case folder may be a
/// workspace) with its result.
fn run(case: &Path) -> Vec<(rcs_dsl::PlanSet, rcs_dsl::Checked)> {
    let sets = rcs_dsl::load_paths(&[case.to_path_buf()])
        .unwrap_or_else(|e| panic!("{}: {e}", case.display()));
    assert!(!sets.is_empty(), "{}: no plan set", case.display());
    sets.into_iter()
        .map(|set| {
            let checked = rcs_dsl::check(&set, &Options::default());
            (set, checked)
        })
        .collect()
}

/// Every diagnostic of a case, rendered in `format`.
fn rendered(results: &[(rcs_dsl::PlanSet, rcs_dsl::Checked)], format: Format) -> String {
    results
        .iter()
        .flat_map(|(set, checked)| {
            checked
                .diagnostics
                .iter()
                .map(move |d| render::render(d, &set.sources, format))
        })
        .collect()
}

/// Every label of every diagnostic lies inside its file, on char boundaries.
fn assert_spans_inside(case: &Path, set: &rcs_dsl::PlanSet, checked: &rcs_dsl::Checked) {
    for d in &checked.diagnostics {
        for l in &d.labels {
            let text = &set.sources.get(l.span.file).text;
            assert!(
                l.span.start <= l.span.end
                    && (l.span.end as usize) <= text.len()
                    && text.is_char_boundary(l.span.start as usize)
                    && text.is_char_boundary(l.span.end as usize),
                "{}: label {:?} outside its file",
                case.display(),
                l
            );
        }
    }
}

#[test]
fn ok_cases_check_clean() {
    for case in cases("ok") {
        let results = run(&case);
        let shown = rendered(&results, Format::Short);
        assert!(shown.is_empty(), "{}:\n{shown}", case.display());
        for (set, checked) in &results {
            assert!(
                checked.ir.is_some(),
                "{} ({}): no IR",
                case.display(),
                set.name
            );
        }
    }
}

#[test]
fn err_cases_match_expectations_and_snapshots() {
    let mut problems = Vec::new();
    for case in cases("err") {
        let results = run(&case);
        for (set, checked) in &results {
            assert_spans_inside(&case, set, checked);
        }
        let got: BTreeSet<String> = results
            .iter()
            .flat_map(|(_, checked)| &checked.diagnostics)
            .map(|d| d.code.name().to_string())
            .collect();
        let want = expected_codes(&case);
        if got != want {
            let shown = rendered(&results, Format::Short);
            problems.push(format!(
                "{}: expected {want:?}, got {got:?}\n{shown}",
                case.display()
            ));
            continue;
        }
        let mut out = rendered(&results, Format::Human { color: false });
        out.push_str("---- json\n");
        out.push_str(&rendered(&results, Format::Json));
        insta::with_settings!({
            snapshot_path => "data/err/snapshots",
            prepend_module_to_snapshot => false,
            omit_expression => true,
            description => case.display().to_string(),
        }, {
            insta::assert_snapshot!(case_name(&case), out);
        });
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// Codes whose failing inputs are megabytes (65,536 statuses or rows):
/// `rcs-dsl/tests/limits.rs` generates them instead of keeping files here.
const GENERATED: &[&str] = &["too_large"];

/// The catalogue is covered: every code has at least two failing cases.
#[test]
fn every_code_has_two_err_cases() {
    let mut count: BTreeMap<String, usize> = BTreeMap::new();
    for case in cases("err") {
        for code in expected_codes(&case) {
            *count.entry(code).or_default() += 1;
        }
    }
    let all = Code::ERRORS.into_iter().chain(Lint::ALL.map(Code::Lint));
    let thin: Vec<String> = all
        .map(|c| c.name())
        .filter(|n| count.get(*n).copied().unwrap_or(0) < 2 && !GENERATED.contains(n))
        .map(|n| format!("{n} ({})", count.get(n).copied().unwrap_or(0)))
        .collect();
    assert!(
        thin.is_empty(),
        "codes with fewer than two err cases: {}",
        thin.join(", ")
    );
}

/// The analysis of conditions is exercised in depth: at least three
/// failing cases for each kind of finding it makes (named by the case's
/// file name), and at least thirty clean plans built around its traps
/// (`ok/01NN_analysis_*`: wrapping, NaN gaps, opaque terms, open statuses…)
/// that must produce no finding at all.
#[test]
fn the_analysis_has_three_err_cases_per_class_and_thirty_clean_plans() {
    const CLASSES: [(&str, &str); 15] = [
        ("shadowed by implication", "shadowed_row_by_implication"),
        ("shadowed by a union of rows", "shadowed_row_by_union"),
        ("shadowed by preceding *N rows", "shadowed_row_by_dont_care"),
        (
            "shadowed by enum exhaustion",
            "shadowed_row_by_enum_exhaustion",
        ),
        (
            "shadowed by status exhaustion",
            "shadowed_row_by_status_exhaustion",
        ),
        (
            "shadowed by boolean structure",
            "shadowed_row_by_boolean_structure",
        ),
        (
            "shadowed by integer ranges",
            "shadowed_row_by_integer_ranges",
        ),
        ("shadowed by type bounds", "shadowed_row_by_type_bounds"),
        ("unreachable row, unsatisfiable", "unreachable_row_"),
        ("unreachable row, type bound", "unreachable_row_type_bound"),
        ("dead end behind dead rows", "dead_end_state_"),
        (
            "unreachable state behind dead rows",
            "unreachable_state_behind",
        ),
        (
            "unreachable state, target of a dead row",
            "unreachable_state_",
        ),
        ("no_done via dead rows", "no_done_"),
        ("unhandled_error", "unhandled_error_"),
    ];
    let names: Vec<String> = cases("err").iter().map(|c| case_name(c)).collect();
    let thin: Vec<String> = CLASSES
        .iter()
        .map(|(what, part)| (what, names.iter().filter(|n| n.contains(part)).count()))
        .filter(|(_, n)| *n < 3)
        .map(|(what, n)| format!("{what} ({n})"))
        .collect();
    assert!(
        thin.is_empty(),
        "classes with fewer than three err cases: {}",
        thin.join(", ")
    );
    let clean = cases("ok")
        .iter()
        .filter(|c| case_name(c).contains("_analysis_"))
        .count();
    assert!(clean >= 30, "only {clean} clean analysis plans in ok/");
}
