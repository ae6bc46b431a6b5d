//! Renumbering, case by case: inserted rows, shared rows, `*N except`,
//! plans of several verbs, controller types, scenarios of both kinds, and
//! hostile input.

use super::*;

fn set_of(text: &str) -> PlanSet {
    PlanSet::from_texts("t", [("a.rcs", text)], None)
}

/// `renumber` of one file that must succeed (its errors shown if not).
fn renumbered(text: &str, scenarios: &[(String, String)]) -> Renumbered {
    match renumber(&set_of(text), scenarios) {
        Ok(out) => out,
        Err(RenumberError::Diagnostics(d)) => {
            panic!("{:?}", d.iter().map(|d| &d.message).collect::<Vec<_>>())
        }
        Err(e) => panic!("{e}"),
    }
}

/// The new text of `a.rcs` (its old text when unchanged).
fn rcs_after(text: &str, out: &Renumbered) -> String {
    out.rcs_files
        .iter()
        .find(|f| f.path == "a.rcs")
        .map_or_else(|| text.to_string(), |f| f.text.clone())
}

fn scenario_after(text: &str, out: &Renumbered) -> String {
    out.scenarios
        .first()
        .map_or_else(|| text.to_string(), |f| f.text.clone())
}

/// A plan whose third row was inserted with a copy of the second's label.
const INSERTED: &str = "controller A {\n    command GO\n    plan GO {\n        \
    E0: *0 when new_command -> S1\n        \
    E1: S1 when state_cycles > 5 -> S2\n        \
    E1: S1   when state_cycles > 3 -> S2 // the inserted row\n        \
    E2: S2 when state_cycles > 1 -> Done\n    }\n}\n";

#[test]
fn an_inserted_row_shifts_the_labels_after_it_and_only_the_digits_change() {
    let out = renumber(&set_of(INSERTED), &[]).unwrap();
    assert_eq!(
        rcs_after(INSERTED, &out),
        INSERTED
            .replace("E1: S1   when", "E2: S1   when")
            .replace("E2: S2", "E3: S2")
    );
    let moved: Vec<(&str, &str, usize)> = out
        .relabelled
        .iter()
        .map(|r| (r.old.as_str(), r.new.as_str(), r.line))
        .collect();
    assert_eq!(moved, [("E1", "E2", 6), ("E2", "E3", 7)]);
    assert_eq!(out.relabelled[0].controller, "A");
    assert_eq!(out.relabelled[0].plan, "GO");
}

#[test]
fn the_scenario_follows_its_rows_and_a_copied_label_is_reported() {
    let scenario =
        "controller: A\nsteps:\n  - command: GO\n    expect: { fired: E0 }   # entry\n  \
        - expect:\n      fired: E1\n  - cycles: 9\n    expect: { fired: \"E2\", state: S2 }\n";
    let out = renumber(
        &set_of(INSERTED),
        &[("s.scenario.yaml".into(), scenario.into())],
    )
    .unwrap();
    assert_eq!(
        scenario_after(scenario, &out),
        scenario.replace("\"E2\"", "\"E3\"")
    );
    assert_eq!(out.renamed.len(), 1);
    assert_eq!(
        (out.renamed[0].line, out.renamed[0].new.as_str()),
        (8, "E3")
    );
    let [undecided] = out.undecided.as_slice() else {
        panic!("{:?}", out.undecided)
    };
    assert_eq!(
        (undecided.path.as_str(), undecided.line),
        ("s.scenario.yaml", 6)
    );
    assert!(
        undecided.message.contains("E1 and E2"),
        "{}",
        undecided.message
    );
}

#[test]
fn renumbering_twice_changes_nothing_the_second_time() {
    let scenario =
        "controller: A\nsteps:\n  - command: GO\n    cycles: 9\n    expect: { fired: E2 }\n";
    let once = renumber(&set_of(INSERTED), &[("s.yaml".into(), scenario.into())]).unwrap();
    let text = rcs_after(INSERTED, &once);
    let scenario = scenario_after(scenario, &once);
    let twice = renumber(&set_of(&text), &[("s.yaml".into(), scenario)]).unwrap();
    assert!(twice.rcs_files.is_empty() && twice.scenarios.is_empty());
    assert!(twice.relabelled.is_empty() && twice.renamed.is_empty());
    assert!(twice.undecided.is_empty(), "{:?}", twice.undecided);
}

#[test]
fn rows_placed_by_use_take_positions_before_the_labels_after_them() {
    let text = "controller A {\n    command GO\n    rows guard {\n        \
        S1 when state_cycles > 9 -> Error\n        * except S1 when state_cycles > 8 -> Error\n    }\n    \
        plan GO {\n        E0: *0 when new_command -> S1\n        use guard\n        \
        E1: S1 when state_cycles > 1 -> Done\n    }\n}\n";
    let out = renumber(&set_of(text), &[]).unwrap();
    assert_eq!(rcs_after(text, &out), text.replace("E1: S1", "E3: S1"));
}

#[test]
fn numbered_dont_cares_with_and_without_except_get_their_positions() {
    let text = "controller A{command GO plan GO{\n*0 when new_command->S1\n*7 except S1 when state_cycles>3->Done\n\
        E9:*9 when state_cycles>5->Error\n* when state_cycles>6->Error}}";
    let out = renumber(&set_of(text), &[]).unwrap();
    // Unformatted, and left so: only the digits moved.
    assert_eq!(
        rcs_after(text, &out),
        text.replace("*7 except", "*1 except")
            .replace("E9:*9", "E2:*2")
    );
    let olds: Vec<&str> = out.relabelled.iter().map(|r| r.old.as_str()).collect();
    assert_eq!(olds, ["*7", "E9", "*9"]);
}

#[test]
fn a_plan_of_several_verbs_is_one_plan_and_its_scenario_names_follow_either_verb() {
    let text = "controller A {\n    command GO\n    command RUN\n    plan GO | RUN {\n        \
        E0: *0 when new_command -> S1\n        E0: S1 when state_cycles > 2 -> S2\n        \
        E1: S2 when state_cycles > 2 -> Done\n    }\n}\n";
    let scenario =
        "controller: A\nsteps:\n  - command: RUN\n    cycles: 7\n    expect: { fired: E1 }\n";
    let out = renumber(&set_of(text), &[("s.yaml".into(), scenario.into())]).unwrap();
    assert_eq!(
        rcs_after(text, &out),
        text.replace("E0: S1", "E1: S1").replace("E1: S2", "E2: S2")
    );
    assert_eq!(out.relabelled[0].plan, "GO | RUN");
    assert_eq!(scenario_after(scenario, &out), scenario.replace("E1", "E2"));
}

#[test]
fn a_controller_type_is_renumbered_once_for_all_its_instances() {
    let text = "buffer Io { ready: bool }\nbuffer In { ready: bool }\n\
        controller type M(station: u8) {\n    reads io: Io\n    command GO\n    plan GO {\n        \
        E0: *0 when new_command -> S1\n        E4: S1 when io.ready -> Done\n    }\n}\n\
        controller ONE = M(station: 1) { io: io_one }\ncontroller TWO = M(station: 2) { io: io_two }\n";
    let out = renumbered(text, &[]);
    assert_eq!(rcs_after(text, &out), text.replace("E4:", "E1:"));
    let [one] = out.relabelled.as_slice() else {
        panic!("{:?}", out.relabelled)
    };
    assert_eq!(one.controller, "type M");
}

#[test]
fn scenario_names_of_every_form_are_renumbered_in_a_one_controller_scenario() {
    let text = "controller A {\n    command GO\n    plan GO {\n        \
        E0: *0 when new_command -> S1\n        S1 when state_cycles > 9 -> Error\n        \
        E1: S1 when state_cycles > 1 -> S2\n        *2 when state_cycles > 7 -> Done\n    }\n}\n";
    let scenario =
        "# a comment kept\ncontroller: A\nsteps:\n  - command: GO\n    expect: {fired: E0}\n  \
        - cycles: 2\n    expect: { fired: '#1' }  # by position\n  - expect: { fired: \"*2\" }\n  \
        - expect: { fired: none }\n";
    let out = renumber(&set_of(text), &[("s.yaml".into(), scenario.into())]).unwrap();
    assert_eq!(
        rcs_after(text, &out),
        text.replace("E1: S1", "E2: S1")
            .replace("*2 when", "*3 when")
    );
    assert_eq!(
        scenario_after(scenario, &out),
        scenario.replace("'#1'", "'#2'").replace("\"*2\"", "\"*3\"")
    );
}

#[test]
fn plans_that_number_a_name_differently_leave_it_and_say_so_unless_the_command_decides() {
    let text = "controller A {\n    command GO\n    command STOP\n    plan GO {\n        \
        E0: *0 when new_command -> S1\n        E0: S1 when state_cycles > 1 -> S2\n        \
        E1: S2 when state_cycles > 1 -> Done\n    }\n    plan STOP {\n        \
        *0 when new_command -> S1\n        S1 when state_cycles > 1 -> Done\n    }\n}\n";
    // Before any command, either plan may run: GO says E2, STOP E1.
    let unknown = "controller: A\nsteps:\n  - expect: { fired: E1 }\n";
    let out = renumber(&set_of(text), &[("u.yaml".into(), unknown.into())]).unwrap();
    assert!(out.scenarios.is_empty());
    assert_eq!(out.undecided.len(), 1, "{:?}", out.undecided);
    assert!(out.undecided[0].message.contains("`GO` E2, `STOP` E1"));
    let known = "controller: A\nsteps:\n  - command: STOP\n    expect: { fired: E0 }\n  \
        - expect: { fired: E1 }\n  - command: { GO: {} }\n    cycles: 3\n    expect: { fired: E1 }\n";
    let out = renumber(&set_of(text), &[("k.yaml".into(), known.into())]).unwrap();
    assert!(out.undecided.is_empty(), "{:?}", out.undecided);
    assert_eq!(
        scenario_after(known, &out),
        "controller: A\nsteps:\n  - command: STOP\n    expect: { fired: E0 }\n  \
        - expect: { fired: E1 }\n  - command: { GO: {} }\n    cycles: 3\n    expect: { fired: E2 }\n"
    );
}

#[test]
fn a_system_scenario_follows_the_root_and_judges_the_others_by_all_their_plans() {
    let text = "controller TOP {\n    subordinates LOW\n    command GO\n    plan GO {\n        \
        E0: *0 when new_command -> S1 { LOW <- GO }\n        E0: S1 when LOW.done -> Done\n    }\n}\n\
        controller LOW {\n    command GO\n    plan GO {\n        E0: *0 when new_command -> S1\n        \
        E3: S1 when state_cycles > 1 -> Done\n    }\n}\n";
    let scenario = "system: true\nsteps:\n  - command: GO\n    cycles: 4\n    \
        expect:\n      TOP: { fired: E0 }\n      LOW: { fired: E3 }\n  - expect: { TOP: { fired: none } }\n";
    let out = renumber(&set_of(text), &[("s.yaml".into(), scenario.into())]).unwrap();
    assert_eq!(
        rcs_after(text, &out),
        text.replace("E0: S1 when LOW", "E1: S1 when LOW")
            .replace("E3:", "E1:")
    );
    assert_eq!(scenario_after(scenario, &out), scenario.replace("E3", "E1"));
    // TOP's `E0` is on two rows: reported, left.
    assert_eq!(out.undecided.len(), 1, "{:?}", out.undecided);
    assert_eq!(out.undecided[0].line, 6);
}

#[test]
fn a_plan_set_with_errors_is_refused_with_its_diagnostics() {
    for text in [
        "controller A { command GO plan GO { E0: *0 when new_command -> Done ",
        "controller A { command GO plan GO { E0: *0 when nope -> Done } }",
        "controller A { command GO rows r { E0: S1 when state_cycles > 1 -> Done } plan GO { E0: *0 when new_command -> S1 use r } }",
    ] {
        match renumber(&set_of(text), &[]) {
            Err(RenumberError::Diagnostics(d)) => assert!(!d.is_empty()),
            other => panic!("{text}: {other:?}"),
        }
    }
}

#[test]
fn hostile_input_never_panics() {
    let huge = "controller A {\n    command GO // é ✓\n    plan GO {\n        /// Ü…\n        \
        E99999999999999999999999999: *0 when new_command -> S1\n        \
        E000: S1 when state_cycles > 1 -> Done\n        \
        *18446744073709551616 when state_cycles > 2 -> Error\n    }\n}\n";
    let scenarios = [
        ("a.yaml".to_string(), "controller: A # ✓\nsteps:\n  - command: GO\n    expect: { fired: E99999999999999999999999999 }\n  - expect: { fired: E000 }\n  - expect: { fired: [1, 2] }\n".to_string()),
        ("b.yaml".to_string(), "controller: [unterminated\n".to_string()),
        ("c.yaml".to_string(), "steps: 3\n".to_string()),
        ("d.yaml".to_string(), "controller: NOBODY\nsteps:\n  - expect: { fired: E1 }\n".to_string()),
        ("e.yaml".to_string(), "\u{0}\u{FEFF}é: *\n".to_string()),
    ];
    let out = renumbered(huge, &scenarios);
    assert_eq!(
        rcs_after(huge, &out),
        huge.replace("E99999999999999999999999999:", "E0:")
            .replace("E000:", "E1:")
            .replace("*18446744073709551616", "*2")
    );
    assert_eq!(
        out.scenarios[0].text,
        scenarios[0].1.replace("E99999999999999999999999999", "E0")
    );
    // `E000` is 0, which row 0's `*0` carries too; the files that are no
    // scenarios are reported, not read.
    let places: Vec<(&str, usize)> = out
        .undecided
        .iter()
        .map(|u| (u.path.as_str(), u.line))
        .collect();
    assert!(places.contains(&("a.yaml", 5)), "{places:?}");
    assert!(places.iter().any(|p| p.0 == "b.yaml"), "{places:?}");
    assert!(places.iter().any(|p| p.0 == "e.yaml"), "{places:?}");
    for text in [
        "",
        "\u{0}",
        "controller Ä {}",
        "controller",
        "controller A { plan GO { E1",
        "é ✓ /* open",
    ] {
        let _ = renumber(&set_of(text), &scenarios);
    }
}
