//! `rcsc fmt` never changes meaning: every golden ok case (files and
//! folders) and mutations of them (whitespace, blank lines, indentation,
//! comments) format to text whose IR equals the original's (spans aside),
//! and formatting the result again changes nothing. Every `.rcs` file of
//! the repository round-trips through the lossless tree.

use proptest::prelude::*;
use rcs_dsl::fmt::meaning::{first_difference, without_places};
use rcs_dsl::fmt::{format, parse, FmtError, FmtOptions};
use rcs_dsl::{check, Options, PlanSet};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The `.rcs` files below `dir` (or `dir` itself), sorted, as (path, text).
fn rcs_files(path: &Path) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut stack = vec![path.to_path_buf()];
    while let Some(p) = stack.pop() {
        if p.is_dir() {
            if p.file_name()
                .is_some_and(|n| n == "target" || n == ".git" || n == "node_modules")
            {
                continue;
            }
            for e in std::fs::read_dir(&p).unwrap() {
                stack.push(e.unwrap().path());
            }
        } else if p.extension().is_some_and(|e| e == "rcs") {
            let rel = p
                .strip_prefix(path)
                .unwrap_or(&p)
                .to_string_lossy()
                .replace('\\', "/");
            let rel = if rel.is_empty() {
                p.file_name().unwrap().to_string_lossy().into_owned()
            } else {
                rel
            };
            out.push((rel, std::fs::read_to_string(&p).unwrap_or_default()));
        }
    }
    out.sort();
    out
}

/// One golden case: its files and manifest.
struct Case {
    name: String,
    files: Vec<(String, String)>,
    manifest: Option<String>,
}

fn ok_cases() -> Vec<Case> {
    let dir = repo().join("tests/data/ok");
    let mut entries: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    entries
        .into_iter()
        .filter(|p| p.is_dir() || p.extension().is_some_and(|e| e == "rcs"))
        .map(|p| {
            // The loader decides which files belong (a manifest's `plans:`).
            let set = rcs_dsl::load_paths(std::slice::from_ref(&p))
                .unwrap()
                .remove(0);
            Case {
                name: p.file_name().unwrap().to_string_lossy().into_owned(),
                files: set
                    .rcs_files
                    .iter()
                    .map(|id| {
                        let f = set.sources.get(*id);
                        (f.path.clone(), f.text.clone())
                    })
                    .collect(),
                manifest: set.manifest_file.map(|id| set.sources.get(id).text.clone()),
            }
        })
        .collect()
}

/// The IR as `rcsc ir --format json` gives it, with every span (and
/// row line number and the file list) removed.
fn ir_without_spans(
    name: &str,
    files: &[(String, String)],
    manifest: Option<&str>,
) -> Option<serde_json::Value> {
    let set = PlanSet::from_texts(
        name,
        files.iter().map(|(p, t)| (p.as_str(), t.as_str())),
        manifest,
    );
    let ir = check(&set, &Options::default()).ir?;
    Some(without_places(&ir))
}

/// Format every file of a case; the same IR, and a second pass changes
/// nothing. `Err` says what went wrong.
fn formats_faithfully(
    name: &str,
    files: &[(String, String)],
    manifest: Option<&str>,
) -> Result<(), String> {
    let options = FmtOptions::default();
    let before = ir_without_spans(name, files, manifest)
        .ok_or_else(|| format!("{name}: the case does not check clean"))?;
    let mut formatted = Vec::new();
    for (path, text) in files {
        let once = format(text, &options).map_err(|e| format!("{name}/{path}: {e}"))?;
        let twice =
            format(&once, &options).map_err(|e| format!("{name}/{path} (second pass): {e}"))?;
        if once != twice {
            return Err(format!(
                "{name}/{path}: not idempotent:\n--- once\n{once}\n--- twice\n{twice}"
            ));
        }
        formatted.push((path.clone(), once));
    }
    let after = ir_without_spans(name, &formatted, manifest)
        .ok_or_else(|| format!("{name}: the formatted case no longer checks clean"))?;
    if before != after {
        return Err(format!(
            "{name}: the IR changed after formatting, at {}",
            first_difference(&before, &after, String::new())
        ));
    }
    Ok(())
}

#[test]
fn every_golden_ok_case_formats_to_the_same_ir_and_is_idempotent() {
    let cases = ok_cases();
    assert!(
        cases.len() >= 150,
        "the golden corpus is there ({} cases)",
        cases.len()
    );
    let mut failures = Vec::new();
    for case in &cases {
        if let Err(why) = formats_faithfully(&case.name, &case.files, case.manifest.as_deref()) {
            failures.push(why);
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n\n")
    );
}

#[test]
fn every_rcs_file_of_the_repository_round_trips_and_formats_or_is_refused() {
    let files = rcs_files(&repo());
    assert!(files.len() > 300, "{} files", files.len());
    for (path, text) in &files {
        assert_eq!(parse(text).root().to_string(), *text, "{path}");
        match format(text, &FmtOptions::default()) {
            Ok(once) => {
                assert_eq!(parse(&once).root().to_string(), once);
                let twice = format(&once, &FmtOptions::default()).unwrap();
                assert_eq!(once, twice, "{path} is not idempotent");
            }
            Err(FmtError::Syntax(_)) => {}
            Err(e) => panic!("{path}: {e}"),
        }
    }
}

/// A tiny deterministic generator (xorshift), seeded by proptest.
struct Rng(u64);
impl Rng {
    fn next(&mut self, n: u64) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0 % n.max(1)
    }
}

/// The text with its layout disturbed and comments added, its tokens
/// untouched: runs of spaces resized (never to nothing), lines
/// re-indented, blank lines added or removed, comments after code and on
/// lines of their own.
fn mutate(text: &str, seed: u64) -> String {
    let mut rng = Rng(seed | 1);
    let mut out = String::new();
    for line in text.lines() {
        let in_doc_or_string = line.contains("///") || line.contains('"');
        let body = line.trim_start();
        if body.is_empty() {
            if rng.next(3) == 0 {
                continue;
            }
            out.push('\n');
            continue;
        }
        match rng.next(8) {
            0 => out.push('\n'),
            1 => out.push_str("\n\n\n"),
            2 if !body.starts_with("///") => out.push_str("// a comment of its own\n"),
            3 if !body.starts_with("///") => out.push_str("/* block */ "),
            _ => {}
        }
        out.push_str(&" ".repeat(rng.next(13) as usize));
        if in_doc_or_string {
            out.push_str(body);
        } else {
            let mut prev_space = false;
            for c in body.chars() {
                if c == ' ' {
                    if !prev_space {
                        out.push_str(["\t", " ", "  ", "   "][rng.next(4) as usize]);
                    }
                    prev_space = true;
                } else {
                    out.push(c);
                    prev_space = false;
                }
            }
            if !body.contains("//") && rng.next(4) == 0 {
                out.push_str("   // trailing");
            }
        }
        out.push_str(["\n", "  \n", "\r\n"][rng.next(3) as usize]);
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn mutated_golden_cases_format_to_the_same_ir(pick in any::<u32>(), seed in any::<u64>()) {
        let cases = ok_cases();
        let case = &cases[pick as usize % cases.len()];
        let files: Vec<(String, String)> = case.files.iter().map(|(p, t)| (p.clone(), mutate(t, seed))).collect();
        // Only mutations that still check clean say anything about meaning.
        if ir_without_spans(&case.name, &files, case.manifest.as_deref()).is_some() {
            if let Err(why) = formats_faithfully(&case.name, &files, case.manifest.as_deref()) {
                prop_assert!(false, "seed {seed}: {why}");
            }
        }
    }
}

/// The property above says something only if mutated cases still check
/// clean: most of them must, for a fixed seed.
#[test]
fn most_mutations_still_check_clean() {
    let cases = ok_cases();
    let clean = cases
        .iter()
        .filter(|case| {
            let files: Vec<(String, String)> = case
                .files
                .iter()
                .map(|(p, t)| (p.clone(), mutate(t, 0x5eed)))
                .collect();
            ir_without_spans(&case.name, &files, case.manifest.as_deref()).is_some()
        })
        .count();
    assert!(
        clean * 10 >= cases.len() * 8,
        "{clean} of {} mutated cases check clean",
        cases.len()
    );
}
