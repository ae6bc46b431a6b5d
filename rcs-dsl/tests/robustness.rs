//! Hostile input through the whole front end: random bytes, mutated valid
//! plans and pathological nesting must give diagnostics (or a clean IR),
//! never a panic, a hang or a stack overflow, and every diagnostic's spans
//! must lie inside its file.

use proptest::prelude::*;
use rcs_dsl::{check, Options, PlanSet};

const SUBMARINE: [(&str, &str); 3] = [
    (
        "maneuvering.rcs",
        include_str!("../../plans/submarine/maneuvering.rcs"),
    ),
    (
        "propulsion.rcs",
        include_str!("../../plans/submarine/propulsion.rcs"),
    ),
    (
        "turbine.rcs",
        include_str!("../../plans/submarine/turbine.rcs"),
    ),
];
const SUBMARINE_YAML: &str = include_str!("../../plans/submarine/rcs.yaml");
const FIGURE13: &str = include_str!("../../plans/figure13/figure13.rcs");

/// Check texts as one plan set; assert every span is inside its file.
fn check_texts(files: &[(&str, &str)], manifest: Option<&str>) -> rcs_dsl::Checked {
    let set = PlanSet::from_texts("fuzz", files.iter().copied(), manifest);
    let checked = check(&set, &Options::default());
    for d in &checked.diagnostics {
        assert!(
            !d.labels.is_empty() && d.labels[0].primary,
            "primary label first: {d:?}"
        );
        for l in &d.labels {
            let text = &set.sources.get(l.span.file).text;
            assert!(
                l.span.start <= l.span.end && (l.span.end as usize) <= text.len(),
                "span {:?} outside a file of {} bytes: {d:?}",
                l.span,
                text.len()
            );
            assert!(
                text.is_char_boundary(l.span.start as usize)
                    && text.is_char_boundary(l.span.end as usize)
            );
        }
        // Every renderer handles every diagnostic.
        for format in [
            rcs_dsl::render::Format::Human { color: false },
            rcs_dsl::render::Format::Short,
            rcs_dsl::render::Format::Json,
        ] {
            assert!(!rcs_dsl::render::render(d, &set.sources, format).is_empty());
        }
    }
    assert_eq!(checked.ir.is_some(), !checked.has_errors());
    checked
}

/// Tokens a mutation may insert: the language's own pieces, so that
/// mutants get deep into the pipeline instead of failing at the first byte.
const TOKENS: &[&str] = &[
    "{",
    "}",
    "(",
    ")",
    "[",
    "]",
    ";",
    ",",
    ":",
    "::",
    ".",
    "->",
    "<-",
    "=",
    "+=",
    "-=",
    "==",
    "!=",
    "<",
    ">=",
    "&&",
    "||",
    "!",
    "-",
    "*",
    "*3",
    "%",
    "/",
    "as f32",
    "as u8",
    "when",
    "otherwise",
    "same",
    "Done",
    "Error",
    "Error(X)",
    "new_command",
    "cmd.speed",
    "state_cycles",
    "plan_cycles",
    "report AT_GOAL",
    "TB <- STOP",
    "TB.done",
    "PR.status",
    "x.stale_cycles",
    "S1",
    "S0",
    "E3:",
    "*0",
    "true",
    "false",
    "0",
    "1.5",
    "18446744073709551616",
    "-128",
    "ship.speed",
    "ship",
    "Ahead",
    "ShipDirection::Ahead",
    "rpm",
    "required_rpm(1.0)",
    "speed_error()",
    "controller",
    "enum",
    "buffer",
    "plan",
    "command",
    "status",
    "error",
    "var",
    "hook",
    "reads",
    "writes",
    "subordinates",
    "level",
    "#[allow(no_done)]",
    "#[deny(unused)]",
    "/// doc\n",
    "// c\n",
    "/*",
    "*/",
    "\"",
    "\n",
    "\r\n",
    "\u{feff}",
    "é",
    "\u{0}",
];

#[derive(Clone, Debug)]
enum Mutation {
    Delete(usize, usize),
    Insert(usize, usize),
    Duplicate(usize, usize),
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 0usize..40).prop_map(|(a, n)| Mutation::Delete(a, n)),
        (any::<usize>(), 0..TOKENS.len()).prop_map(|(a, t)| Mutation::Insert(a, t)),
        (any::<usize>(), 0usize..200).prop_map(|(a, n)| Mutation::Duplicate(a, n)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

fn floor_boundary(s: &str, mut i: usize) -> usize {
    i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn apply(text: &str, muts: &[Mutation]) -> String {
    let mut s = text.to_string();
    for m in muts {
        let len = s.len().max(1);
        match *m {
            Mutation::Delete(at, n) => {
                let a = floor_boundary(&s, at % len);
                let b = floor_boundary(&s, a + n);
                s.replace_range(a..b, "");
            }
            Mutation::Insert(at, t) => {
                let a = floor_boundary(&s, at % len);
                s.insert_str(a, TOKENS[t]);
            }
            Mutation::Duplicate(at, n) => {
                let a = floor_boundary(&s, at % len);
                let b = floor_boundary(&s, a + n);
                let piece = s[a..b].to_string();
                s.insert_str(b, &piece);
            }
            Mutation::Truncate(at) => {
                let a = floor_boundary(&s, at % len);
                s.truncate(a);
            }
        }
    }
    s
}

/// Cases per property: 300, or `RCSC_FUZZ_CASES` for a long run (README,
/// "Fuzzing").
fn fuzz_cases() -> u32 {
    std::env::var("RCSC_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300)
}

const SCENARIO: &str =
    include_str!("../../plans/submarine/scenarios/pr_ahead_turbine_error.scenario.yaml");

proptest! {
    #![proptest_config(ProptestConfig { cases: fuzz_cases(), ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
        let text = String::from_utf8_lossy(&bytes).into_owned();
        check_texts(&[("random.rcs", &text)], None);
    }

    #[test]
    fn random_token_soup_never_panics(toks in proptest::collection::vec(0..TOKENS.len(), 0..300)) {
        let text: String = toks.iter().map(|t| TOKENS[*t]).collect::<Vec<_>>().join(" ");
        check_texts(&[("soup.rcs", &text)], None);
    }

    #[test]
    fn mutated_submarine_never_panics(
        which in 0usize..3,
        muts in proptest::collection::vec(mutation(), 1..6),
        yaml_muts in proptest::collection::vec(mutation(), 0..3),
    ) {
        let mut files: Vec<(&str, String)> = SUBMARINE.iter().map(|(n, t)| (*n, t.to_string())).collect();
        files[which].1 = apply(&files[which].1, &muts);
        let yaml = apply(SUBMARINE_YAML, &yaml_muts);
        let refs: Vec<(&str, &str)> = files.iter().map(|(n, t)| (*n, t.as_str())).collect();
        check_texts(&refs, Some(&yaml));
    }

    #[test]
    fn mutated_scenarios_never_panic(muts in proptest::collection::vec(mutation(), 1..8)) {
        let ir = submarine_ir();
        let text = apply(SCENARIO, &muts);
        let file = rcs_dsl::source::SourceFile::new("fuzz.scenario.yaml", text);
        if let Err(e) = rcs_dsl::scenario::parse(&ir, &file, "fuzz") {
            // A refusal says where, inside the file.
            prop_assert!(e.line <= file.line_starts().len() + 1, "{e:?}");
        }
    }

    #[test]
    fn mutated_figure13_never_panics(muts in proptest::collection::vec(mutation(), 1..8)) {
        let text = apply(FIGURE13, &muts);
        check_texts(&[("figure13.rcs", &text)], None);
    }
}

/// The submarine plans, lowered once per test thread.
fn submarine_ir() -> rcs_dsl::ir::Ir {
    let set = PlanSet::from_texts("submarine", SUBMARINE.iter().copied(), Some(SUBMARINE_YAML));
    check(&set, &Options::default())
        .ir
        .unwrap_or_else(|| panic!("the submarine plans check"))
}

#[test]
fn unmutated_reference_plans_check_clean() {
    let c = check_texts(&SUBMARINE, Some(SUBMARINE_YAML));
    assert!(c.diagnostics.is_empty(), "{:?}", c.diagnostics);
    let c = check_texts(&[("figure13.rcs", FIGURE13)], None);
    assert!(c.diagnostics.is_empty(), "{:?}", c.diagnostics);
}

fn plan_with_condition(cond: &str) -> String {
    format!("controller A {{ command GO plan GO {{ *0 when new_command && {cond} -> Done }} }}")
}

fn codes(c: &rcs_dsl::Checked) -> Vec<&'static str> {
    c.diagnostics.iter().map(|d| d.code.name()).collect()
}

#[test]
fn deep_parentheses_are_a_syntax_error_not_a_stack_overflow() {
    let cond = format!("{}true{}", "(".repeat(100_000), ")".repeat(100_000));
    let c = check_texts(&[("deep.rcs", &plan_with_condition(&cond))], None);
    assert_eq!(codes(&c), ["syntax"]);
    assert!(
        c.diagnostics[0].message.contains("nested"),
        "{}",
        c.diagnostics[0].message
    );
}

#[test]
fn unbalanced_opening_brackets_are_bounded() {
    let text = "[".repeat(1_000_000);
    let c = check_texts(&[("open.rcs", &text)], None);
    assert_eq!(codes(&c), ["syntax"]);
}

#[test]
fn long_operator_chains_are_bounded() {
    for op in ["&&", "||", "+", "*", "=="] {
        let cond = vec!["true"; 2_000].join(op);
        let c = check_texts(&[("chain.rcs", &plan_with_condition(&cond))], None);
        assert!(c.has_errors(), "{op}: {:?}", codes(&c));
        assert!(codes(&c).contains(&"syntax"), "{op}: {:?}", codes(&c));
    }
}

#[test]
fn long_prefix_and_postfix_runs_are_bounded() {
    let nots = format!("{}true", "!".repeat(100_000));
    let c = check_texts(&[("nots.rcs", &plan_with_condition(&nots))], None);
    assert_eq!(codes(&c), ["syntax"]);
    let casts = format!("1{} == 1", " as u8".repeat(50_000));
    let c = check_texts(&[("casts.rcs", &plan_with_condition(&casts))], None);
    assert_eq!(codes(&c), ["syntax"]);
    let fields = format!("x{} == 1", ".f".repeat(50_000));
    let c = check_texts(&[("fields.rcs", &plan_with_condition(&fields))], None);
    assert_eq!(codes(&c), ["syntax"]);
}

#[test]
fn a_deep_hierarchy_does_not_overflow() {
    let n = 20_000;
    let mut text = String::new();
    for i in 0..n {
        let sub = if i + 1 < n {
            format!("subordinates C{}", i + 1)
        } else {
            String::new()
        };
        text.push_str(&format!(
            "controller C{i} {{ {sub} command GO plan GO {{ *0 when new_command -> Done }} }}\n"
        ));
    }
    let c = check_texts(&[("chain.rcs", &text)], None);
    assert!(c.diagnostics.is_empty(), "{:?}", codes(&c));
    let ir = c.ir.expect("clean");
    assert_eq!(ir.schedule[0].order.len(), n);
}

#[test]
fn a_hierarchy_ring_is_a_cycle_not_a_hang() {
    let n = 5_000;
    let mut text = String::new();
    for i in 0..n {
        text.push_str(&format!(
            "controller C{i} {{ subordinates C{} command GO plan GO {{ *0 when new_command -> Done }} }}\n",
            (i + 1) % n
        ));
    }
    let c = check_texts(&[("ring.rcs", &text)], None);
    assert_eq!(codes(&c), ["hierarchy_cycle"]);
}

#[test]
fn crlf_and_bom_are_accepted() {
    let text = format!("\u{feff}{}", FIGURE13.replace('\n', "\r\n"));
    let c = check_texts(&[("figure13.rcs", &text)], None);
    assert!(c.diagnostics.is_empty(), "{:?}", codes(&c));
}

#[test]
fn oversized_files_are_refused_with_a_diagnostic() {
    let text = format!("// {}\n", "x".repeat(rcs_dsl::parser::MAX_FILE_BYTES));
    let c = check_texts(&[("huge.rcs", &text)], None);
    assert_eq!(codes(&c), ["syntax"]);
    assert!(c.diagnostics[0].message.contains("too large"));
}
