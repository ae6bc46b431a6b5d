//! SCRATCH (to be deleted): run every plan scenario and report row coverage.

use rcs_dsl::scenario;
use rcs_dsl::source::SourceFile;
use rcs_dsl::{check, load_folder, Options};
use serde_json::Value as Json;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

fn verb_of(v: &Json) -> Option<String> {
    match v {
        Json::String(s) => Some(s.clone()),
        Json::Object(m) => m.keys().next().cloned(),
        _ => None,
    }
}

#[test]
fn coverage() {
    let mut missing_total = 0;
    for set in ["../plans/submarine", "../plans/figure13"] {
        let loaded = load_folder(Path::new(set)).expect("plans");
        let ir = check(&loaded, &Options::default()).ir.expect("clean");
        // (controller, verb) -> row name -> scenarios firing it
        let mut hit: BTreeMap<(String, String), BTreeMap<String, BTreeSet<String>>> =
            BTreeMap::new();
        let dir = Path::new(set).join("scenarios");
        let mut paths: Vec<_> = std::fs::read_dir(&dir)
            .map(|d| d.map(|e| e.unwrap().path()).collect())
            .unwrap_or_default();
        paths.sort();
        for p in paths {
            let text = std::fs::read_to_string(&p).unwrap();
            let stem = p
                .file_name()
                .unwrap()
                .to_str()
                .unwrap()
                .trim_end_matches(".scenario.yaml")
                .to_string();
            let file = SourceFile::new(p.to_str().unwrap(), text.clone());
            let s = scenario::parse(&ir, &file, &stem)
                .unwrap_or_else(|e| panic!("{}:{}: {}", p.display(), e.line, e.message));
            let out = scenario::run(&ir, &s);
            println!("== {stem} ({}): {:?}", s.name, out.failure);
            assert!(
                out.failure.is_none(),
                "{}: {:?}; fired {:?}",
                p.display(),
                out.failure,
                out.fired
            );
            let raw: Json = rcs_dsl::yaml::from_str(&text).unwrap();
            let ctrl = raw["controller"].as_str().unwrap().to_string();
            let mut verb: Option<String> = None;
            let mut i = 0;
            let mut line = String::new();
            for step in raw["steps"].as_array().unwrap() {
                if let Some(c) = step.get("command") {
                    verb = verb_of(c);
                }
                let n = step.get("cycles").and_then(|c| c.as_u64()).unwrap_or(1) as usize;
                let fired = &out.fired[i..i + n];
                i += n;
                let v = verb.clone().unwrap_or_else(|| "-".into());
                let mut compact: Vec<String> = Vec::new();
                for f in fired {
                    if f != "-" {
                        hit.entry((ctrl.clone(), v.clone()))
                            .or_default()
                            .entry(f.clone())
                            .or_default()
                            .insert(stem.clone());
                    }
                    compact.push(f.clone());
                }
                if n > 3 {
                    let nn = compact.iter().filter(|x| *x == "-").count();
                    line += &format!(
                        " {v}:[{}x{n}: {nn} none, last {}]",
                        n,
                        compact.last().unwrap()
                    );
                } else {
                    line += &format!(" {v}:{:?}", compact);
                }
            }
            assert_eq!(i, out.fired.len());
            println!("   {line}");
        }
        for c in &ir.controllers {
            for p in &c.plans {
                let verb = &c.commands[p.verb.index()].name;
                let h = hit.get(&(c.name.clone(), verb.clone()));
                for r in &p.rows {
                    let name = r.display_name();
                    let who = h.and_then(|h| h.get(&name));
                    match who {
                        Some(w) => println!("{} {} {}: {:?}", c.name, verb, name, w),
                        None => {
                            missing_total += 1;
                            println!("{} {} {}: MISSING", c.name, verb, name)
                        }
                    }
                }
            }
        }
    }
    println!("missing rows: {missing_total}");
}
