//! `rcsc graph` and `rcsc ir` end to end: what they print, where, and with
//! which exit status (0 / 1 / 2).

use std::process::Command;

mod common;
mod tools;
use common::{rcsc, scratch, text};

const BROKEN: &str = "controller A {\n    command GO\n    plan GO {\n        *0 when new_command && nope -> Done\n    }\n}\n";
const UNUSED_VAR: &str = "controller A {\n    command GO\n    var spare: u8 = 0\n    plan GO {\n        *0 when new_command -> Done\n    }\n}\n";

#[test]
fn graph_prints_the_plans_dot() {
    let out = rcsc(&["graph", "plans/submarine", "--plan", "PR.AHEAD"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(out.stderr.is_empty(), "{}", text(&out.stderr));
    let dot = text(&out.stdout);
    assert!(dot.contains("digraph \"PR.AHEAD\" {"), "{dot}");
    assert!(dot.contains("\"*0\" -> \"S1\""), "{dot}");
    // The same text `rcsc build` writes to graphs/PR/AHEAD.dot.
    let set = rcs_dsl::load_paths(&["plans/submarine".into()]).unwrap();
    let ir = rcs_dsl::check(&set[0], &rcs_dsl::Options::default())
        .ir
        .unwrap();
    let ctrl = &ir.controllers[ir.controller_by_name("PR").unwrap().index()];
    let plan = ctrl.plan_of("AHEAD").unwrap();
    assert_eq!(dot, rcs_codegen::dot::plan_graph(&ir, ctrl, plan));
}

#[test]
fn graph_of_a_single_file_and_the_hierarchy() {
    let out = rcsc(&["graph", "plans/figure13/figure13.rcs", "--plan", "GX.RUN"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("digraph \"GX.RUN\""));

    let out = rcsc(&["graph", "plans/submarine", "--hierarchy"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let dot = text(&out.stdout);
    assert!(dot.contains("digraph \"submarine\""), "{dot}");
    assert!(dot.contains("\"SM\" -> \"PR\";"), "{dot}");

    // One of --plan and --hierarchy, not both, not neither.
    assert_eq!(rcsc(&["graph", "plans/submarine"]).status.code(), Some(2));
    let both = rcsc(&[
        "graph",
        "plans/submarine",
        "--hierarchy",
        "--plan",
        "PR.AHEAD",
    ]);
    assert_eq!(both.status.code(), Some(2));
}

#[test]
fn graph_writes_to_a_file_with_out() {
    let dir = scratch("out", &[]);
    let file = dir.join("ahead.dot");
    let out = rcsc(&[
        "graph",
        "plans/submarine",
        "--plan",
        "PR.AHEAD",
        "-o",
        file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(out.stdout.is_empty());
    let written = std::fs::read_to_string(&file).unwrap();
    assert!(written.contains("digraph \"PR.AHEAD\""));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn graph_renders_svg_through_graphviz() {
    if !tools::dot_available("`rcsc graph --format svg`") {
        return;
    }
    let out = rcsc(&[
        "graph",
        "plans/submarine",
        "--plan",
        "PR.AHEAD",
        "--format",
        "svg",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let svg = text(&out.stdout);
    assert!(svg.contains("<svg"), "{svg}");
    assert!(svg.contains("</svg>"), "{svg}");
    assert!(svg.contains("PR · AHEAD"), "the graph's title: {svg}");
}

#[test]
fn svg_without_graphviz_names_the_package() {
    // An empty PATH: `dot` cannot be found.
    let out = Command::new(env!("CARGO_BIN_EXE_rcsc"))
        .args([
            "graph",
            "plans/submarine",
            "--plan",
            "PR.AHEAD",
            "--format",
            "svg",
        ])
        .env("PATH", "")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let err = text(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("Graphviz `dot` not found"), "{err}");
    assert!(err.contains("apt-get install graphviz"), "{err}");
    assert!(err.contains("--format dot"), "{err}");
}

#[test]
fn unknown_plan_exits_2_listing_the_plans() {
    for plan in ["PR.ASTERN", "XX.AHEAD"] {
        let out = rcsc(&["graph", "plans/submarine", "--plan", plan]);
        assert_eq!(out.status.code(), Some(2), "{plan}");
        assert!(out.stdout.is_empty());
        let err = text(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(&format!("no plan `{plan}`")), "{err}");
        for known in ["PR.AHEAD", "PR.INIT", "TB.AHEAD", "SM.TRANSIT"] {
            assert!(err.contains(known), "{known}: {err}");
        }
    }
    // Not of the form CTRL.VERB: a usage error from the argument parser.
    let out = rcsc(&["graph", "plans/submarine", "--plan", "PR"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("CTRL.VERB"));
}

#[test]
fn graph_and_ir_refuse_plans_with_errors() {
    let dir = scratch("broken", &[("a.rcs", BROKEN)]);
    let path = dir.to_str().unwrap();
    for args in [
        vec!["graph", path, "--plan", "A.GO"],
        vec!["ir", path],
        vec!["ir", path, "--format", "json"],
    ] {
        let mut args = args;
        args.extend(["--message-format", "json"]);
        let out = rcsc(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}: {}", text(&out.stdout));
        // stdout carries the product, so JSON diagnostics go to stderr.
        let stderr = text(&out.stderr);
        let lines: Vec<&str> = stderr.lines().collect();
        assert_eq!(lines.len(), 1, "{stderr}");
        let v: serde_json::Value = serde_json::from_str(lines[0]).expect("a JSON diagnostic");
        assert_eq!(v["code"], "unknown_name");
        assert_eq!(v["severity"], "error");
        assert_eq!(v["line"], 4);
    }
    // Human diagnostics too, with the summary line.
    let out = rcsc(&["ir", path]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(err.contains("error[unknown_name]"), "{err}");
    assert!(
        err.contains("could not check the plans due to 1 error"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn warnings_go_to_stderr_and_the_product_to_stdout() {
    let dir = scratch("warn", &[("a.rcs", UNUSED_VAR)]);
    let path = dir.to_str().unwrap();
    let out = rcsc(&["graph", path, "--plan", "A.GO"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(text(&out.stderr).contains("warning[unused]"));
    assert!(text(&out.stdout).starts_with("// @generated by rcsc"));

    let out = rcsc(&["ir", path, "--format", "json", "--message-format", "json"]);
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is the IR only");
    assert_eq!(v["controllers"][0]["name"], "A");
    assert!(text(&out.stderr).contains("\"code\":\"unused\""));

    let out = rcsc(&["ir", path, "--quiet", "-D", "unused"]);
    assert_eq!(out.status.code(), Some(1), "-D works on ir");
    let out = rcsc(&["ir", path, "--quiet", "-A", "unused"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stderr.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn ir_json_parses_back() {
    let out = rcsc(&["ir", "plans/submarine", "--format", "json"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert_eq!(v["system"], "submarine");
    let names: Vec<&str> = v["controllers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(names.len(), 3);
    for n in ["SM", "PR", "TB"] {
        assert!(names.contains(&n), "{names:?}");
    }
    let pr = v["controllers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "PR")
        .unwrap();
    assert_eq!(pr["title"], "Propulsion");
    let ahead = pr["plans"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["rows"].as_array().unwrap().len() == 7)
        .expect("the AHEAD plan has seven rows");
    assert_eq!(ahead["states"][0]["name"], "S0");
    assert_eq!(ahead["rows"][0]["is_entry"], true);
    // Spans are byte ranges into a file of the set, named relative to it.
    let span = &ahead["rows"][0]["span"];
    assert!(span["end"].as_u64().unwrap() > span["start"].as_u64().unwrap());
    let file = span["file"].as_u64().unwrap() as usize;
    assert_eq!(v["files"][file], "propulsion.rcs");
    assert_eq!(v["schedule"][0]["period_ns"], 30_000_000);
}

#[test]
fn ir_yaml_is_the_default() {
    let out = rcsc(&["ir", "plans/submarine"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let yaml = text(&out.stdout);
    let lines: Vec<&str> = yaml.lines().collect();
    for want in [
        "system: submarine",
        "files:",
        "controllers:",
        "schedule:",
        "limits:",
    ] {
        assert!(lines.contains(&want), "{want}:\n{yaml}");
    }
    for want in ["name: PR", "title: Propulsion", "max_rules_per_plan: 10"] {
        assert!(
            lines
                .iter()
                .any(|l| l.trim_start().trim_start_matches("- ") == want),
            "{want}:\n{yaml}"
        );
    }
    let explicit = rcsc(&["ir", "plans/submarine", "--format", "yaml"]);
    assert_eq!(explicit.stdout, out.stdout);
}

#[test]
fn ir_of_several_plan_sets_is_a_list() {
    let out = rcsc(&[
        "ir",
        "plans/submarine",
        "plans/figure13",
        "--format",
        "json",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let systems: Vec<&str> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|ir| ir["system"].as_str().unwrap())
        .collect();
    assert_eq!(systems, ["submarine", "figure13"]);
}

#[test]
fn missing_paths_exit_2() {
    for verb in ["graph", "ir"] {
        let mut args = vec![verb, "no/such/plans"];
        if verb == "graph" {
            args.extend(["--plan", "A.GO"]);
        }
        let out = rcsc(&args);
        assert_eq!(out.status.code(), Some(2), "{verb}");
        assert_eq!(text(&out.stderr).lines().count(), 1, "{verb}");
    }
}

#[test]
fn help_shows_examples_for_every_verb() {
    for (verb, example) in [
        ("check", "rcsc check plans/submarine"),
        ("build", "rcsc build plans/submarine"),
        ("graph", "rcsc graph plans/submarine --plan PR.AHEAD"),
        ("ir", "rcsc ir plans/submarine"),
    ] {
        let out = rcsc(&[verb, "--help"]);
        assert_eq!(out.status.code(), Some(0), "{verb}");
        let help = text(&out.stdout);
        for want in [
            "Examples:",
            example,
            "--message-format",
            "--color",
            "--quiet",
        ] {
            assert!(help.contains(want), "{verb}: {want}\n{help}");
        }
        if verb != "check" {
            assert!(help.contains("--out"), "{verb}: --out\n{help}");
        }
    }
    let out = rcsc(&["--help"]);
    let help = text(&out.stdout);
    for verb in ["check", "build", "graph", "ir"] {
        assert!(help.contains(&format!("rcsc {verb} ")), "{verb}:\n{help}");
    }
}

#[test]
fn build_accepts_out_as_well_as_out_dir() {
    let dir = scratch("build-out", &[]);
    let out_dir = dir.join("gen");
    let out = rcsc(&[
        "build",
        "plans/figure13",
        "--out",
        out_dir.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(out_dir.join("graphs/GX/RUN.dot").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A state set is drawn as one edge per state, each labelled with the
/// row; an `except` row as its dashed `*N` node saying what it leaves out;
/// `rcsc ir` writes both patterns with the plan's state ids.
#[test]
fn state_sets_and_except_in_graph_and_ir() {
    let set = "tests/data/ok/0210_state_sets";
    let out = rcsc(&["graph", set, "--plan", "CELL.RUN"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let dot = text(&out.stdout);
    let e2: Vec<&str> = dot
        .lines()
        .filter(|l| l.contains("id=\"edge-E2\""))
        .collect();
    assert_eq!(e2.len(), 2, "one edge per state of the set:\n{dot}");
    assert!(e2[0]
        .trim_start()
        .starts_with("\"Starting\" -> \"Holding\""));
    assert!(e2[1].trim_start().starts_with("\"Execute\" -> \"Holding\""));
    // The edge names its row; the row in full is in the state table.
    assert!(e2.iter().all(|l| l.contains("<TD>E2</TD>")), "{dot}");
    assert!(
        dot.contains("<TD ALIGN=\"LEFT\" BALIGN=\"LEFT\">line.jam</TD>"),
        "{dot}"
    );
    let node = dot
        .lines()
        .find(|l| l.trim_start().starts_with("\"*5\" [id=\"node-any-E5\""))
        .unwrap_or_else(|| panic!("a *5 node:\n{dot}"));
    assert!(node.contains("style=dashed"), "{node}");
    assert!(dot.contains(">* except Holding</TD>"), "{dot}");
    assert!(dot.contains("\"*5\" -> \"Error\""), "{dot}");
    assert!(!dot.contains("\"Holding\" -> \"Error\""), "{dot}");

    let out = rcsc(&["ir", set, "--format", "json"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    let plan = &v["controllers"][0]["plans"][0];
    let states: Vec<&str> = plan["states"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(states, ["S0", "Starting", "Execute", "Holding"]);
    assert_eq!(
        plan["rows"][2]["from"],
        serde_json::json!({ "states": [1, 2] })
    );
    assert_eq!(
        plan["rows"][5]["from"],
        serde_json::json!({ "except": [5, [3]] })
    );
    assert_eq!(plan["rows"][1]["from"], serde_json::json!({ "state": 1 }));
}
