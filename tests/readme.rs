//! The README, kept true by running it (issue 28, item 5).
//!
//! - Every ```` ```text ```` block of README.md is a **sample**: it is
//!   preceded by a `<!-- sample … -->` comment, and unless that comment
//!   names another test that checks it, this file runs its `$ rcsc …`
//!   command in a copy of `plans/`, `rcs.yaml` and `tests/data/scenarios/`
//!   (after the edit the comment asks for: `replace in FILE: TEXT` /
//!   `with: TEXT`) and compares what a terminal would show, stdout and
//!   stderr interleaved, line by line. A line `…` stands for any number of
//!   lines; the seconds of a `Finished in` line are not compared.
//! - Every `rcsc …` line of a ```` ```sh ```` block names a subcommand
//!   and options `rcsc SUBCOMMAND --help` lists.
//! - The counts and lists: the plan sets under `plans/`, the crates under
//!   `examples/`, the pages under `docs/`, and the diagnostic codes with
//!   their default levels.

use rcs_dsl::lint::{Level, Lint};
use rcs_dsl::Code;
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{copy_tree, text};

fn readme() -> String {
    std::fs::read_to_string("README.md").expect("README.md")
}

/// A fenced block: its info string, its first line's number (1-based) and
/// its text, and the lines just above its opening fence.
struct Block {
    info: String,
    line: usize,
    body: String,
    comment: Option<String>,
}

fn blocks(doc: &str) -> Vec<Block> {
    let lines: Vec<&str> = doc.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if let Some(info) = lines[i].strip_prefix("```") {
            let start = i + 1;
            let mut end = start;
            while end < lines.len() && !lines[end].starts_with("```") {
                end += 1;
            }
            // The comment ending on the line above the fence, if any.
            let comment = (i > 0 && lines[i - 1].trim_end().ends_with("-->")).then(|| {
                let mut k = i - 1;
                while k > 0 && !lines[k].contains("<!--") {
                    k -= 1;
                }
                lines[k..i].join("\n")
            });
            out.push(Block {
                info: info.trim().to_string(),
                line: start + 1,
                body: lines[start..end.min(lines.len())].join("\n"),
                comment,
            });
            i = end + 1;
        } else {
            i += 1;
        }
    }
    out
}

/// The value of `key: value` on a line of a sample comment.
fn field<'a>(comment: &'a str, key: &str) -> Option<&'a str> {
    comment
        .lines()
        .find_map(|l| l.trim().strip_prefix(key).map(str::trim))
}

fn scratch_copy(line: usize) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rcsc-readme-{}-{line}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    copy_tree(Path::new("plans"), &dir.join("plans"));
    copy_tree(
        Path::new("tests/data/scenarios"),
        &dir.join("tests/data/scenarios"),
    );
    std::fs::copy("rcs.yaml", dir.join("rcs.yaml")).expect("rcs.yaml");
    dir
}

/// `    Finished in 0.14s` → `    Finished in <time>`.
fn normalise(line: &str) -> String {
    let line = line.trim_end();
    match line.find("Finished in ") {
        Some(at) if line.ends_with('s') => format!("{}Finished in <time>", &line[..at]),
        _ => line.to_string(),
    }
}

/// Whether `got` matches `want`, where a `want` line `…` matches any run
/// of lines (none included).
fn matches(want: &[String], got: &[String]) -> bool {
    match want.split_first() {
        None => got.is_empty(),
        Some((w, rest)) if w.trim() == "…" => (0..=got.len()).any(|k| matches(rest, &got[k..])),
        Some((w, rest)) => got
            .split_first()
            .is_some_and(|(g, more)| g == w && matches(rest, more)),
    }
}

#[test]
fn every_output_sample_is_what_rcsc_prints() {
    let doc = readme();
    let mut ran = 0;
    for block in blocks(&doc).iter().filter(|b| b.info == "text") {
        let at = format!("README.md:{}", block.line);
        let comment = block
            .comment
            .as_deref()
            .filter(|c| c.contains("<!-- sample"))
            .unwrap_or_else(|| {
                panic!("{at}: a ```text block without a `<!-- sample … -->` comment saying what checks it")
            });
        // Checked elsewhere: the test named must exist and read README.md.
        if let Some(other) = comment
            .split(|c: char| c.is_whitespace() || c == '(' || c == ')')
            .find(|w| w.starts_with("examples/") || w.starts_with("tests/"))
            .filter(|w| w.ends_with(".rs") && *w != "tests/readme.rs")
        {
            let source = std::fs::read_to_string(other)
                .unwrap_or_else(|e| panic!("{at}: the sample's test {other}: {e}"));
            assert!(
                source.contains("README.md"),
                "{at}: {other} does not read README.md"
            );
            continue;
        }
        let mut lines = block.body.lines();
        let command = lines
            .next()
            .and_then(|l| l.strip_prefix("$ rcsc "))
            .unwrap_or_else(|| panic!("{at}: a sample starts with its `$ rcsc …` command"));
        let want: Vec<String> = lines.map(normalise).collect();
        let dir = scratch_copy(block.line);
        if let Some(file) = field(comment, "replace in ") {
            let (file, from) = file.split_once(": ").expect("replace in FILE: TEXT");
            let to = field(comment, "with: ").expect("`with:` after `replace in`");
            let path = dir.join(file);
            let source = std::fs::read_to_string(&path).expect("the file to edit");
            assert_eq!(source.matches(from).count(), 1, "{at}: `{from}` in {file}");
            std::fs::write(&path, source.replace(from, to)).expect("edit");
        }
        let exit: i32 = field(comment, "exit: ").map_or(0, |e| e.parse().expect("exit: N"));
        // One pipe for both streams, as a terminal shows them: stdout is
        // line-buffered and stderr unbuffered, so the order is rcsc's own.
        let out = Command::new("sh")
            .arg("-c")
            .arg("exec \"$0\" \"$@\" 2>&1")
            .arg(env!("CARGO_BIN_EXE_rcsc"))
            .args(command.split_whitespace())
            .current_dir(&dir)
            .env("NO_COLOR", "1")
            .output()
            .expect("sh runs rcsc");
        let got: Vec<String> = text(&out.stdout).lines().map(normalise).collect();
        assert_eq!(
            out.status.code(),
            Some(exit),
            "{at}: `rcsc {command}` exited otherwise:\n{}",
            text(&out.stdout)
        );
        assert!(
            matches(&want, &got),
            "{at}: `rcsc {command}` prints something else now.\nREADME:\n{}\n\nrcsc:\n{}",
            want.join("\n"),
            got.join("\n")
        );
        let _ = std::fs::remove_dir_all(&dir);
        ran += 1;
    }
    assert!(ran >= 4, "only {ran} samples ran");
}

#[test]
fn the_sample_matcher_takes_ellipses_and_nothing_else() {
    let v = |s: &[&str]| s.iter().map(|l| normalise(l)).collect::<Vec<_>>();
    assert!(matches(&v(&["a", "…", "d"]), &v(&["a", "b", "c", "d"])));
    assert!(matches(&v(&["a", "…", "b"]), &v(&["a", "b"])));
    assert!(!matches(&v(&["a", "c"]), &v(&["a", "b"])));
    assert!(!matches(&v(&["a"]), &v(&["a", "b"])));
    assert!(matches(
        &v(&["    Finished in 0.01s"]),
        &v(&["    Finished in 12.50s"])
    ));
}

/// `rcsc SUB --help`, cached per subcommand.
fn help(sub: &str, cache: &mut std::collections::BTreeMap<String, String>) -> String {
    cache
        .entry(sub.to_string())
        .or_insert_with(|| {
            let out = Command::new(env!("CARGO_BIN_EXE_rcsc"))
                .args([sub, "--help"])
                .output()
                .expect("rcsc runs");
            assert!(out.status.success(), "`rcsc {sub} --help` fails");
            text(&out.stdout)
        })
        .clone()
}

#[test]
fn every_rcsc_command_shown_uses_options_that_exist() {
    let doc = readme();
    let mut cache = std::collections::BTreeMap::new();
    let mut checked = 0;
    for block in blocks(&doc).iter().filter(|b| b.info == "sh") {
        for (k, line) in block.body.lines().enumerate() {
            // `source <(rcsc …)`, `rcsc … | dot`, `rcsc … && rcsc …`.
            let line = line.split(" #").next().unwrap_or("");
            for part in line.split(['|', '&', '(', ')', ';']) {
                let Some(rest) = part.trim().strip_prefix("rcsc ") else {
                    continue;
                };
                let mut words = rest.split_whitespace();
                let sub = words.next().expect("a subcommand");
                let page = help(sub, &mut cache);
                for w in words.take_while(|w| !w.starts_with('>')) {
                    let flag = w.split('=').next().unwrap_or(w);
                    if flag.starts_with('-') {
                        // The option as a whole word of the page: `--open` is
                        // not `--opener`.
                        let whole = page.match_indices(flag).any(|(at, _)| {
                            !page[at + flag.len()..]
                                .starts_with(|c: char| c.is_alphanumeric() || c == '-' || c == '_')
                        });
                        assert!(
                            whole,
                            "README.md:{}: `rcsc {sub}` has no option `{flag}`",
                            block.line + k
                        );
                    }
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 20, "only {checked} commands found");
}

/// The backticked names of the paragraph starting with `lead`.
fn listed(doc: &str, lead: &str) -> Vec<String> {
    let start = doc
        .find(lead)
        .unwrap_or_else(|| panic!("README.md: no `{lead}`"));
    let para = &doc[start..start + doc[start..].find("\n\n").unwrap_or(doc.len() - start)];
    para.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

#[test]
fn the_diagnostic_codes_are_the_catalogue() {
    let doc = readme();
    let errors = listed(&doc, "Errors: ");
    let want: Vec<String> = Code::ERRORS.iter().map(|c| c.name().to_string()).collect();
    assert_eq!(errors, want, "README.md's list of errors");
    let lints = listed(&doc, "Lints (default level): ");
    let want: Vec<String> = Lint::ALL.iter().map(|l| l.name().to_string()).collect();
    assert_eq!(lints, want, "README.md's list of lints");
    // The levels: every deny lint says so, and only they.
    let start = doc.find("Lints (default level): ").expect("lints");
    let para = &doc[start..start + doc[start..].find("\n\n").expect("paragraph")];
    for l in Lint::ALL {
        let marked = para.contains(&format!("`{}` (deny)", l.name()));
        assert_eq!(
            marked,
            l.default_level() == Level::Deny,
            "README.md: `{}` is {:?} by default",
            l.name(),
            l.default_level()
        );
    }
}

/// Folder names under `dir` (files with `ext`, without it, when given).
fn entries(dir: &str, ext: Option<&str>) -> Vec<String> {
    let mut out: Vec<String> = std::fs::read_dir(dir)
        .expect("readable")
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| match ext {
            None => p.is_dir(),
            Some(x) => p.extension().is_some_and(|e| e == x),
        })
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    out.sort();
    out
}

/// The row of the Layout table for `path`.
fn layout_row<'a>(doc: &'a str, path: &str) -> &'a str {
    let key = format!("| `{path}` |");
    doc.lines()
        .find(|l| l.starts_with(&key))
        .unwrap_or_else(|| panic!("README.md's layout has no row for {path}"))
}

#[test]
fn the_layout_and_counts_name_what_is_there() {
    let doc = readme();
    const NUMBERS: [&str; 11] = [
        "no", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten",
    ];
    let sets = entries("plans", None);
    let quick = &doc[doc
        .find("`rcsc build plans/` is the main job.")
        .expect("Quick start")..];
    let quick = &quick[..quick.find("\n\n").expect("paragraph")];
    assert!(
        quick.contains(&format!("holding {}\nplan sets", NUMBERS[sets.len()]))
            || quick.contains(&format!("holding {} plan sets", NUMBERS[sets.len()])),
        "README.md's Quick start should say plans/ holds {} plan sets",
        NUMBERS[sets.len()]
    );
    let plans_row = layout_row(&doc, "plans/");
    for set in &sets {
        assert!(
            quick.contains(&format!("`plans/{set}`")),
            "Quick start: plans/{set}"
        );
        assert!(
            plans_row.contains(&format!("`{set}`")),
            "layout: plans/{set}"
        );
    }
    let examples_row = layout_row(&doc, "examples/");
    for ex in entries("examples", None) {
        assert!(
            examples_row.contains(&format!("`{ex}`")),
            "layout: examples/{ex}"
        );
    }
    let docs_row = layout_row(&doc, "docs/");
    for page in entries("docs", Some("md")) {
        assert!(
            docs_row.contains(&format!("`{page}`")),
            "layout: docs/{page}"
        );
    }
    for krate in ["rcs-dsl", "rcs-codegen", "rcs-runtime"] {
        layout_row(&doc, &format!("{krate}/"));
    }
    for page in ["CONTRIBUTING.md", "CHANGELOG.md", "BENCHMARKS.md"] {
        assert!(
            doc.contains(&format!("]({page})")),
            "README.md links {page}"
        );
    }
}

#[test]
fn rcsc_help_names_every_kind_of_path() {
    let out = Command::new(env!("CARGO_BIN_EXE_rcsc"))
        .arg("--help")
        .output()
        .expect("rcsc runs");
    let help = text(&out.stdout);
    for kind in ["plan-set folder", "workspace", ".rcs files"] {
        assert!(
            help.contains(kind),
            "`rcsc --help` does not mention {kind}:\n{help}"
        );
    }
}
