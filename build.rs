//! Ships `rcs-runtime` inside `rcsc`: `rcsc test --backend compiled` builds
//! the generated code against the runtime, and an installed `rcsc` has no
//! source tree to point cargo at. This writes `$OUT_DIR/runtime.rs` with
//! every file below the runtime's `src/` (`include_str!`, so cargo tracks
//! each one) and a standalone manifest made from the runtime's
//! `Cargo.toml`: its `workspace = true` keys replaced by the workspace's
//! values, and what only the workspace builds (dev-dependencies, benches,
//! the optional Zenoh bridge) left out. Generated on every build, the copy
//! cannot drift from the real crate.
//!
//! The runtime's folder comes from the runtime itself (`DEP_RCS_RUNTIME_ROOT`,
//! set by its `links` build script), not from a path beside this file: in
//! the repository it is `rcs-runtime/`, but the published rcsc package holds
//! only rcsc (cargo leaves a nested package's folder out of a package), and
//! `cargo install rcsc` builds it against the rcs-runtime crate cargo
//! unpacked — whose manifest is the normalized one `cargo publish` writes.
//! Both manifest forms are read with a real TOML parser.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use toml_edit::{DocumentMut, Item, Value};

fn main() {
    let runtime = PathBuf::from(std::env::var_os("DEP_RCS_RUNTIME_ROOT").expect(
        "rcs-runtime's build script names its folder (`links = \"rcs_runtime\"` in its manifest)",
    ));
    let manifest_path = runtime.join("Cargo.toml");
    for watched in [runtime.join("src"), manifest_path.clone()] {
        println!("cargo::rerun-if-changed={}", watched.display());
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

    let manifest = parse(&manifest_path);
    // Inheritance only in the repository's form; then the workspace root is
    // the nearest folder above with a `[workspace]` table.
    let workspace = uses_workspace(&manifest).then(|| {
        let root = runtime
            .ancestors()
            .skip(1)
            .map(|dir| dir.join("Cargo.toml"))
            .find(|candidate| candidate.is_file() && parse(candidate).contains_key("workspace"))
            .expect("rcs-runtime inherits from a workspace, but none is above it");
        println!("cargo::rerun-if-changed={}", root.display());
        parse(&root)
    });
    let standalone = standalone_manifest(&manifest, workspace.as_ref());
    writeln!(
        out,
        "/// `rcs-runtime/Cargo.toml` without workspace inheritance.\n\
         pub const RUNTIME_MANIFEST: &str = {standalone:?};"
    )
    .unwrap();

    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").expect("set by cargo"));
    std::fs::write(out_dir.join("runtime.rs"), out).expect("write $OUT_DIR/runtime.rs");
}

fn parse(path: &Path) -> DocumentMut {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    text.parse()
        .unwrap_or_else(|e| panic!("{} is not TOML: {e}", path.display()))
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

/// `{ workspace = true }` (or `key.workspace = true`), an inherited value.
fn inherits(item: &Item) -> bool {
    item.as_table_like()
        .and_then(|t| t.get("workspace"))
        .and_then(Item::as_bool)
        == Some(true)
}

fn uses_workspace(manifest: &DocumentMut) -> bool {
    ["package", "dependencies"].iter().any(|section| {
        manifest
            .get(section)
            .and_then(Item::as_table_like)
            .is_some_and(|t| t.iter().any(|(_, item)| inherits(item)))
    })
}

/// One TOML value on one line, without the decoration it had in its file.
fn inline(item: &Item, what: &str) -> Value {
    let mut value = item
        .clone()
        .into_value()
        .unwrap_or_else(|_| panic!("rcs-runtime/Cargo.toml: `{what}` is not a value"));
    if let Some(table) = value.as_inline_table_mut() {
        table.fmt();
    }
    value.decor_mut().clear();
    value
}

/// `[section] key` of the workspace manifest, for an inherited key.
fn from_workspace<'w>(workspace: Option<&'w DocumentMut>, section: &str, key: &str) -> &'w Item {
    workspace
        .and_then(|ws| ws.get("workspace"))
        .and_then(|ws| ws.get(section))
        .and_then(|s| s.get(key))
        .unwrap_or_else(|| {
            panic!("rcs-runtime inherits `{key}`, which [workspace.{section}] lacks")
        })
}

/// The runtime's manifest as a crate of its own: `[package]`'s identity,
/// the non-optional `[dependencies]` and the `[features]` that do not only
/// turn on an optional one (the Zenoh bridge's: the compiled backend runs
/// one process). Stops the build on a form it does not know rather than
/// ship a manifest cargo would read otherwise.
fn standalone_manifest(manifest: &DocumentMut, workspace: Option<&DocumentMut>) -> String {
    for (section, _) in manifest.iter() {
        assert!(
            matches!(
                section,
                "package"
                    | "dependencies"
                    | "features"
                    | "dev-dependencies"
                    | "lib"
                    | "bench"
                    | "example"
                    | "test"
                    | "lints"
                    | "badges"
            ),
            "rcs-runtime/Cargo.toml: build.rs does not know what to do with [{section}]"
        );
    }
    let mut out = String::from("[package]\n");
    let package = manifest["package"]
        .as_table_like()
        .expect("rcs-runtime/Cargo.toml has [package]");
    // Identity only: `links` and `build` belong to the real crate's build
    // script, which the shipped copy does not carry; `readme`, `include`
    // and the registry metadata name files it does not carry either.
    for key in ["name", "version", "edition", "rust-version", "license"] {
        let Some(item) = package.get(key) else {
            continue;
        };
        let item = if inherits(item) {
            from_workspace(workspace, "package", key)
        } else {
            item
        };
        writeln!(out, "{key} = {}", inline(item, key)).unwrap();
    }

    out.push_str("\n[dependencies]\n");
    let mut dropped_deps: Vec<String> = Vec::new();
    let dependencies = manifest
        .get("dependencies")
        .and_then(Item::as_table_like)
        .expect("rcs-runtime/Cargo.toml has [dependencies]");
    for (name, item) in dependencies.iter() {
        let table = item.as_table_like();
        if table
            .and_then(|t| t.get("optional"))
            .and_then(Item::as_bool)
            == Some(true)
        {
            dropped_deps.push(name.to_string());
            continue;
        }
        let mut value = if inherits(item) {
            let extra: Vec<&str> = table.unwrap().iter().map(|(k, _)| k).collect();
            assert!(
                extra.iter().all(|k| *k == "workspace"),
                "rcs-runtime/Cargo.toml: `{name}`: only a plain `{{ workspace = true }}` is resolved, not {extra:?}"
            );
            inline(from_workspace(workspace, "dependencies", name), name)
        } else {
            inline(item, name)
        };
        if let Some(table) = value.as_inline_table_mut() {
            assert!(
                !table.contains_key("path") && !table.contains_key("git"),
                "rcs-runtime/Cargo.toml: `{name}` is not from the registry; the shipped copy cannot carry it"
            );
            // `{ version = "2" }`, as the normalized manifest writes it,
            // is `"2"`.
            if table.len() == 1 {
                if let Some(version) = table.get("version") {
                    value = version.clone();
                    value.decor_mut().clear();
                }
            }
        }
        writeln!(out, "{name} = {value}").unwrap();
    }

    let mut dropped_features: Vec<String> = Vec::new();
    let mut features = String::new();
    if let Some(table) = manifest.get("features").and_then(Item::as_table_like) {
        for (name, item) in table.iter() {
            let enables: Vec<&str> = item
                .as_array()
                .expect("a feature is an array")
                .iter()
                .filter_map(Value::as_str)
                .collect();
            let needs_dropped = !enables.is_empty()
                && enables.iter().all(|d| {
                    d.strip_prefix("dep:")
                        .is_some_and(|n| dropped_deps.iter().any(|x| x == n))
                });
            if needs_dropped {
                dropped_features.push(name.to_string());
            } else {
                writeln!(features, "{name} = {}", inline(item, name)).unwrap();
            }
        }
    }
    if !features.is_empty() {
        out.push_str("\n[features]\n");
        out.push_str(&features);
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
    out
}
