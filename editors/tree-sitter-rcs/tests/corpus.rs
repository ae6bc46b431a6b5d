//! The tree-sitter grammar against the compiler: every `.rcs` file of the
//! repository, and every ```` ```rcs ```` block of its Markdown, that
//! rcs-dsl's parser accepts must parse here with no ERROR or MISSING node
//! (issue 32's acceptance). Which files count is decided by the compiler
//! itself (`rcs_dsl::parser::parse_file`), not by a list: the golden error
//! cases that are syntax errors on purpose drop out, the others stay in.
//!
//! Also here: the shape of the tree that the highlight queries and editors
//! rely on (a row's parts are fields, operators nest by precedence), the
//! highlight queries compiled and run against the grammar (and Helix's copy
//! kept in step), and the CLI's `test/corpus` cases, run without the CLI.

use std::path::{Path, PathBuf};
use tree_sitter::{Language, Node, Parser, Query, QueryCursor, StreamingIterator as _, Tree};

fn language() -> Language {
    tree_sitter_rcs::LANGUAGE.into()
}

fn parse(text: &str) -> Tree {
    let mut parser = Parser::new();
    parser
        .set_language(&language())
        .expect("the generated parser's ABI is one this tree-sitter reads");
    parser
        .parse(text, None)
        .expect("no timeout or cancellation is set")
}

/// Every ERROR or MISSING node of `tree`, as `line:column: what` (1-based).
fn syntax_problems(tree: &Tree) -> Vec<String> {
    let mut problems = Vec::new();
    let mut stack = vec![tree.root_node()];
    while let Some(node) = stack.pop() {
        if node.is_error() || node.is_missing() {
            let at = node.start_position();
            let what = if node.is_missing() {
                format!("missing `{}`", node.kind())
            } else {
                "ERROR node".to_string()
            };
            problems.push(format!("{}:{}: {what}", at.row + 1, at.column + 1));
        }
        // Only subtrees that hold an error are worth walking into.
        if node.has_error() {
            let mut cursor = node.walk();
            stack.extend(node.children(&mut cursor));
        }
    }
    problems.sort();
    problems
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Files under `dir` whose name ends in one of `extensions`, sorted, skipping
/// build output, dependencies and hidden folders.
fn files_under(dir: &Path, extensions: &[&str], out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            if !(name.starts_with('.') || name == "target" || name == "node_modules") {
                files_under(&path, extensions, out);
            }
        } else if extensions.iter().any(|e| name.ends_with(e)) {
            out.push(path);
        }
    }
}

/// A text to hold the grammar to: where it came from and what it says.
struct Sample {
    origin: String,
    text: String,
}

/// Every `.rcs` file of the repository, and every ```` ```rcs ```` block of
/// its Markdown files (doc examples are plans people copy).
fn repository_samples() -> Vec<Sample> {
    let root = repo_root();
    let mut paths = Vec::new();
    files_under(&root, &[".rcs", ".md"], &mut paths);
    paths.sort();
    let mut samples = Vec::new();
    for path in paths {
        let origin = path
            .strip_prefix(&root)
            .unwrap_or(&path)
            .display()
            .to_string();
        let Ok(bytes) = std::fs::read(&path) else {
            continue;
        };
        // Not UTF-8: the compiler refuses it (tests/data/err/0106_…).
        let Ok(text) = String::from_utf8(bytes) else {
            continue;
        };
        if origin.ends_with(".md") {
            samples.extend(markdown_rcs_blocks(&origin, &text));
        } else {
            samples.push(Sample { origin, text });
        }
    }
    samples
}

/// The ```` ```rcs ```` blocks of a Markdown text, but not `rcs fragment`
/// ones (parts of a file, never whole ones).
fn markdown_rcs_blocks(origin: &str, text: &str) -> Vec<Sample> {
    let mut blocks = Vec::new();
    let mut open: Option<(usize, String)> = None;
    for (n, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        match &mut open {
            None => {
                if let Some(info) = trimmed.strip_prefix("```") {
                    let mut words = info.split_whitespace();
                    if words.next() == Some("rcs") && !info.contains("fragment") {
                        open = Some((n + 1, String::new()));
                    }
                }
            }
            Some((start, body)) => {
                if trimmed.starts_with("```") {
                    blocks.push(Sample {
                        origin: format!("{origin}:{start}"),
                        text: std::mem::take(body),
                    });
                    open = None;
                } else {
                    body.push_str(line);
                    body.push('\n');
                }
            }
        }
    }
    blocks
}

fn compiler_parses(text: &str) -> bool {
    rcs_dsl::parser::parse_file(rcs_dsl::source::FileId(0), text).is_ok()
}

/// The acceptance test: no file the compiler parses has an ERROR or MISSING
/// node here. Lists every problem of every file, not only the first.
#[test]
fn every_repository_plan_the_compiler_parses_parses_without_error() {
    let samples = repository_samples();
    let mut checked_files = 0;
    let mut checked_blocks = 0;
    let mut excluded = Vec::new();
    let mut failures = Vec::new();
    for sample in &samples {
        if !compiler_parses(&sample.text) {
            excluded.push(sample.origin.as_str());
            continue;
        }
        if sample.origin.ends_with(".rcs") {
            checked_files += 1;
        } else {
            checked_blocks += 1;
        }
        for problem in syntax_problems(&parse(&sample.text)) {
            failures.push(format!("{}:{problem}", sample.origin));
        }
    }
    eprintln!(
        "parsed {checked_files} .rcs files and {checked_blocks} Markdown rcs blocks; \
         excluded because rcs-dsl's parser rejects them: {}",
        excluded.join(", ")
    );
    assert!(
        failures.is_empty(),
        "{} syntax problems in plans the compiler parses:\n{}",
        failures.len(),
        failures.join("\n")
    );
    // Guard against a walk that found nothing (a moved root, a renamed
    // folder): the repository has hundreds of plans, the shipped ones among them.
    assert!(
        checked_files >= 300,
        "only {checked_files} .rcs files found"
    );
    for shipped in [
        "plans/submarine/propulsion.rcs",
        "plans/packml/unit.rcs",
        "plans/fieldbus_drive/drive.rcs",
    ] {
        assert!(
            samples.iter().any(|s| s.origin == shipped) && !excluded.contains(&shipped),
            "{shipped} was not checked"
        );
    }
    // The golden error cases are the files left out, and one file that a
    // plan set's manifest leaves out because it is not `.rcs` at all.
    // (Markdown blocks may be left out: some show a syntax error on
    // purpose, `expect=syntax`, and some show one entry, not a whole file.)
    let not_a_plan = "tests/data/ok/0016_plan_set_split/ignored.rcs";
    let unexpected: Vec<&&str> = excluded
        .iter()
        .filter(|origin| origin.ends_with(".rcs"))
        .filter(|origin| !origin.starts_with("tests/data/err/") && **origin != not_a_plan)
        .collect();
    assert!(
        unexpected.is_empty(),
        "rcs-dsl refuses these, which are no error cases: {unexpected:?}"
    );
}

/// The check above can fail: a broken plan yields a problem with its place.
#[test]
fn a_broken_plan_is_reported_with_its_place() {
    let broken =
        "controller X {\n    command GO\n    plan GO {\n        E0: *0 when -> S1\n    }\n}\n";
    assert!(!compiler_parses(broken));
    let problems = syntax_problems(&parse(broken));
    assert!(!problems.is_empty(), "no problem found in {broken:?}");
    assert!(problems.iter().all(|p| p.starts_with("4:")), "{problems:?}");

    let unclosed = "enum Dir { Ahead, Stopped\n";
    let problems = syntax_problems(&parse(unclosed));
    assert!(
        problems
            .iter()
            .any(|p| p.contains("missing") || p.contains("ERROR")),
        "{problems:?}"
    );
}

/// The first node of `kind` in a depth-first walk.
fn find<'t>(node: Node<'t>, kind: &str) -> Option<Node<'t>> {
    if node.kind() == kind {
        return Some(node);
    }
    let mut cursor = node.walk();
    let children: Vec<Node<'t>> = node.children(&mut cursor).collect();
    children.into_iter().find_map(|child| find(child, kind))
}

fn text_of<'s>(node: Node<'_>, source: &'s str) -> &'s str {
    &source[node.byte_range()]
}

const SHAPES: &str = r#"
/// A unit.
#[allow(no_done)]
controller UNIT "Unit" {
    subordinates INFEED
    command START accept when state == Idle
    status state: PackState = Idle
    pre { n = 0x0F | 0b1010_0000; }
    plan START {
        E0: *0 when new_command && -x as u8 > 2 || a & 1 == b -> S1 { INFEED <- START(speed: 1.5s) }
        use on_fault
        E2: A | B when INFEED.done -> Error(FAULTED) { report ERROR(FAULTED) }
        *3 except A | B otherwise -> same
    }
}
"#;

#[test]
fn a_row_has_its_parts_as_fields() {
    let tree = parse(SHAPES);
    assert!(
        !tree.root_node().has_error(),
        "{}",
        tree.root_node().to_sexp()
    );
    let row = find(tree.root_node(), "row").unwrap();
    let field = |name: &str| {
        row.child_by_field_name(name)
            .unwrap_or_else(|| panic!("no `{name}` field in {}", row.to_sexp()))
    };
    assert_eq!(field("label").kind(), "row_label");
    assert_eq!(text_of(field("label"), SHAPES), "E0");
    assert_eq!(field("from").kind(), "dont_care");
    assert_eq!(field("condition").kind(), "binary_expression");
    assert_eq!(field("target").kind(), "target");
    assert_eq!(text_of(field("target"), SHAPES), "S1");
    assert_eq!(field("jobs").kind(), "job_list");

    let send = find(row, "send_job").unwrap();
    assert_eq!(
        text_of(send.child_by_field_name("verb").unwrap(), SHAPES),
        "START"
    );
    let plan = find(tree.root_node(), "plan_body").unwrap();
    let mut cursor = plan.walk();
    let kinds: Vec<&str> = plan.named_children(&mut cursor).map(|n| n.kind()).collect();
    assert_eq!(kinds, ["row", "use_rows", "row", "row"]);
}

#[test]
fn operators_nest_by_the_compilers_precedence() {
    let tree = parse(SHAPES);
    let row = find(tree.root_node(), "row").unwrap();
    let condition = row.child_by_field_name("condition").unwrap();
    // `new_command && -x as u8 > 2 || a & 1 == b`: `||` is loosest.
    let operator =
        |n: Node| text_of(n.child_by_field_name("operator").unwrap(), SHAPES).to_string();
    assert_eq!(operator(condition), "||");
    let left = condition.child_by_field_name("left").unwrap();
    assert_eq!(operator(left), "&&");
    // `-x as u8 > 2`: the comparison holds `-(x as u8)`.
    let comparison = left.child_by_field_name("right").unwrap();
    assert_eq!(operator(comparison), ">");
    let unary = comparison.child_by_field_name("left").unwrap();
    assert_eq!(unary.kind(), "unary_expression");
    assert_eq!(
        unary.child_by_field_name("operand").unwrap().kind(),
        "cast_expression"
    );
    // `a & 1 == b` is `(a & 1) == b` with Rust's precedence (the compiler
    // refuses it unparenthesised; the editor grammar reads it as Rust does).
    let right = condition.child_by_field_name("right").unwrap();
    assert_eq!(operator(right), "==");
    assert_eq!(operator(right.child_by_field_name("left").unwrap()), "&");
}

#[test]
fn every_section_8_construct_has_its_node() {
    let text = r#"
const LIMIT: duration = 50ms
controller type Module(station: u8) {
    reads io: ModuleIo
    command START
    hook io_cmd(word: u16)
    jobs abort_all(why: error) { cause = why; INFEED <- ABORT }
    rows on_fault { * except Aborting when io.stale_time > 100ms -> Aborting { abort_all(FAULTED) } }
    plan START { E0: *0 when new_command -> Done { io_cmd(0x000F | ((station as u16) << 8)) } }
}
controller INFEED = Module(station: 1) { io: infeed_io }
"#;
    let tree = parse(text);
    assert!(
        !tree.root_node().has_error(),
        "{}",
        tree.root_node().to_sexp()
    );
    for kind in [
        "controller_type_definition",
        "controller_instance",
        "binding",
        "jobs_definition",
        "rows_definition",
        "dont_care",
        "state_set",
        "cast_expression",
        "call_expression",
    ] {
        assert!(find(tree.root_node(), kind).is_some(), "no {kind} node");
    }
    assert!(compiler_parses(text), "the sample itself must be valid rcs");
}

/// The highlight queries compile against this grammar (every node, field
/// and token they name exists), and capture what an editor shows.
#[test]
fn highlight_queries_compile_and_capture_keywords_comments_and_labels() {
    let query = Query::new(&language(), tree_sitter_rcs::HIGHLIGHTS_QUERY)
        .unwrap_or_else(|e| panic!("queries/highlights.scm: {e}"));
    let tree = parse(SHAPES);
    let mut cursor = QueryCursor::new();
    let mut captures = cursor.captures(&query, tree.root_node(), SHAPES.as_bytes());
    let mut seen: Vec<(String, String)> = Vec::new();
    while let Some((m, index)) = captures.next() {
        let capture = m.captures[*index];
        seen.push((
            text_of(capture.node, SHAPES).to_string(),
            query.capture_names()[capture.index as usize].to_string(),
        ));
    }
    for (text, capture) in [
        ("controller", "keyword"),
        ("plan", "keyword"),
        ("when", "keyword.conditional"),
        ("/// A unit.", "comment.documentation"),
        ("E0", "label"),
        ("*0", "label"),
        ("S1", "constant"),
        ("1.5s", "number"),
        ("UNIT", "type"),
        ("new_command", "variable.builtin"),
        ("done", "property"),
        ("allow", "attribute"),
    ] {
        assert!(
            seen.iter().any(|(t, c)| t == text && c == capture),
            "`{text}` is not captured as @{capture}; captures: {seen:?}"
        );
    }
    // Disjoint patterns: no node gets two different captures.
    let mut by_node = std::collections::BTreeMap::new();
    let mut cursor = QueryCursor::new();
    let mut captures = cursor.captures(&query, tree.root_node(), SHAPES.as_bytes());
    while let Some((m, index)) = captures.next() {
        let capture = m.captures[*index];
        let name = query.capture_names()[capture.index as usize];
        let previous = by_node.insert(capture.node.id(), name);
        assert!(
            previous.is_none() || previous == Some(name),
            "`{}` captured as @{} and @{name}",
            text_of(capture.node, SHAPES),
            previous.unwrap()
        );
    }
}

/// Helix names its captures its own way (`@constant.numeric`, not
/// `@number`); editors/helix holds the same queries under Helix's names.
/// The table is the one editors/README.md gives as a `sed` command.
const HELIX_NAMES: [(&str, &str); 6] = [
    ("@comment.documentation", "@comment.line.documentation"),
    ("@keyword.conditional", "@keyword.control.conditional"),
    ("@number", "@constant.numeric"),
    ("@boolean", "@constant.builtin.boolean"),
    ("@property", "@variable.other.member"),
    ("@function.call", "@function"),
];

#[test]
fn helix_queries_are_these_queries_under_helix_names() {
    let path = repo_root().join("editors/helix/queries/rcs/highlights.scm");
    let helix = std::fs::read_to_string(&path).expect("editors/helix/queries/rcs/highlights.scm");
    let body: String = helix
        .lines()
        .skip_while(|line| line.starts_with("; Generated") || line.starts_with("; "))
        .skip(1)
        .map(|line| format!("{line}\n"))
        .collect();
    let mut want = tree_sitter_rcs::HIGHLIGHTS_QUERY.to_string();
    for (from, to) in HELIX_NAMES {
        want = want.replace(from, to);
    }
    assert!(
        body == want,
        "{} is out of step with queries/highlights.scm: regenerate it with the \
         sed command of editors/README.md",
        path.display()
    );
    Query::new(&language(), &helix).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
}

/// `test/corpus/*.txt`, the cases `tree-sitter test` runs, checked here too
/// so that CI holds them without the CLI: each case's input must give the
/// tree written under it (field names aside, as the CLI compares).
#[test]
fn the_cli_corpus_cases_give_their_trees() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("test/corpus");
    let mut files = Vec::new();
    files_under(&dir, &[".txt"], &mut files);
    files.sort();
    assert!(!files.is_empty(), "no corpus files in {}", dir.display());
    let mut cases = 0;
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        for (title, input, expected) in corpus_cases(&text) {
            cases += 1;
            let got = without_field_names(&parse(&input).root_node().to_sexp());
            assert_eq!(got, squeeze(&expected), "{}: {title}", file.display());
        }
    }
    assert!(cases >= 3, "only {cases} corpus cases");
}

/// The cases of a corpus file: `===` title `===`, input, `---`, tree.
fn corpus_cases(text: &str) -> Vec<(String, String, String)> {
    let is_rule = |line: &str, c: char| line.len() >= 3 && line.chars().all(|x| x == c);
    let lines: Vec<&str> = text.lines().collect();
    let mut cases = Vec::new();
    let mut i = 0;
    while i + 2 < lines.len() {
        if !(is_rule(lines[i], '=') && is_rule(lines[i + 2], '=')) {
            i += 1;
            continue;
        }
        let title = lines[i + 1].to_string();
        let mut j = i + 3;
        let mut input = String::new();
        while j < lines.len() && !is_rule(lines[j], '-') {
            input.push_str(lines[j]);
            input.push('\n');
            j += 1;
        }
        let mut expected = String::new();
        j += 1;
        while j < lines.len() && !(is_rule(lines[j], '=') && j + 2 < lines.len()) {
            expected.push_str(lines[j]);
            expected.push('\n');
            j += 1;
        }
        cases.push((title, input, expected));
        i = j;
    }
    cases
}

/// An S-expression on one line, single-spaced, no space inside parentheses.
fn squeeze(sexp: &str) -> String {
    sexp.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .replace("( ", "(")
        .replace(" )", ")")
}

/// `to_sexp()` without its `field: ` prefixes, squeezed.
fn without_field_names(sexp: &str) -> String {
    let words: Vec<&str> = sexp
        .split_whitespace()
        // A field name is a word ending in `:` (node kinds start with `(`).
        .filter(|word| !word.ends_with(':') || word.starts_with('('))
        .collect();
    squeeze(&words.join(" "))
}
