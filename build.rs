//! Ships `rcs-runtime` inside `rcsc`: `rcsc test --backend compiled` builds
//! the generated code against the runtime, and an installed `rcsc` has no
//! source tree to point cargo at. This writes `$OUT_DIR/runtime.rs` with
//! every file below `rcs-runtime/src` (`include_str!`, so cargo tracks each
//! one) and a standalone manifest made from `rcs-runtime/Cargo.toml`: its
//! `workspace = true` keys replaced by the workspace's values, and what only
//! the workspace builds (dev-dependencies, benches) left out. Generated on
//! every build, the copy cannot drift from the real crate.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn main() {
    let root = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let runtime = root.join("rcs-runtime");
    for watched in ["rcs-runtime/src", "rcs-runtime/Cargo.toml", "Cargo.toml"] {
        println!("cargo:rerun-if-changed={watched}");
    }

    let mut files = Vec::new();
    collect(&runtime.join("src"), &mut files);
    files.sort();
    let mut out =
        String::from("/// Every file of `rcs-runtime/src`: (path in the crate, contents).\n");
    out.push_str("pub const RUNTIME_FILES: &[(&str, &str)] = &[\n");
    for file in &files {
        let relative = file.strip_prefix(&runtime).expect("below the runtime");
        let relative = relative.to_str().expect("UTF-8 path").replace('\\', "/");
        let absolute = file.to_str().expect("UTF-8 path");
        writeln!(out, "    ({relative:?}, include_str!({absolute:?})),").unwrap();
    }
    out.push_str("];\n\n");
    let workspace = read(&root.join("Cargo.toml"));
    let manifest = standalone_manifest(&read(&runtime.join("Cargo.toml")), &workspace);
    writeln!(
        out,
        "/// `rcs-runtime/Cargo.toml` without workspace inheritance.\n\
         pub const RUNTIME_MANIFEST: &str = {manifest:?};"
    )
    .unwrap();

    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").expect("set by cargo"));
    std::fs::write(out_dir.join("runtime.rs"), out).expect("write $OUT_DIR/runtime.rs");
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    for entry in entries {
        let path = entry.expect("a folder entry").path();
        if path.is_dir() {
            collect(&path, out);
        } else {
            out.push(path);
        }
    }
}

/// `key = value` lines of each `[section]` of a TOML file (one-line values:
/// what the project's manifests use).
fn sections(toml: &str) -> BTreeMap<String, BTreeMap<String, String>> {
    let mut all: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    let mut section = String::new();
    for line in toml.lines().map(str::trim) {
        if line.starts_with('[') {
            section = line.trim_matches(|c| c == '[' || c == ']').to_string();
        } else if let Some((key, value)) = line.split_once('=') {
            if !line.starts_with('#') {
                all.entry(section.clone())
                    .or_default()
                    .insert(key.trim().to_string(), value.trim().to_string());
            }
        }
    }
    all
}

/// The runtime's manifest with every `workspace = true` resolved. Keeps
/// `[package]`, `[dependencies]` and `[features]`, less the optional
/// dependencies (the Zenoh bridge's) and the features that only turn them
/// on, which the one-process compiled backend never uses; stops the build on a form
/// it does not know rather than ship a manifest cargo would read otherwise.
fn standalone_manifest(manifest: &str, workspace: &str) -> String {
    let ws = sections(workspace);
    let lookup = |section: &str, key: &str| -> String {
        ws.get(section)
            .and_then(|s| s.get(key))
            .unwrap_or_else(|| panic!("rcs-runtime inherits `{key}`, which [{section}] lacks"))
            .clone()
    };
    let mut out = String::new();
    let mut keep = false;
    let mut section = String::new();
    let mut dropped_deps: Vec<String> = Vec::new();
    let mut dropped_features: Vec<String> = Vec::new();
    for line in manifest.lines() {
        let trimmed = line.trim();
        if trimmed.starts_with('[') {
            section = trimmed.trim_matches(|c| c == '[' || c == ']').to_string();
            keep = matches!(section.as_str(), "package" | "dependencies" | "features");
            assert!(
                keep || matches!(section.as_str(), "dev-dependencies" | "bench" | "example"),
                "rcs-runtime/Cargo.toml: build.rs does not know what to do with [{section}]"
            );
            if keep {
                out.push('\n');
                out.push_str(trimmed);
                out.push('\n');
            }
            continue;
        }
        if !keep || trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let (key, value) = trimmed.split_once('=').expect("a `key = value` line");
        let (key, value) = (key.trim(), value.trim());
        // The shipped copy runs one process: no optional dependency (the
        // Zenoh bridge's), and no feature that only turns them on.
        if section == "dependencies" && value.replace(' ', "").contains("optional=true") {
            dropped_deps.push(key.to_string());
            continue;
        }
        if section == "features" {
            let needs_dropped = value
                .trim_matches(|c| c == '[' || c == ']')
                .split(',')
                .map(|d| d.trim().trim_matches('"'))
                .filter(|d| !d.is_empty())
                .all(|d| {
                    d.strip_prefix("dep:")
                        .is_some_and(|n| dropped_deps.iter().any(|x| x == n))
                });
            if needs_dropped {
                dropped_features.push(key.to_string());
                continue;
            }
        }
        let resolved = if let Some(name) = key.strip_suffix(".workspace") {
            assert_eq!(value, "true", "{trimmed}");
            let from = if section == "package" {
                "workspace.package"
            } else {
                "workspace.dependencies"
            };
            format!("{name} = {}", lookup(from, name))
        } else if value.contains("workspace") {
            let compact: String = value.chars().filter(|c| !c.is_whitespace()).collect();
            assert_eq!(
                compact, "{workspace=true}",
                "rcs-runtime/Cargo.toml: `{trimmed}`: only a plain `{{ workspace = true }}` is resolved"
            );
            assert_eq!(section, "dependencies", "{trimmed}");
            format!("{key} = {}", lookup("workspace.dependencies", key))
        } else {
            trimmed.to_string()
        };
        out.push_str(&resolved);
        out.push('\n');
    }
    if !dropped_features.is_empty() {
        // The sources still say `#[cfg(feature = "zenoh")]`: a known name,
        // never on.
        let names: Vec<String> = dropped_features.iter().map(|f| format!("{f:?}")).collect();
        out.push_str(&format!(
            "\n[lints.rust]\nunexpected_cfgs = {{ level = \"warn\", check-cfg = ['cfg(feature, values({}))'] }}\n",
            names.join(", ")
        ));
    }
    out.trim_start().to_string()
}
