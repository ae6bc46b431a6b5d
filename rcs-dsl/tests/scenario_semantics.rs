//! The scenario semantics of docs/scenarios.md, one test per rule:
//! subordinate answers bound per cycle (and a step of N cycles runs as N
//! one-cycle steps, over random scenarios), one name per row (`E<position>`),
//! verb and variant names YAML 1.1 would read as booleans, `initial:` for
//! vars and `writes`, values reported as the language writes them, partial
//! arrays, the bound on `cycles` (memory constant in it:
//! `scenario_memory.rs`), and `hooks_called`.

use proptest::prelude::*;
use rcs_dsl::ir::Ir;

/// `A` drives subordinate `B` round a loop: every DONE of B is answered
/// with a new command, an ERROR ends the plan, a silent B is noticed.
const PLANS: &str = r#"
enum Answer { YES, NO, ON, OFF, Y, N }
buffer Out { v: i32, a: [f64; 20] }

controller B {
    command GO
    plan GO { *0 when new_command -> Done }
}

controller A {
    subordinates B
    writes out: Out
    command GO
    command ON
    command OFF
    command BIG
    command TRUE(flag: bool)
    var n: i32 = 0
    var d: Answer = YES
    var a: [f64; 20]
    hook probe(k: i32) -> bool
    hook answer() -> Answer
    plan GO {
        *0 when new_command -> S1 { B <- GO }
        S1 when B.done -> S2 { n += 1; B <- GO }
        S2 when B.done -> S1 { B <- GO }
        S1 when B.error -> Done
        S2 when B.stale_cycles > 2 -> S1 { B <- GO }
    }
    plan ON {
        *0 when new_command && n == 5 -> S1 { out.v = n }
        *1 when new_command -> S1
        S1 when probe(n) -> S1
        S1 when answer() == OFF -> Done
    }
    plan OFF { *0 when new_command -> Done }
    plan TRUE { *0 when new_command && cmd.flag -> Done }
    plan BIG { *0 when new_command -> Done { n = 2147483647; d = ON; a[3] = 1.5 } }
}
"#;

mod scenario_run;
use rcs_dsl::scenario;
use scenario_run::{failure, ir_of, parse, passes, run};

fn ir() -> Ir {
    ir_of(PLANS)
}

#[test]
fn a_multi_cycle_step_sees_answers_to_commands_sent_during_it() {
    let ir = ir();
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: GO\n    subordinates: { B: DONE }\n    cycles: 2\n    expect: { fired: E1, state: S2, vars: { n: 1 } }\n",
    );
    // Three cycles: sent on the first, answered on the second, and the
    // command of the second answered on the third.
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: GO\n    subordinates: { B: DONE }\n    cycles: 3\n    expect: { fired: E2, state: S1, vars: { n: 1 } }\n",
    );
}

#[test]
fn a_kept_answer_does_not_answer_the_next_command() {
    let ir = ir();
    // Step 1's DONE answered serial 0; B keeps showing that at step 2, so
    // the GO sent in step 1 is not answered until step 3 says so.
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: GO\n    subordinates: { B: DONE }\n    expect: { fired: E0 }\n  - expect: { fired: none, state: S1 }\n  - subordinates: { B: DONE }\n    expect: { fired: E1, state: S2 }\n",
    );
    // An answer given in `initial:` stands for every step.
    passes(
        &ir,
        "controller: A\ninitial: { subordinates: { B: DONE } }\nsteps:\n  - command: GO\n    expect: { fired: E0 }\n  - expect: { fired: E1 }\n  - expect: { fired: E2 }\n",
    );
}

/// One step: an optional command, an optional answer of B, its cycles.
#[derive(Clone, Debug)]
struct RandomStep {
    command: Option<&'static str>,
    answer: Option<&'static str>,
    cycles: u64,
}

fn step_text(command: Option<&str>, answer: Option<&str>, cycles: u64) -> String {
    let mut t = String::from("  - cycles: ");
    t.push_str(&cycles.to_string());
    t.push('\n');
    if let Some(c) = command {
        t.push_str(&format!("    command: {c}\n"));
    }
    if let Some(a) = answer {
        t.push_str(&format!("    subordinates: {{ B: {a} }}\n"));
    }
    t
}

fn random_step() -> impl Strategy<Value = RandomStep> {
    let command = prop::option::weighted(0.2, prop::sample::select(vec!["GO", "OFF"]));
    let answer = prop::option::weighted(
        0.6,
        prop::sample::select(vec![
            "DONE",
            "EXECUTING",
            "ERROR",
            "NOT_READY",
            "{ status: DONE, echo: previous }",
            "{ status: DONE, silent: true }",
            "{ status: DONE, echo: 1 }",
        ]),
    );
    (command, answer, 1u64..6).prop_map(|(command, answer, cycles)| RandomStep {
        command,
        answer,
        cycles,
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("RCS_SCENARIO_CASES").ok().and_then(|n| n.parse().ok()).unwrap_or(256)
    ))]

    /// One step of N cycles and N one-cycle steps with the same inputs
    /// (the answer repeated, the command once) give the same run.
    #[test]
    fn n_cycles_in_one_step_run_as_n_one_cycle_steps(
        steps in prop::collection::vec(random_step(), 1..8)
    ) {
        let ir = ir();
        let mut whole = String::from("controller: A\nsteps:\n  - command: GO\n");
        let mut split = whole.clone();
        for s in &steps {
            whole.push_str(&step_text(s.command, s.answer, s.cycles));
            for i in 0..s.cycles {
                split.push_str(&step_text(s.command.filter(|_| i == 0), s.answer, 1));
            }
        }
        let (a, b) = (run(&ir, &whole), run(&ir, &split));
        prop_assert!(a.failure.is_none() && b.failure.is_none());
        prop_assert_eq!(&a.fired, &b.fired, "\n{}\n{}", whole, split);
        prop_assert_eq!(&a.rows, &b.rows);
    }
}

#[test]
fn every_row_answers_to_e_and_its_position() {
    let ir = ir();
    // Unlabelled rows, by position; the older aliases still work.
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: GO\n    expect: { fired: E0 }\n  - subordinates: { B: DONE }\n    expect: { fired: E1 }\n",
    );
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: GO\n    expect: { fired: \"*0\" }\n",
    );
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: GO\n    expect: { fired: \"#0\" }\n",
    );
    // A failure names rows the same way.
    let f = failure(
        &ir,
        "controller: A\nsteps:\n  - command: GO\n    expect: { fired: E1 }\n",
    );
    assert_eq!(f, "fired: expected E1, got E0");
    // An unknown row gets the plan's rows as a hint.
    let (line, message) = parse(
        &ir,
        "controller: A\nsteps:\n  - command: GO\n    expect: { fired: E9 }\n",
    )
    .err()
    .expect("refused");
    assert_eq!(line, 4);
    assert!(
        message.contains("no row of `A` is called `E9`"),
        "{message}"
    );
    assert!(
        message.contains("GO: E0–E4") && message.contains("OFF: E0"),
        "{message}"
    );
}

#[test]
fn names_yaml_1_1_reads_as_booleans_are_names() {
    let ir = ir();
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: ON\n    expect: { fired: E1, state: S1 }\n",
    );
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: OFF\n    expect: { status: DONE }\n",
    );
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: ON\n  - hooks: { answer: OFF }\n    expect: { fired: E3 }\n",
    );
    passes(&ir, "controller: A\ninitial: { vars: { d: NO } }\nsteps:\n  - command: OFF\n    expect: { vars: { d: NO } }\n");
    passes(&ir, "controller: A\ninitial: { vars: { d: YES } }\nsteps:\n  - command: OFF\n    expect: { vars: { d: YES } }\n");
    for v in ["Y", "N", "OFF"] {
        let text = format!("controller: A\ninitial: {{ vars: {{ d: {v} }} }}\nsteps:\n  - command: OFF\n    expect: {{ vars: {{ d: {v} }} }}\n");
        passes(&ir, &text);
    }
    // A verb spelled like a boolean, and a boolean in any of YAML 1.2's spellings.
    for flag in ["true", "True", "TRUE"] {
        let text = format!("controller: A\nsteps:\n  - command: {{ TRUE: {{ flag: {flag} }} }}\n    expect: {{ status: DONE }}\n");
        passes(&ir, &text);
    }
    passes(&ir, "controller: A\nsteps:\n  - command: { TRUE: { flag: FALSE } }\n    expect: { status: EXECUTING, fired: none }\n");
    let (_, message) = parse(
        &ir,
        "controller: A\nsteps:\n  - command: { TRUE: { flag: yes } }\n",
    )
    .err()
    .expect("refused");
    assert!(message.contains("`flag`: expected bool"), "{message}");
}

#[test]
fn initial_sets_vars_and_the_controllers_own_writes() {
    let ir = ir();
    passes(
        &ir,
        "controller: A\ninitial: { vars: { n: 5 } }\nsteps:\n  - command: ON\n    expect: { fired: E0, writes: { out: { v: 5 } } }\n",
    );
    passes(
        &ir,
        "controller: A\ninitial: { writes: { out: { v: 7, a: { 2: 0.5 } } } }\nsteps:\n  - command: OFF\n    expect: { writes: { out: { v: 7, a: [0.0, 0.0, 0.5] } } }\n",
    );
    let (line, message) = parse(
        &ir,
        "controller: A\ninitial:\n  vars: { m: 1 }\nsteps: []\n",
    )
    .err()
    .expect("refused");
    assert_eq!((line, message.as_str()), (3, "`A` has no var `m`"));
}

#[test]
fn failures_print_values_as_the_language_writes_them() {
    let ir = ir();
    let f = failure(
        &ir,
        "controller: A\nsteps:\n  - command: BIG\n    expect: { vars: { n: 0, d: YES } }\n",
    );
    assert_eq!(
        f,
        "vars.n: expected 0, got 2147483647; vars.d: expected YES, got ON"
    );
    let f = failure(
        &ir,
        "controller: A\nsteps:\n  - command: BIG\n    expect: { vars: { a: { 4: 1.5 } } }\n",
    );
    assert_eq!(
        f,
        "vars.a: expected [0.0, 0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 0.0, …], got [0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 0.0, 0.0, …] (first difference at [3]: expected 0.0, got 1.5)"
    );
    let f = failure(
        &ir,
        "controller: A\nsteps:\n  - command: GO\n    expect: { sent: {} }\n",
    );
    assert_eq!(f, "sent: expected {}, got B <- GO");
    assert!(!f.contains("Int(") && !f.contains("Enum("));
}

#[test]
fn arrays_may_be_given_in_part() {
    let ir = ir();
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: BIG\n    expect: { vars: { a: { 3: 1.5 } } }\n",
    );
    passes(&ir, "controller: A\nsteps:\n  - command: BIG\n    expect: { vars: { a: [0.0, 0.0, 0.0, 1.5] } }\n");
    let (line, message) = parse(&ir, "controller: A\nsteps:\n  - command: BIG\n    expect:\n      vars: { a: [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0] }\n").err().expect("refused");
    assert_eq!(line, 5);
    assert!(
        message.contains("21 elements given, but the array holds 20"),
        "{message}"
    );
    let (_, message) = parse(
        &ir,
        "controller: A\nsteps:\n  - command: BIG\n    expect: { vars: { a: { 20: 1.0 } } }\n",
    )
    .err()
    .expect("refused");
    assert!(
        message.contains("`20` is not an index of this array (0 to 19)"),
        "{message}"
    );
}

#[test]
fn cycles_run_from_one_to_the_bound_with_a_line_for_anything_else() {
    let ir = ir();
    for bad in ["0", "10000001", "4294967295", "-1", "1.5", "many"] {
        let text = format!("controller: A\nsteps:\n  - command: GO\n  - cycles: {bad}\n");
        let (line, message) = parse(&ir, &text)
            .err()
            .unwrap_or_else(|| panic!("{bad} accepted"));
        assert_eq!(line, 4, "{bad}");
        assert!(message.contains("from 1 to 10000000"), "{bad}: {message}");
    }
    assert_eq!(scenario::MAX_CYCLES, 10_000_000);
}

#[test]
fn hooks_called_counts_a_steps_calls() {
    let ir = ir();
    passes(
        &ir,
        "controller: A\nsteps:\n  - command: ON\n    expect: { hooks_called: { probe: 0 } }\n  - cycles: 3\n    expect: { hooks_called: { probe: 3, answer: 3 } }\n",
    );
    let f = failure(
        &ir,
        "controller: A\nsteps:\n  - command: ON\n  - expect: { hooks_called: { probe: 2 } }\n",
    );
    assert_eq!(
        f,
        "hooks_called.probe: expected 2 call(s) in the step, got 1"
    );
}

#[test]
fn hooks_called_checks_each_calls_arguments() {
    let ir = ir();
    passes(
        &ir,
        "controller: A\ninitial: { vars: { n: 3 } }\nsteps:\n  - command: ON\n  - cycles: 2\n    expect: { hooks_called: { probe: [{ k: 3 }, { k: 3 }], answer: [{}, {}] } }\n",
    );
    let f = failure(
        &ir,
        "controller: A\nsteps:\n  - command: ON\n  - cycles: 3\n    expect: { hooks_called: { probe: [{ k: 1 }] } }\n",
    );
    assert_eq!(
        f,
        "hooks_called.probe: expected [(k: 1)], got [(k: 0), (k: 0), … (3 calls)]"
    );
    let (line, message) = parse(
        &ir,
        "controller: A\nsteps:\n  - expect: { hooks_called: { probe: [{ j: 1 }] } }\n",
    )
    .err()
    .expect("refused");
    assert_eq!(
        (line, message.as_str()),
        (3, "hook `probe` has no parameter `j`")
    );
}
