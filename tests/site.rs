//! `rcsc doc`, `rcsc trace` and traces, end to end: the pages of a small
//! plan set (snapshots of the pure generation), every link of the site
//! for `plans/` resolving, byte-identical output, the site without
//! Graphviz, `--open` without a browser, trace versions, a run of the submarine example replayed
//! through `rcsc trace`, a large set documented cluster by cluster, and
//! the Changes page of `rcsc doc --diff` (fixture: `tests/data/site/`).

mod common;
#[path = "../rcs-dsl/benches/common/plan_set.rs"]
mod plan_set;

use common::site_links::broken_links;
use common::{copy_tree, rcsc, scratch, text, tree};
use rcs_codegen::site::{self, SetDoc, Site, Svgs};
use std::collections::BTreeMap;
use std::path::Path;

const SMALL: &str = "\
/// Moves and stops.
controller A {
    reads pos: Position
    command GO(speed: f64)
    status MOVING
    plan GO {
        /// Start moving.
        E0: *0 when new_command -> S1 { report MOVING }
        E1: S1 when pos.x > 10.0 -> Done
        E2: S1 when pos.x > 20.0 -> Done
        E3: *3 when plan_cycles > 99 -> Error
    }
}
buffer Position { x: f64 }
";

/// A stand-in for Graphviz: an SVG with one element per `id` of the DOT,
/// each wrapped in the link the DOT asks for (as `dot -Tsvg` does).
fn fake_svg(dot: &str) -> String {
    let mut out = String::from("<?xml version=\"1.0\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\">\n");
    for line in dot.lines() {
        let Some(at) = line.find("[id=\"") else {
            continue;
        };
        let rest = &line[at + 5..];
        let id = &rest[..rest.find('"').unwrap()];
        let url = rest
            .split_once("URL=\"")
            .map(|(_, u)| &u[..u.find('"').unwrap()])
            .unwrap_or("");
        out.push_str(&format!(
            "<g id=\"{id}\"><a xlink:href=\"{url}\"><text>{id}</text></a></g>\n"
        ));
    }
    out.push_str("</svg>\n");
    out
}

fn small_site_files(with_runs: bool) -> BTreeMap<String, String> {
    let set = rcs_dsl::PlanSet::from_texts("small", [("small.rcs", SMALL)], None);
    // The shadowed row is a warning here, so the site has a finding to show.
    let shadowed = rcs_dsl::lint::Lint::from_name("shadowed_row").unwrap();
    let options = rcs_dsl::Options {
        lint_flags: vec![(shadowed, rcs_dsl::lint::Level::Warn)],
    };
    let checked = rcs_dsl::check(&set, &options);
    let ir = checked.ir.expect("the small set checks");
    let mut runs = site::RunCounts {
        source: "a test".into(),
        ..Default::default()
    };
    runs.add_row("A", 0, 0, 1);
    runs.add_row("A", 0, 1, 1);
    runs.add_state("A", 0, 1, 7);
    let s = Site {
        shared: false,
        changes: None,
        sets: vec![SetDoc {
            ir: &ir,
            sources: set.sources.files().map(|(_, f)| f.text.as_str()).collect(),
            findings: &checked.diagnostics,
            runs: with_runs.then_some(&runs),
        }],
    };
    let svgs: Svgs = site::graphs(&s)
        .into_iter()
        .map(|g| (g.key, fake_svg(&g.dot)))
        .collect();
    let mut files: BTreeMap<String, String> = site::pages(&s, &svgs)
        .into_iter()
        .map(|f| (f.path, f.contents))
        .collect();
    for g in site::graphs(&s) {
        files.insert(format!("{}.dot", g.key), g.dot);
    }
    files
}

#[test]
fn pages_of_a_small_plan_set() {
    let files = small_site_files(true);
    for (path, contents) in &files {
        if path.ends_with(".css") || path.ends_with("site.js") {
            continue;
        }
        insta::assert_snapshot!(format!("site_small__{}", path.replace('/', "__")), contents);
    }
    // A finding sits on the row it concerns: E2 can never fire after E1.
    let plan = &files["A.GO.html"];
    let row = &plan[plan.find("<tr id=\"row-E2\"").unwrap()..];
    let row = &row[..row.find("</tr>").unwrap()];
    assert!(row.contains("class=\"finding"), "{row}");
    // Runs: heavier edges, never-fired rows marked, cycles per state.
    assert!(files["A.GO.html.dot"].contains("class=\"never\""));
    assert!(
        plan.contains("<tr id=\"row-E3\" class=\"never\">"),
        "{plan}"
    );
    assert!(plan.contains("7 cycles"));
    assert_eq!(broken_links(&files), Vec::<String>::new());
    // Without runs nothing says so.
    let plain = small_site_files(false);
    assert!(!plain["A.GO.html"].contains("hits"));
}

/// The site's files as text.
fn site_of(dir: &Path) -> BTreeMap<String, String> {
    tree(dir)
        .into_iter()
        .map(|(p, b)| (p, String::from_utf8(b).expect("UTF-8")))
        .collect()
}

#[test]
fn every_link_of_the_plans_site_resolves_and_output_is_the_same_twice() {
    let dir = scratch("doc-plans", &[]);
    let (a, b) = (dir.join("a"), dir.join("b"));
    for out in [&a, &b] {
        let o = rcsc(&["doc", "plans", "--coverage", "-o", out.to_str().unwrap()]);
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    let files = site_of(&a);
    assert!(
        files.contains_key("submarine/PR.AHEAD.html"),
        "{:?}",
        files.keys()
    );
    assert_eq!(broken_links(&files), Vec::<String>::new());
    assert_eq!(tree(&a), tree(&b), "two runs differ");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn without_graphviz_the_site_has_notices_instead_of_drawings() {
    let dir = scratch("doc-nodot", &[]);
    let out = dir.join("site");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rcsc"))
        .args(["doc", "plans/submarine", "-o", out.to_str().unwrap()])
        .env("PATH", &dir) // an empty folder: no `dot`
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("Graphviz `dot` not found"),
        "{}",
        text(&o.stderr)
    );
    let files = site_of(&out);
    assert!(files["PR.AHEAD.html"].contains("class=\"notice\""));
    assert!(!files["PR.AHEAD.html"].contains("<svg"));
    assert_eq!(broken_links(&files), Vec::<String>::new());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `rcsc doc plans/figure13 -q --open` into `out`, with no program on the
/// PATH (an empty folder) and `$BROWSER` as given.
fn doc_open(out: &Path, empty: &Path, browser: Option<&Path>) -> std::process::Output {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_rcsc"));
    cmd.args([
        "doc",
        "plans/figure13",
        "-q",
        "--open",
        "-o",
        out.to_str().unwrap(),
    ])
    .env("PATH", empty)
    .env("NO_COLOR", "1");
    match browser {
        Some(b) => cmd.env("BROWSER", b),
        None => cmd.env_remove("BROWSER"),
    };
    cmd.output().unwrap()
}

#[test]
fn doc_open_without_a_browser_names_the_page_in_one_line() {
    let dir = scratch("doc-nobrowser", &[]);
    let out = dir.join("site");
    let index = out.join("index.html");
    let o = doc_open(&out, &dir, None);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("no browser") && err.contains(index.to_str().unwrap()),
        "{err}"
    );
    assert!(index.is_file());
    // A `$BROWSER` that fails is named.
    let o = doc_open(&out, &dir, Some(&dir.join("no-such-browser")));
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("`$BROWSER`") && err.contains("no-such-browser"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn traces_of_another_version_or_format_are_refused_with_their_line() {
    let dir = scratch(
        "trace-versions",
        &[
            ("v9.jsonl", "{\"format\":\"rcs-trace\",\"version\":9}\n"),
            (
                "junk.jsonl",
                "{\"format\":\"rcs-trace\",\"version\":1}\nhello\n",
            ),
        ],
    );
    let o = rcsc(&["trace", dir.join("v9.jsonl").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("line 1: trace format version 9"),
        "{}",
        text(&o.stderr)
    );
    let o = rcsc(&["trace", dir.join("junk.jsonl").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("line 2: not a trace record"),
        "{}",
        text(&o.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Rows by name with their counts, from `rcsc trace` lines `    E2   9`
/// under the plan's heading.
fn trace_counts(summary: &str, plan: &str) -> BTreeMap<String, u64> {
    let mut out = BTreeMap::new();
    let mut inside = false;
    for line in summary.lines() {
        if !line.starts_with(' ') {
            inside = line.starts_with(&format!("{plan}:"));
            continue;
        }
        let mut words = line.split_whitespace();
        if let (true, Some(row), Some(n)) = (inside, words.next(), words.next()) {
            if let Ok(n) = n.parse() {
                out.insert(row.to_string(), n);
            }
        }
    }
    out
}

#[test]
fn scenario_traces_count_what_coverage_reports() {
    let dir = scratch("test-trace", &[]);
    let t = dir.join("t.jsonl");
    let o = rcsc(&[
        "test",
        "plans/submarine",
        "--coverage",
        "--trace",
        t.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let coverage = text(&o.stdout);
    let o = rcsc(&["trace", t.to_str().unwrap(), "--plans", "plans/submarine"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let summary = text(&o.stdout);
    // The rows the trace never saw fire are the rows coverage lists.
    for plan in ["PR.AHEAD", "TB.AHEAD", "SM.TRANSIT"] {
        let counts = trace_counts(&summary, plan);
        assert!(!counts.is_empty(), "{plan} missing:\n{summary}");
        for (row, n) in counts {
            let listed = coverage.lines().any(|l| {
                l.trim_start().starts_with("not fired:")
                    && l.split_whitespace().nth(2) == Some(row.as_str())
                    && coverage_plan_of(&coverage, l) == plan
            });
            assert_eq!(
                n == 0,
                listed,
                "{plan} {row}: {n} in the trace\n{summary}\n{coverage}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The plan a `not fired:` line of `rcsc test --coverage` belongs to.
fn coverage_plan_of<'a>(coverage: &'a str, line: &str) -> &'a str {
    let mut plan = "";
    for l in coverage.lines() {
        if l.ends_with(" rows") && l.starts_with("  ") && !l.starts_with("   ") {
            plan = l.split_whitespace().next().unwrap_or("");
        }
        if l == line {
            return plan;
        }
    }
    plan
}

#[test]
fn a_submarine_run_replays_through_rcsc_trace() {
    let dir = scratch("replay", &[]);
    let t = dir.join("run.jsonl");
    let run = std::process::Command::new(env!("CARGO"))
        .args([
            "run",
            "-q",
            "-p",
            "submarine-example",
            "--",
            "--fast",
            "--every",
            "1",
            "--trace",
        ])
        .arg(&t)
        .output()
        .unwrap();
    let printed = text(&run.stdout);
    assert!(run.status.success(), "{printed}{}", text(&run.stderr));
    assert!(printed.contains("PR reports AT_GOAL"), "{printed}");
    // The rows the run printed: the `PR rows` column, `E2×3 E3`.
    let mut expected: BTreeMap<String, u64> = BTreeMap::new();
    for line in printed.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 4 || cells[0].parse::<u64>().is_err() {
            continue;
        }
        for item in cells[3].split_whitespace().filter(|i| *i != "-") {
            let (row, n) = item.split_once('×').unwrap_or((item, "1"));
            *expected.entry(row.to_string()).or_default() += n.parse::<u64>().unwrap();
        }
    }
    assert!(expected.len() > 1, "{printed}");
    let o = rcsc(&["trace", t.to_str().unwrap(), "--plans", "plans/submarine"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let summary = text(&o.stdout);
    let mut counted = trace_counts(&summary, "PR.AHEAD");
    counted.retain(|_, n| *n > 0);
    assert_eq!(counted, expected, "{summary}\n{printed}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `rcsc doc --diff`: the fixture's new door against its old one (paths;
/// a revision is read the same way as `rcsc diff` reads it). Which pages
/// exist, which links, which colours the diff graph draws.
#[test]
fn doc_diff_adds_a_changes_page_linked_from_what_changed() {
    let dir = scratch("doc-diff", &[]);
    let out = dir.join("site");
    let o = rcsc(&[
        "doc",
        "tests/data/site/new/door",
        "--diff",
        "tests/data/site/old/door",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let files = site_of(&out);
    assert_eq!(broken_links(&files), Vec::<String>::new());
    let changes = &files["diff-changes.html"];
    // The index and the changed controller and plan link to their part of
    // the page; the unchanged plan does not.
    assert!(files["index.html"].contains("<a href=\"diff-changes.html\">Changes against tests/data/site/old/door</a>: 1 plan changed."));
    assert!(files["DOOR.html"].contains("href=\"diff-changes.html#ctrl-door.DOOR\""));
    assert!(files["DOOR.OPEN.html"]
        .contains("href=\"diff-changes.html#plan-door.DOOR.OPEN\">changed in this diff"));
    assert!(!files["DOOR.CLOSE.html"].contains("changed in this diff"));
    // One changed plan, linked to its page, drawn and tabled.
    assert_eq!(changes.matches("class=\"changed-plan\"").count(), 1);
    assert!(changes.contains("<h4>Plan <a href=\"DOOR.OPEN.html\">DOOR.OPEN</a></h4>"));
    assert!(!changes.contains("DOOR.CLOSE"));
    assert!(changes.contains("<li class=\"added\">state <code>S2</code> added</li>"));
    for class in ["renumbered", "changed", "added"] {
        assert!(
            changes.contains(&format!("<tr class=\"{class}\">")),
            "{class}"
        );
    }
    assert!(changes.contains("<p class=\"moved\"><b>⇅ Moved in precedence</b></p>"));
    // The graph as `diff_dot` colours it: added green, changed orange,
    // the row moved marked.
    let svg = &changes[changes.find("<svg").unwrap()..changes.find("</svg>").unwrap()];
    for colour in ["stroke=\"darkgreen\"", "stroke=\"darkorange\""] {
        assert!(svg.contains(colour), "{colour}");
    }
    assert!(svg.contains("⇅"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn doc_diff_against_what_is_neither_a_path_nor_a_revision_fails() {
    let dir = scratch("doc-diff-bad", &[]);
    let o = rcsc(&[
        "doc",
        "tests/data/site/new/door",
        "--diff",
        "no-such-revision-or-path",
        "-o",
        dir.join("site").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("neither a file or folder nor a git revision"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A set above `LARGE_SET`: the index draws clusters (no controller of the
/// whole hierarchy), each cluster has a page with its controllers, the
/// lists have pages of at most `LIST_PAGE` rows, the search index sends buffers to their list; no page
/// loads the search index itself; every link resolves.
#[test]
fn a_large_set_is_documented_cluster_by_cluster() {
    let n = site::LIST_PAGE + 7;
    let texts = plan_set::plan_set(n);
    let set = rcs_dsl::PlanSet::from_texts(
        "large",
        texts.iter().map(|(p, t)| (p.as_str(), t.as_str())),
        None,
    );
    let checked = rcs_dsl::check(&set, &rcs_dsl::Options::default());
    let ir = checked.ir.expect("the generated set checks");
    let s = Site {
        shared: false,
        changes: None,
        sets: vec![SetDoc {
            ir: &ir,
            sources: set.sources.files().map(|(_, f)| f.text.as_str()).collect(),
            findings: &checked.diagnostics,
            runs: None,
        }],
    };
    let graphs = site::graphs(&s);
    assert!(!graphs.iter().any(|g| g.key == "hierarchy"));
    let svgs: Svgs = graphs
        .iter()
        .map(|g| (g.key.clone(), fake_svg(&g.dot)))
        .collect();
    let files: BTreeMap<String, String> = site::pages(&s, &svgs)
        .into_iter()
        .map(|f| (f.path, f.contents))
        .collect();
    assert_eq!(broken_links(&files), Vec::<String>::new());
    let index = &files["index.html"];
    assert!(
        !index.contains("id=\"ctrl-"),
        "the whole hierarchy is drawn"
    );
    let clusters: Vec<&String> = files.keys().filter(|p| p.starts_with("cluster-")).collect();
    assert!(clusters.len() >= 3, "{clusters:?}");
    // Each controller is drawn (as a member) in exactly one cluster.
    let mut drawn = 0;
    for c in &clusters {
        assert!(index.contains(&format!("href=\"{c}\"")), "{c}");
        drawn += files[*c].matches("<g id=\"ctrl-").count();
    }
    assert_eq!(drawn, n);
    // The lists are paged: 250 rows, then the 7 left.
    let rows = |page: &str| files[page].matches("<tr><td><a href=").count();
    assert_eq!(rows("list-controllers.html"), site::LIST_PAGE);
    assert_eq!(rows("list-controllers-2.html"), 7);
    assert!(files["list-controllers.html"].contains("<a href=\"list-controllers-2.html\">"));
    // A buffer link leads to the page of the list that shows it (the
    // crawler above checks the anchor is there).
    assert!(files.contains_key("list-buffers-3.html"));
    let page = files["C252.html"]
        .split("href=\"")
        .find(|l| l.contains("#b-large.d252\""))
        .unwrap();
    assert!(page.starts_with("list-buffers-"), "{page}");
    assert!(files["search.js"].contains("\"list-buffers.html#b-large.d0\""));
    assert!(files["C1.html"].contains("href=\"list-buffers.html#b-large.d1\""));
    assert!(files
        .iter()
        .all(|(p, t)| !p.ends_with(".html") || !t.contains("search.js")));
}

/// A plan set whose doc comments try Markdown and hostile HTML, with a
/// finding that has a witness.
const POLISH: &str = "\
/// Feeds parts. Ends in `Error` when the *sensor* fails; see
/// [the cell](https://example.org/cell) or [this](javascript:alert(1)).
/// <script>alert(1)</script>
controller Feeder {
    reads s: Sensor
    command FEED
    status FED
    error TIMEOUT
    plan FEED {
        E0: *0 when new_command -> S1
        E1: S1 when state_cycles > 20 -> Error(TIMEOUT)
        E2: S1 when !s.ready -> S2
        E3: S1 when s.ready -> Done { report FED }
        E4: S2 when !s.ready -> S1
        E5: S2 when s.ready -> Done
    }
}
buffer Sensor { ready: bool }
";

#[test]
fn the_site_renders_docs_as_markdown_and_says_each_thing_once() {
    let dir = scratch("polish", &[("plans/feeder.rcs", POLISH)]);
    let out = dir.join("site");
    let o = rcsc(&[
        "doc",
        dir.join("plans").to_str().unwrap(),
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let files = site_of(&out);
    // The one link out is the one the doc comment wrote.
    assert_eq!(
        broken_links(&files),
        ["Feeder.html: https://example.org/cell (leads outside the site)"]
    );
    let ctrl = &files["Feeder.html"];
    // Markdown, and nothing a browser would run.
    assert!(ctrl.contains("<code>Error</code>"), "{ctrl}");
    assert!(ctrl.contains("<em>sensor</em>"), "{ctrl}");
    assert!(ctrl.contains("<a href=\"https://example.org/cell\">the cell</a>"));
    assert!(!ctrl.contains("<script>alert"), "{ctrl}");
    assert!(!ctrl.contains("javascript:"), "{ctrl}");
    // Statuses and errors say what they are and which rows give them.
    assert!(ctrl.contains("No command has arrived yet"), "{ctrl}");
    assert!(ctrl.contains("rows reporting it: <a href=\"Feeder.FEED.html#row-E3\">FEED E3</a>"));
    assert!(ctrl.contains("rows ending with it: <a href=\"Feeder.FEED.html#row-E1\">FEED E1</a>"));
    assert!(ctrl.contains("REFUSED <small>(built in)</small>"));
    // The livelock's witness once, not also as its terminal note; names
    // in its message as code.
    let plan = &files["Feeder.FEED.html"];
    assert_eq!(plan.matches("class=\"witness\"").count(), 1, "{plan}");
    assert!(!plan.contains("for example, in state"), "{plan}");
    assert!(plan.contains("plan <code>FEED</code> can loop"), "{plan}");
    // S0 is explained where it is listed.
    assert!(plan.contains("where every command starts; not drawn as a state: the entry row <a href=\"#row-E0\">E0</a> leaves it"));
    // The index: contents and counts.
    let index = &files["index.html"];
    assert!(index.contains("<nav class=\"toc\">"), "{index}");
    assert!(
        index.contains("<span class=\"count warning\">1 warning</span>"),
        "{index}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_changes_page_says_each_kind_once_and_no_heading_stands_empty() {
    let dir = scratch("changes-words", &[]);
    let old = dir.join("old");
    copy_tree(Path::new("plans/submarine"), &old.join("submarine"));
    let out = dir.join("site");
    let o = rcsc(&[
        "doc",
        "plans/",
        "--diff",
        old.to_str().unwrap(),
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let changes = &site_of(&out)["diff-changes.html"];
    for set in ["figure13", "rcs_ex", "packml"] {
        let at = changes
            .find(&format!("<h2>System {set} (added)</h2>"))
            .unwrap_or_else(|| panic!("{set} added:\n{changes}"));
        let next = &changes[at..changes[at..].find("</section>").unwrap() + at];
        assert!(next.contains("A new plan set:"), "{next}");
    }
    // Against the decls_changed case: a kind word never doubled.
    let out2 = dir.join("site2");
    let o = rcsc(&[
        "doc",
        "tests/data/diff/decls_changed/new",
        "--diff",
        "tests/data/diff/decls_changed/old",
        "-q",
        "-o",
        out2.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let changes = &site_of(&out2)["diff-changes.html"];
    assert!(
        changes.contains("<code>command DRAIN(rate: u8)</code>"),
        "{changes}"
    );
    for doubled in [
        "command <code>command",
        "status <code>status",
        "buffer type <code>buffer",
    ] {
        assert!(!changes.contains(doubled), "{doubled}: {changes}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
