//! The documentation is tested like code:
//!
//! - every ```rcs block of `docs/language.md` checks as it says: a plain
//!   `rcs` block with no diagnostic at all, an `rcs expect=CODE, …` block with
//!   exactly those codes (`rcs fragment` blocks are not checked); a
//!   ```yaml expect=… block is the `rcs.yaml` of the `rcs` block before it;
//!   a ```files expect=… block lists a folder layout (each `.rcs` file gets
//!   a small clean controller, each `rcs.yaml` is empty), loaded from its
//!   top folder as `rcsc` would;
//! - every diagnostic code has an example and a section there;
//! - `docs/ahead.svg`, the state graph shown in the README, is what
//!   `rcsc graph plans/submarine --plan PR.AHEAD --format svg` draws today
//!   (`UPDATE_DOCS=1 cargo test --test docs` rewrites it);
//! - the README gives the install, build and test commands, and its example
//!   scenario passes on the submarine plans, as do the examples of
//!   `docs/scenarios.md` (one-controller and system scenarios).

use rcs_dsl::lint::Lint;
use rcs_dsl::render::{self, Format};
use rcs_dsl::{Code, Options};
use std::collections::BTreeSet;
use std::process::Command;

mod markdown;
mod tools;
mod walkthrough;

use markdown::{blocks, Block};

/// Check one plan set made of `rcs` (as `example.rcs`) and an optional manifest;
/// returns the codes found and their short rendering.
fn check(rcs: &str, manifest: Option<&str>) -> (BTreeSet<String>, String) {
    let set = rcs_dsl::PlanSet::from_texts("example", [("example.rcs", rcs)], manifest);
    let checked = rcs_dsl::check(&set, &Options::default());
    let codes = checked
        .diagnostics
        .iter()
        .map(|d| d.code.name().to_string())
        .collect();
    let text = checked
        .diagnostics
        .iter()
        .map(|d| render::render(d, &set.sources, Format::Short))
        .collect();
    (codes, text)
}

/// Lay out the files of a ```files block in a scratch folder and check
/// every plan set its top folder holds; the codes found and their short
/// rendering.
fn check_layout(listing: &str, line: usize) -> (BTreeSet<String>, String) {
    let dir = std::env::temp_dir().join(format!("rcsc-docs-layout-{}-{line}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut top = None;
    for (i, path) in listing
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .enumerate()
    {
        let p = dir.join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        let body = if path.ends_with(".rcs") {
            format!("controller C{i} {{\n    command GO\n    plan GO {{ *0 when new_command -> Done }}\n}}\n")
        } else {
            String::new()
        };
        std::fs::write(&p, body).unwrap();
        top.get_or_insert_with(|| dir.join(path.split('/').next().unwrap()));
    }
    let sets = rcs_dsl::load_paths(&[top.expect("a file")]).unwrap();
    let mut codes = BTreeSet::new();
    let mut text = String::new();
    for set in &sets {
        for d in rcs_dsl::check(set, &Options::default()).diagnostics {
            codes.insert(d.code.name().to_string());
            text.push_str(&render::render(&d, &set.sources, Format::Short));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    (codes, text)
}

fn language_md() -> String {
    std::fs::read_to_string("docs/language.md").expect("docs/language.md exists")
}

#[test]
fn every_example_in_the_language_reference_checks_as_it_says() {
    let doc = language_md();
    let mut previous_rcs: Option<String> = None;
    let mut checked = 0;
    let mut failures = Vec::new();
    for b in blocks(&doc) {
        match b.lang.as_str() {
            "rcs" if b.is_fragment() => {}
            "rcs" => {
                let want = b.expected().unwrap_or_default();
                let (got, text) = check(&b.text, None);
                if got != want {
                    failures.push(format!(
                        "docs/language.md:{}: expected {want:?}, got {got:?}\n{text}",
                        b.line
                    ));
                }
                previous_rcs = Some(b.text.clone());
                checked += 1;
            }
            "files" => {
                let want = b.expected().unwrap_or_default();
                let (got, text) = check_layout(&b.text, b.line);
                if got != want {
                    failures.push(format!(
                        "docs/language.md:{}: expected {want:?}, got {got:?}\n{text}",
                        b.line
                    ));
                }
                checked += 1;
            }
            "yaml" if b.text.contains("steps:") => {
                // A scenario of the `rcs` block before it: `rcsc test` passes it.
                let rcs = previous_rcs.as_deref().unwrap_or_else(|| {
                    panic!("docs/language.md:{}: no rcs block before it", b.line)
                });
                if let Err(report) = scenario_passes(rcs, &b.text, b.line) {
                    failures.push(format!("docs/language.md:{}: {report}", b.line));
                }
                checked += 1;
            }
            "yaml" => match b.expected() {
                Some(want) => {
                    let rcs = previous_rcs.as_deref().unwrap_or_else(|| {
                        panic!("docs/language.md:{}: no rcs block before it", b.line)
                    });
                    let (got, text) = check(rcs, Some(&b.text));
                    if got != want {
                        failures.push(format!(
                            "docs/language.md:{}: expected {want:?}, got {got:?}\n{text}",
                            b.line
                        ));
                    }
                    checked += 1;
                }
                None => {
                    // A reference manifest: it must at least be a valid one.
                    let file = rcs_dsl::source::SourceFile::new("rcs.yaml", b.text.clone());
                    if let Err(ds) = rcs_dsl::manifest::parse(rcs_dsl::source::FileId(0), &file) {
                        failures.push(format!(
                            "docs/language.md:{}: not a valid manifest: {:?}",
                            b.line,
                            ds.iter().map(|d| &d.message).collect::<Vec<_>>()
                        ));
                    }
                }
            },
            _ => {}
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(checked >= 30, "only {checked} examples were checked");
}

#[test]
fn every_diagnostic_code_has_a_section_and_an_example() {
    let doc = language_md();
    let shown: BTreeSet<String> = blocks(&doc)
        .iter()
        .filter_map(Block::expected)
        .flatten()
        .collect();
    let codes = Code::ERRORS
        .into_iter()
        .chain(Lint::ALL.into_iter().map(Code::Lint));
    let mut missing = Vec::new();
    for code in codes {
        let name = code.name();
        if !doc.contains(&format!("#### `{name}`\n")) {
            missing.push(format!("no `#### `{name}`` section"));
        }
        // `too_large` needs 65,536 of something: its example is shown as
        // text, and `rcs-dsl/tests/limits.rs` checks it.
        if !shown.contains(name) && name != "too_large" {
            missing.push(format!("no `expect={name}` example"));
        }
    }
    assert!(
        missing.is_empty(),
        "docs/language.md: {}",
        missing.join("; ")
    );
}

#[test]
fn the_readme_gives_install_build_and_test_commands() {
    let readme = std::fs::read_to_string("README.md").unwrap();
    let commands: Vec<&str> = readme
        .lines()
        .map(|l| l.split('#').next().unwrap_or("").trim())
        .filter(|l| l.starts_with("cargo ") || l.starts_with("rcsc "))
        .collect();
    for want in [
        "cargo install --locked --path .",
        "rcsc build plans/",
        "cargo test --workspace",
    ] {
        assert!(
            commands.contains(&want),
            "README.md should give `{want}`; its cargo commands: {commands:?}"
        );
    }
    assert!(
        readme.contains("docs/ahead.svg"),
        "README.md shows the graph"
    );
    assert!(
        readme.contains("docs/language.md"),
        "README.md links the reference"
    );
}

#[test]
fn the_readme_scenario_passes() {
    doc_scenarios_pass("README.md");
}

#[test]
fn the_scenario_reference_example_passes() {
    doc_scenarios_pass("docs/scenarios.md");
}

/// Whether `rcsc test` passes `scenario` on the plan set made of `rcs`.
fn scenario_passes(rcs: &str, scenario: &str, line: usize) -> Result<(), String> {
    let dir =
        std::env::temp_dir().join(format!("rcsc-docs-scenario-{line}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("example.rcs"), rcs).map_err(|e| e.to_string())?;
    let file = dir.join("example.scenario.yaml");
    std::fs::write(&file, scenario).map_err(|e| e.to_string())?;
    let out = Command::new(env!("CARGO_BIN_EXE_rcsc"))
        .arg("test")
        .arg(&dir)
        .arg(&file)
        .env("NO_COLOR", "1")
        .output()
        .map_err(|e| e.to_string())?;
    std::fs::remove_dir_all(&dir).ok();
    let stdout = String::from_utf8_lossy(&out.stdout);
    if out.status.success() && stdout.ends_with("1 passed, 0 failed\n") {
        Ok(())
    } else {
        Err(format!(
            "the scenario fails:\n{stdout}{}",
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

/// Every scenario shown in `doc` (one-controller and system ones) passes
/// on the submarine plans.
fn doc_scenarios_pass(doc: &str) {
    let text = std::fs::read_to_string(doc).unwrap();
    let scenarios: Vec<Block> = blocks(&text)
        .into_iter()
        .filter(|b| {
            b.lang == "yaml"
                && b.text.contains("steps:")
                && (b.text.contains("controller:")
                    || b.text
                        .lines()
                        .any(|l| l.starts_with("system:") || l.starts_with("controllers:")))
        })
        .collect();
    assert!(!scenarios.is_empty(), "{doc} shows a scenario");
    let stem = doc.replace(['/', '.'], "-");
    let dir = std::env::temp_dir().join(format!("rcsc-docs-{stem}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (i, scenario) in scenarios.iter().enumerate() {
        let file = dir.join(format!("doc{i}.scenario.yaml"));
        std::fs::write(&file, &scenario.text).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_rcsc"))
            .args(["test", "plans/submarine"])
            .arg(&file)
            .env("NO_COLOR", "1")
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && stdout.ends_with("1 passed, 0 failed\n"),
            "{doc}:{}: the scenario fails:\n{stdout}",
            scenario.line
        );
    }
    std::fs::remove_dir_all(dir).ok();
}

/// SVG text without what depends on the Graphviz build (its version comment).
fn normalise_svg(svg: &str) -> String {
    let mut svg = svg.replace("\r\n", "\n");
    if let Some(start) = svg.find("<!-- Generated by graphviz") {
        if let Some(len) = svg[start..].find("-->") {
            svg.replace_range(start..start + len + 3, "");
        }
    }
    svg
}

#[test]
fn the_readme_state_graph_is_up_to_date() {
    if !tools::dot_available("docs/ahead.svg") {
        return;
    }
    let out = Command::new(env!("CARGO_BIN_EXE_rcsc"))
        .args([
            "graph",
            "plans/submarine",
            "--plan",
            "PR.AHEAD",
            "--format",
            "svg",
        ])
        .env("NO_COLOR", "1")
        .output()
        .expect("rcsc runs");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fresh = String::from_utf8(out.stdout).expect("SVG is UTF-8");
    let path = "docs/ahead.svg";
    if std::env::var_os("UPDATE_DOCS").is_some() {
        std::fs::write(path, &fresh).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        normalise_svg(&committed) == normalise_svg(&fresh),
        "{path} is stale: regenerate it with `UPDATE_DOCS=1 cargo test --test docs` \
         (or `rcsc graph plans/submarine --plan PR.AHEAD --format svg -o {path}`)"
    );
}

/// The README's "Using the generated code", followed as a newcomer would,
/// against this checkout (see `walkthrough`).
#[test]
fn using_the_generated_code_works_as_written() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    walkthrough::run(&readme, root, &root.join("target/using-generated-code"));
}
