//! Traces as MCAP recordings (issue 31, item 2): `rcsc test --trace
//! FILE.mcap` on a plan set of `plans/` writes the same bytes every run,
//! `rcsc trace` sums it exactly as the JSON-lines trace of the same run, a
//! damaged recording is refused with a code and a help line (never a
//! panic), the writer's marker rules hold for `.mcap`, and an independent
//! reader — the PyPI `mcap` package, in a virtual environment under the
//! target folder — finds one channel per controller and per buffer, JSON
//! Schemas that name the fields, and one message per traced cycle.
#![cfg(feature = "mcap")]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::{rcsc, rcsc_in, scratch, text};

const PLANS: &str = "plans/submarine";

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 temp path")
}

fn assert_ok(out: &Output) {
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
}

/// Run the plan set's scenarios, tracing to `path`.
fn traced(path: &Path) -> Vec<u8> {
    assert_ok(&rcsc(&["test", PLANS, "--trace", s(path)]));
    std::fs::read(path).unwrap()
}

#[test]
fn the_same_run_records_the_same_bytes() {
    let dir = scratch("same", &[]);
    let (a, b) = (dir.join("a.mcap"), dir.join("b.mcap"));
    let first = traced(&a);
    assert!(first.starts_with(b"\x89MCAP0\r\n"), "an MCAP recording");
    assert!(first.ends_with(b"\x89MCAP0\r\n"), "finished");
    assert_eq!(first, traced(&b), "two runs, two different recordings");
    // The next run replaces its own recording (the marker is in it).
    assert_eq!(first, traced(&a));
}

#[test]
fn mcap_and_json_lines_sum_alike() {
    let dir = scratch("alike", &[]);
    let mcap = traced(&dir.join("t.mcap"));
    let lines = traced(&dir.join("t.jsonl"));
    // The same name in two folders: told apart by content, not by name.
    let plans = std::fs::canonicalize(PLANS).unwrap();
    let mut outputs = Vec::new();
    for (sub, bytes) in [("m", &mcap), ("j", &lines)] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
        std::fs::write(dir.join(sub).join("run.trace"), bytes).unwrap();
        for plans_arg in [None, Some(&plans)] {
            let mut args = vec!["trace", "run.trace"];
            if let Some(p) = plans_arg {
                args.extend(["--plans", s(p)]);
            }
            let out = rcsc_in(&dir.join(sub), &args);
            assert_ok(&out);
            outputs.push(text(&out.stdout));
        }
    }
    assert!(outputs[1].contains("rows fired"), "{}", outputs[1]);
    assert_eq!(outputs[0], outputs[2], "without --plans");
    assert_eq!(outputs[1], outputs[3], "with --plans");
    // `rcsc doc --trace` draws the same numbers from either.
    let mut pages = Vec::new();
    for sub in ["m", "j"] {
        let out = rcsc_in(
            &dir.join(sub),
            &["doc", s(&plans), "--trace", "run.trace", "-o", "site", "-q"],
        );
        assert_ok(&out);
        pages.push(site_files(&dir.join(sub).join("site")));
    }
    assert!(pages[0].len() > 10_000, "a site was written");
    assert!(pages[0] == pages[1], "the sites differ");
}

/// Every file below `dir`, by relative path, concatenated in name order.
fn site_files(dir: &Path) -> Vec<u8> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    let mut files = Vec::new();
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                files.push(p);
            }
        }
    }
    files.sort();
    for f in files {
        out.extend_from_slice(f.strip_prefix(dir).unwrap().to_string_lossy().as_bytes());
        out.extend(std::fs::read(&f).unwrap());
    }
    out
}

#[test]
fn a_damaged_recording_is_refused_with_a_code_and_help() {
    let dir = scratch("damaged", &[]);
    let whole = traced(&dir.join("t.mcap"));
    let bad = dir.join("bad.mcap");
    for len in [9, 40, whole.len() / 3, whole.len() - 9] {
        std::fs::write(&bad, &whole[..len]).unwrap();
        for args in [
            vec!["trace", s(&bad)],
            vec!["doc", PLANS, "--trace", s(&bad), "-o", s(&dir.join("site"))],
        ] {
            let out = rcsc(&args);
            let err = text(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{args:?} at {len}: {err}");
            assert!(err.contains("error[bad_mcap]"), "{err}");
            assert!(err.contains("bad.mcap"), "names the file: {err}");
            assert!(err.contains("help:"), "{err}");
            assert!(!err.contains("panicked"), "{err}");
        }
    }
}

#[test]
fn a_recording_rcsc_did_not_write_is_not_replaced() {
    let dir = scratch("foreign", &[]);
    let path = dir.join("t.mcap");
    let ours = traced(&path);
    // Another writer's recording: the same bytes without the marker.
    let marker = b"@generated by rcsc";
    let at = ours
        .windows(marker.len())
        .position(|w| w == marker)
        .unwrap();
    let mut theirs = ours.clone();
    theirs[at] = b'#';
    std::fs::write(&path, &theirs).unwrap();
    let out = rcsc(&["test", PLANS, "--trace", s(&path)]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("error[not_generated]"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), theirs, "left as it was");
}

/// Cycles per (executive, controller) in a JSON-lines trace.
fn cycles_per_controller(jsonl: &[u8]) -> BTreeMap<(String, String), u64> {
    let mut n = BTreeMap::new();
    for line in text(jsonl).lines().skip(1) {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        let key = (
            v["executive"].as_str().unwrap().to_string(),
            v["controller"].as_str().unwrap().to_string(),
        );
        *n.entry(key).or_insert(0) += 1;
    }
    n
}

/// What the Python reader reports of a recording.
const READER: &str = r#"
import json, sys
from mcap.reader import make_reader
with open(sys.argv[1], "rb") as f:
    reader = make_reader(f)
    summary = reader.get_summary()
    channels = {}
    for ch in summary.channels.values():
        schema = summary.schemas[ch.schema_id]
        parsed = json.loads(schema.data)
        channels[str(ch.id)] = {
            "topic": ch.topic,
            "message_encoding": ch.message_encoding,
            "schema_encoding": schema.encoding,
            "schema_name": schema.name,
            "properties": sorted(parsed["properties"]),
            "metadata": dict(ch.metadata),
            "count": 0,
            "writers": [],
        }
    for schema, channel, message in reader.iter_messages():
        c = channels[str(channel.id)]
        c["count"] += 1
        body = json.loads(message.data)
        if "writer" in body and body["writer"] not in c["writers"]:
            c["writers"].append(body["writer"])
    print(json.dumps(channels))
"#;

/// A virtual environment with the PyPI `mcap` package, made once under
/// the target folder; `None` (after saying why) when pip cannot reach the
/// registry outside CI. Under `CI`, every failure fails the test.
fn python_with_mcap() -> Option<PathBuf> {
    let venv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("mcap-venv");
    let python = venv.join("bin").join("python3");
    let have = |py: &Path| {
        Command::new(py)
            .args(["-c", "import mcap.reader"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if have(&python) {
        return Some(python);
    }
    let made = Command::new("python3")
        .args(["-m", "venv", "--clear"])
        .arg(&venv)
        .output()
        .expect("python3 runs (install python3 and python3-venv)");
    assert!(
        made.status.success(),
        "python3 -m venv failed (install python3-venv): {}",
        text(&made.stderr)
    );
    let pip = Command::new(&python)
        .args([
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
            "mcap",
        ])
        .output()
        .expect("pip runs");
    if !pip.status.success() {
        let err = text(&pip.stderr);
        let unreachable = [
            "connection",
            "Connection",
            "resolve",
            "No matching distribution",
        ]
        .iter()
        .any(|w| err.contains(w));
        if unreachable && std::env::var_os("CI").is_none() {
            eprintln!("skipped: pip cannot reach the package registry to install `mcap`:\n{err}");
            return None;
        }
        panic!("pip install mcap failed: {err}");
    }
    assert!(
        have(&python),
        "`import mcap.reader` fails after pip install mcap"
    );
    Some(python)
}

#[test]
fn the_pypi_mcap_reader_finds_channels_schemas_and_every_cycle() {
    let dir = scratch("pypi", &[]);
    let recording = dir.join("t.mcap");
    traced(&recording);
    let lines = traced(&dir.join("t.jsonl"));
    let cycles = cycles_per_controller(&lines);
    let Some(python) = python_with_mcap() else {
        return;
    };
    let out = Command::new(&python)
        .args(["-c", READER])
        .arg(&recording)
        .output()
        .unwrap();
    assert_ok(&out);
    let channels: BTreeMap<String, serde_json::Value> =
        serde_json::from_slice(&out.stdout).unwrap();
    let (mut controllers, mut buffers) = (0, 0);
    for c in channels.values() {
        let meta = &c["metadata"];
        let executive = meta["rcs.executive"].as_str().unwrap().to_string();
        assert_eq!(c["message_encoding"], "json", "{c}");
        assert_eq!(c["schema_encoding"], "jsonschema", "{c}");
        let props: Vec<&str> = c["properties"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p.as_str().unwrap())
            .collect();
        match meta["rcs.kind"].as_str() {
            Some("controller") => {
                controllers += 1;
                let name = meta["rcs.controller"].as_str().unwrap().to_string();
                assert_eq!(c["schema_name"], "rcs.ControllerCycle");
                for field in [
                    "verb",
                    "verb_name",
                    "state",
                    "state_name",
                    "fired",
                    "status",
                ] {
                    assert!(props.contains(&field), "{field} in {props:?}");
                }
                let topic = c["topic"].as_str().unwrap();
                assert!(
                    topic.starts_with("/rcs/") && topic.ends_with(&name),
                    "{topic}"
                );
                assert_eq!(
                    c["count"].as_u64(),
                    cycles.get(&(executive, name)).copied(),
                    "{c}"
                );
            }
            Some("buffer") => {
                buffers += 1;
                assert!(props.contains(&"value"), "{props:?}");
                let writers = c["writers"].as_array().unwrap();
                assert_eq!(writers.len(), 1, "one writer per buffer: {c}");
                let writer = writers[0].as_str().unwrap().to_string();
                assert_eq!(
                    c["count"].as_u64(),
                    cycles.get(&(executive, writer)).copied()
                );
            }
            other => panic!("a channel of kind {other:?}: {c}"),
        }
    }
    assert_eq!(controllers, cycles.len(), "one channel per controller run");
    assert!(buffers > 0, "the submarine's controllers write buffers");
}
