//! The policies of the split submarine and of a three-process set: every
//! crossing is allowed exactly on both ends, nothing else is, and the
//! output is deterministic. Zenoh itself enforcing them is tested with
//! rogue processes in `rcs-runtime` and the split example.

use std::collections::BTreeSet;
use std::path::Path;

use rcs_dsl::ir::Ir;
use rcs_dsl::placement::Placement;
use serde_json::Value;

use super::*;

fn load(dir: &Path) -> Ir {
    let set = rcs_dsl::load::load_folder(dir).expect("load the plan set");
    let checked = rcs_dsl::check(&set, &rcs_dsl::Options::default());
    checked.ir.expect("the plan set checks")
}

fn split_submarine() -> Ir {
    load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/submarine-split/plans"))
}

/// `(subject, flow, message, key)` for every allowed action of a policy.
fn allowed(policy: &Value) -> BTreeSet<(String, String, String, String)> {
    let acl = &policy["access_control"];
    assert_eq!(acl["enabled"], true);
    assert_eq!(acl["default_permission"], "deny");
    let rules = acl["rules"].as_array().unwrap();
    let mut out = BTreeSet::new();
    for p in acl["policies"].as_array().unwrap() {
        for subject in p["subjects"].as_array().unwrap() {
            for id in p["rules"].as_array().unwrap() {
                let r = rules.iter().find(|r| r["id"] == *id).expect("rule exists");
                assert_eq!(r["permission"], "allow");
                for flow in r["flows"].as_array().unwrap() {
                    for m in r["messages"].as_array().unwrap() {
                        for k in r["key_exprs"].as_array().unwrap() {
                            out.insert((
                                subject.as_str().unwrap().to_owned(),
                                flow.as_str().unwrap().to_owned(),
                                m.as_str().unwrap().to_owned(),
                                k.as_str().unwrap().to_owned(),
                            ));
                        }
                    }
                }
            }
        }
    }
    out
}

/// What the placement says process `p`'s policy must allow: computed from
/// the crossings, independently of how `policy` groups its rules.
fn expected(ir: &Ir, pl: &Placement, p: usize) -> BTreeSet<(String, String, String, String)> {
    let key = |x: &rcs_dsl::placement::Crossing| {
        format!("rcs/{}/{}", ir.system, buffer_name(ir, &x.kind))
    };
    let mut out = BTreeSet::new();
    let mut add = |s: &str, f: &str, m: &str, k: String| {
        out.insert((s.to_owned(), f.to_owned(), m.to_owned(), k));
    };
    for x in &pl.crossings {
        if x.writer == p {
            for &q in &x.readers {
                add(&pl.processes[q], "egress", "put", key(x));
                add(&pl.processes[q], "ingress", "declare_subscriber", key(x));
            }
        } else if x.readers.contains(&p) {
            let w = &pl.processes[x.writer];
            add(w, "ingress", "put", key(x));
            add(w, "egress", "declare_subscriber", key(x));
        }
    }
    // The console: the operator alone watches the figures and controls
    // the executives.
    let console = |what: &str| format!("rcs/{}/_console/{}/{what}", ir.system, pl.processes[p]);
    add(OPERATOR, "egress", "put", console("figures"));
    add(
        OPERATOR,
        "ingress",
        "declare_subscriber",
        console("figures"),
    );
    add(OPERATOR, "ingress", "put", console("control"));
    add(OPERATOR, "egress", "declare_subscriber", console("control"));
    for (c, ctrl) in ir.controllers.iter().enumerate() {
        if pl.ctrl_process[c] != p {
            continue;
        }
        let status = format!("rcs/{}/{}.status", ir.system, ctrl.name);
        add(OPERATOR, "egress", "put", status.clone());
        add(OPERATOR, "ingress", "declare_subscriber", status);
        if ctrl.supervisor.is_none() {
            let command = format!("rcs/{}/{}.command", ir.system, ctrl.name);
            add(OPERATOR, "ingress", "put", command.clone());
            add(OPERATOR, "egress", "declare_subscriber", command);
        }
    }
    out
}

#[test]
fn every_crossing_is_allowed_on_both_ends_and_nothing_else() {
    let ir = split_submarine();
    let pl = Placement::of(&ir);
    assert_eq!(pl.processes, ["helm", "engine"]);
    for p in 0..pl.processes.len() {
        let policy = policy(&ir, &pl, p);
        assert_eq!(allowed(&policy), expected(&ir, &pl, p), "process {p}");
        // No wildcard anywhere: `rcs/**` is never a permitted key.
        let text = policy.to_string();
        assert!(!text.contains('*'), "{text}");
        // Deterministic.
        assert_eq!(text, super::policy(&ir, &pl, p).to_string());
    }
    // The engine may not put the helm's command to SM, nor anything to
    // itself: spot checks in words.
    let engine = allowed(&policy(&ir, &pl, 1));
    assert!(engine.contains(&(
        "helm".into(),
        "ingress".into(),
        "put".into(),
        "rcs/submarine_split/TB.command".into()
    )));
    assert!(!engine
        .iter()
        .any(|(s, f, m, k)| s == "helm" && f == "ingress" && m == "put" && k.ends_with(".status")));
}

#[test]
fn each_put_has_a_size_limit_and_the_file_is_a_zenoh_config() {
    let ir = split_submarine();
    let pl = Placement::of(&ir);
    let policy = policy(&ir, &pl, 0);
    let filters = policy["low_pass_filter"].as_array().unwrap();
    let imported = pl
        .crossings
        .iter()
        .filter(|x| x.readers.contains(&0))
        .count();
    // One per imported buffer, and the console's controls.
    assert_eq!(filters.len(), imported + 1);
    assert!(filters.iter().any(|f| f["key_exprs"][0]
        == "rcs/submarine_split/_console/helm/control"
        && f["size_limit"].as_u64() >= Some(584)));
    for f in filters {
        let limit = f["size_limit"].as_u64().unwrap();
        assert!((300..10_000).contains(&limit), "{f}");
    }
    let file = zenoh_config_file(&ir, &pl, 0);
    assert!(file.starts_with("// @generated by rcsc"));
    let json: String = file.lines().filter(|l| !l.starts_with("//")).collect();
    let v: Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["mode"], "peer");
    assert_eq!(v["transport"]["link"]["tls"]["enable_mtls"], true);
    assert_eq!(v["access_control"], policy["access_control"]);
}

#[test]
fn the_operator_policy_mirrors_the_processes() {
    let ir = split_submarine();
    let pl = Placement::of(&ir);
    let op = allowed(&operator_policy(&ir, &pl));
    // Every permission a process grants the operator, the operator holds
    // in the opposite direction, and nothing more.
    let flip = |f: &str| if f == "ingress" { "egress" } else { "ingress" };
    let mut mirrored = BTreeSet::new();
    for (p, process) in pl.processes.iter().enumerate() {
        for (s, f, m, k) in allowed(&policy(&ir, &pl, p)) {
            if s == OPERATOR {
                mirrored.insert((process.clone(), flip(&f).to_owned(), m, k));
            }
        }
    }
    assert_eq!(op, mirrored);
    assert!(op.contains(&(
        "helm".into(),
        "egress".into(),
        "put".into(),
        "rcs/submarine_split/SM.command".into()
    )));
    assert!(op.contains(&(
        "engine".into(),
        "egress".into(),
        "put".into(),
        "rcs/submarine_split/_console/engine/control".into()
    )));
}
