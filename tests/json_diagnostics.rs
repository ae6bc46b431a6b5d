//! `--message-format json` against its published schema
//! (docs/diagnostic.schema.json, explained in docs/diagnostics-json.md):
//! every diagnostic of the golden error corpus, as the binary prints it,
//! must validate, and the corpus must reach every branch of the schema, so
//! neither the output nor the schema can change without the other.
//!
//! The validator below reads the keywords the schema uses (`type`, `const`,
//! `enum`, `required`, `properties`, `additionalProperties`, `items`,
//! `oneOf`, `minimum`, `$ref` into `$defs`) and refuses any other keyword,
//! so the schema cannot quietly rely on one it does not check.

use serde_json::Value;
use std::collections::BTreeSet;
use std::path::Path;

mod common;
use common::{rcsc, text};

const KEYWORDS: &[&str] = &[
    "$schema",
    "$id",
    "title",
    "description",
    "$defs",
    "type",
    "const",
    "enum",
    "required",
    "properties",
    "additionalProperties",
    "items",
    "oneOf",
    "minimum",
    "$ref",
];

struct Validator<'a> {
    root: &'a Value,
    /// `$ref`s and `oneOf` branches some instance went through.
    reached: BTreeSet<String>,
}

impl<'a> Validator<'a> {
    fn validate(&mut self, schema: &Value, v: &Value, at: &str) -> Result<(), String> {
        let obj = schema
            .as_object()
            .ok_or_else(|| format!("schema at {at} is not an object"))?;
        for k in obj.keys() {
            if !KEYWORDS.contains(&k.as_str()) {
                return Err(format!("schema keyword `{k}` is not checked by this test"));
            }
        }
        if let Some(r) = obj.get("$ref").and_then(Value::as_str) {
            let name = r
                .strip_prefix("#/$defs/")
                .ok_or_else(|| format!("unsupported $ref {r}"))?;
            self.reached.insert(format!("$defs/{name}"));
            let target = &self.root["$defs"][name];
            if target.is_null() {
                return Err(format!("$ref {r} names no definition"));
            }
            return self.validate(target, v, at);
        }
        if let Some(t) = obj.get("type") {
            let types: Vec<&str> = match t {
                Value::String(s) => vec![s.as_str()],
                Value::Array(a) => a.iter().filter_map(Value::as_str).collect(),
                _ => return Err("bad type keyword".into()),
            };
            if !types.iter().any(|t| is_type(v, t)) {
                return Err(format!("{at}: {v} is not of type {types:?}"));
            }
        }
        if let Some(c) = obj.get("const") {
            if c != v {
                return Err(format!("{at}: {v} is not {c}"));
            }
        }
        if let Some(Value::Array(options)) = obj.get("enum") {
            if !options.contains(v) {
                return Err(format!("{at}: {v} is not one of {options:?}"));
            }
        }
        if let (Some(min), Some(n)) = (obj.get("minimum").and_then(Value::as_i64), v.as_i64()) {
            if n < min {
                return Err(format!("{at}: {n} < {min}"));
            }
        }
        if let Value::Object(fields) = v {
            if let Some(Value::Array(req)) = obj.get("required") {
                for r in req.iter().filter_map(Value::as_str) {
                    if !fields.contains_key(r) {
                        return Err(format!("{at}: required field `{r}` is missing"));
                    }
                }
            }
            let props = obj.get("properties").and_then(Value::as_object);
            for (k, fv) in fields {
                let here = format!("{at}.{k}");
                match (
                    props.and_then(|p| p.get(k)),
                    obj.get("additionalProperties"),
                ) {
                    (Some(s), _) => self.validate(s, fv, &here)?,
                    (None, Some(Value::Bool(false))) => {
                        return Err(format!("{at}: field `{k}` is not in the schema"))
                    }
                    (None, Some(s @ Value::Object(_))) => self.validate(s, fv, &here)?,
                    (None, _) => {}
                }
            }
        }
        if let (Some(items), Value::Array(elems)) = (obj.get("items"), v) {
            for (i, e) in elems.iter().enumerate() {
                self.validate(items, e, &format!("{at}[{i}]"))?;
            }
        }
        if let Some(Value::Array(branches)) = obj.get("oneOf") {
            let mut matched = Vec::new();
            for (i, b) in branches.iter().enumerate() {
                let mut inner = Validator {
                    root: self.root,
                    reached: BTreeSet::new(),
                };
                if inner.validate(b, v, at).is_ok() {
                    matched.push(i);
                    self.reached.extend(inner.reached);
                }
            }
            if matched.len() != 1 {
                return Err(format!(
                    "{at}: {v} matches {} oneOf branches",
                    matched.len()
                ));
            }
            self.reached.insert(format!("{at}/oneOf/{}", matched[0]));
        }
        Ok(())
    }
}

fn is_type(v: &Value, t: &str) -> bool {
    match t {
        "object" => v.is_object(),
        "array" => v.is_array(),
        "string" => v.is_string(),
        "integer" => v.is_i64() || v.is_u64(),
        "number" => v.is_number(),
        "boolean" => v.is_boolean(),
        "null" => v.is_null(),
        _ => false,
    }
}

fn schema() -> Value {
    let text = std::fs::read_to_string("docs/diagnostic.schema.json").expect("schema file");
    serde_json::from_str(&text).expect("the schema is JSON")
}

/// Every error case of the golden corpus (files and plan-set folders).
fn corpus() -> Vec<String> {
    let mut cases: Vec<String> = std::fs::read_dir("tests/data/err")
        .expect("tests/data/err")
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.is_dir() || p.extension().is_some_and(|x| x == "rcs"))
        .filter(|p| !p.ends_with("snapshots"))
        .map(|p| p.display().to_string())
        .collect();
    cases.sort();
    cases
}

#[test]
fn every_diagnostic_of_the_error_corpus_validates_against_the_schema() {
    let schema = schema();
    let mut v = Validator {
        root: &schema,
        reached: BTreeSet::new(),
    };
    let mut lines = 0;
    let mut codes = BTreeSet::new();
    // One call per case: several .rcs files on one command line are one
    // plan set, and the cases' controllers would clash.
    for case in corpus() {
        let out = rcsc(&["check", "--message-format", "json", &case]);
        assert!(
            out.status.code().is_some_and(|c| c <= 2),
            "rcsc check crashed on {case}: {}",
            text(&out.stderr)
        );
        let mut here = 0;
        for line in text(&out.stdout).lines() {
            let value: Value = serde_json::from_str(line)
                .unwrap_or_else(|e| panic!("{case}: not JSON ({e}): {line}"));
            if let Err(e) = v.validate(&schema, &value, "$") {
                panic!("{case}: {e}\nin: {line}");
            }
            codes.insert(value["code"].as_str().unwrap_or_default().to_string());
            here += 1;
        }
        assert!(here > 0, "{case}: an error case printed no diagnostic");
        lines += here;
    }
    assert!(lines > 400, "only {lines} diagnostics in the corpus");
    assert!(codes.len() > 50, "only {} codes: {codes:?}", codes.len());
    // Every definition and every oneOf branch is used by some diagnostic,
    // so the schema describes output rcsc really prints.
    let defs: BTreeSet<String> = schema["$defs"]
        .as_object()
        .expect("$defs")
        .keys()
        .map(|k| format!("$defs/{k}"))
        .collect();
    let missing: Vec<_> = defs.difference(&v.reached).collect();
    assert!(missing.is_empty(), "never reached: {missing:?}");
    let branches = schema["$defs"]["expect"]["oneOf"]
        .as_array()
        .expect("expect branches")
        .len();
    let kinds = v
        .reached
        .iter()
        .filter(|r| r.contains(".expect/oneOf/"))
        .map(|r| r.rsplit('/').next().unwrap_or_default().to_string())
        .collect::<BTreeSet<_>>();
    assert_eq!(
        kinds.len(),
        branches,
        "expect kinds the corpus shows: {kinds:?}"
    );
}

#[test]
fn the_validator_refuses_what_the_schema_does_not_allow() {
    let schema = schema();
    let good = serde_json::json!({
        "format": "rcsc-diagnostic", "version": 1, "code": "syntax",
        "severity": "error", "message": "m", "file": "a.rcs",
        "line": 1, "column": 1, "end_line": 1, "end_column": 2,
        "labels": [], "notes": [], "help": null
    });
    let mut v = Validator {
        root: &schema,
        reached: BTreeSet::new(),
    };
    assert_eq!(v.validate(&schema, &good, "$"), Ok(()));
    for (field, bad) in [
        ("version", serde_json::json!(2)),
        ("severity", serde_json::json!("fatal")),
        ("line", serde_json::json!(0)),
        ("extra", serde_json::json!(true)),
        ("witness", serde_json::json!({"state": "S1"})),
    ] {
        let mut d = good.clone();
        d[field] = bad.clone();
        assert!(
            v.validate(&schema, &d, "$").is_err(),
            "{field} = {bad} passed"
        );
    }
    let mut d = good.clone();
    d.as_object_mut().expect("object").remove("format");
    assert!(
        v.validate(&schema, &d, "$").is_err(),
        "format missing passed"
    );
}

#[test]
fn the_json_format_page_and_the_schema_name_the_same_version() {
    let schema = schema();
    let version = schema["properties"]["version"]["const"]
        .as_u64()
        .expect("const version");
    let page = std::fs::read_to_string("docs/diagnostics-json.md").expect("page");
    assert!(page.starts_with(&format!("# JSON diagnostics (version {version})")));
    assert!(Path::new("docs/diagnostic.schema.json").exists());
}
