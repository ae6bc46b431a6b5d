//! Compile every plan set of the repository (`plans/*` and the golden ok
//! cases `tests/data/ok/*`) through `rcs_codegen::Config`, as a user's
//! build.rs would. The workspace's `cargo clippy -D warnings` then checks
//! every generated module (with the scenario driver, which the
//! differential tests use). Also builds the C port of the methodology's
//! controller template for the benchmark.

use std::path::{Path, PathBuf};

#[path = "../../rcs-dsl/tests/common/hierarchy.rs"]
mod hierarchy;

/// How many random hierarchies are compiled for the differential test.
const HIERARCHIES: usize = 8;

fn module_name(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let s: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    format!("set_{s}")
}

/// Whether the plan set at `path` has a manifest that names a `process:`.
fn places_processes(path: &Path) -> bool {
    std::fs::read_to_string(path.join("rcs.yaml"))
        .is_ok_and(|m| m.lines().any(|l| l.trim_start().starts_with("process:")))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = PathBuf::from(std::env::var("OUT_DIR")?);
    let mut includes = String::new();
    let mut registry = String::new();
    for folder in ["../../plans", "../../tests/data/ok"] {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(folder)?
            .map(|e| e.map(|e| e.path()))
            .collect::<Result<_, _>>()?;
        entries.sort();
        for path in entries {
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let is_set = path.is_dir() && name != "snapshots"
                || path.extension().is_some_and(|e| e == "rcs");
            if !is_set {
                continue;
            }
            // A set placed in several processes generates `System::process`,
            // which needs rcs-runtime's Zenoh bridge: compiled only with this
            // crate's feature `zenoh`, so that a build without it compiles
            // nothing from Zenoh.
            if std::env::var_os("CARGO_FEATURE_ZENOH").is_none() && places_processes(&path) {
                continue;
            }
            let module = module_name(&path);
            let dest = out.join("sets").join(&module);
            rcs_codegen::Config::new()
                .out_dir(&dest)
                .graphs(false)
                .driver(true)
                .serde(rcs_codegen::SerdeDerives::Feature("serde".into()))
                .compile(&path)?;
            let rust = std::fs::read_dir(dest.join("rust"))?
                .map(|e| e.map(|e| e.path()))
                .collect::<Result<Vec<_>, _>>()?;
            let [rust] = rust.as_slice() else {
                return Err(format!("{}: expected one generated Rust file", path.display()).into());
            };
            includes.push_str(&format!(
                "pub mod {module} {{\n    include!({:?});\n}}\n",
                rust.display().to_string()
            ));
            // The generated file is `rust/<system>.rs` holding `pub mod <system>`.
            let system = rust
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let system_mod = rcs_codegen::ident::ident(&rcs_codegen::ident::snake(&system));
            let rel = path
                .strip_prefix("../../")
                .unwrap_or(&path)
                .display()
                .to_string();
            registry.push_str(&format!(
                "    PlanSet {{ path: {rel:?}, new_driver: {module}::{system_mod}::new_driver, new_system_driver: {module}::{system_mod}::new_system_driver }},\n"
            ));
        }
    }
    includes.push_str(&format!(
        "/// Every plan set above: its path from the workspace root and its\n\
         /// generated scenario driver.\npub const SETS: &[PlanSet] = &[\n{registry}];\n"
    ));
    // The console benchmark's fleet (examples/console_load.rs includes it;
    // not a set of the registry: it has no scenarios to differ on).
    rcs_codegen::Config::new()
        .out_dir(out.join("fleet"))
        .graphs(false)
        .compile("fleet")?;
    let hierarchies = random_hierarchies(&out, &mut includes)?;
    includes.push_str(&format!(
        "/// Random hierarchies whose checks found a cross-controller finding\n\
         /// with a system run (`rcs-dsl/tests/common/hierarchy.rs`; `path`\n\
         /// is absolute, under `OUT_DIR`).\npub const RANDOM_HIERARCHIES: &[PlanSet] = &[\n{hierarchies}];\n"
    ));
    std::fs::write(out.join("sets.rs"), includes)?;

    // The folders themselves: a plan set added to either is compiled in
    // (`Config::compile` names only the sets that were there).
    println!("cargo::rerun-if-changed=../../plans");
    println!("cargo::rerun-if-changed=../../tests/data/ok");
    println!("cargo::rerun-if-changed=fleet");
    println!("cargo::rerun-if-changed=c/pr_template.c");
    println!("cargo::rerun-if-changed=../../rcs-dsl/tests/common/hierarchy.rs");
    cc::Build::new()
        .file("c/pr_template.c")
        .opt_level(2)
        .warnings(true)
        .compile("pr_template");
    Ok(())
}

/// The first [`HIERARCHIES`] random hierarchies, on fixed seeds, that check
/// without an error and have a cross-controller finding with a system run
/// (the property the differential test then checks on generated code),
/// compiled as the sets above are; their registry entries.
fn random_hierarchies(
    out: &Path,
    includes: &mut String,
) -> Result<String, Box<dyn std::error::Error>> {
    let mut registry = String::new();
    let mut kept = 0;
    for n in 0..2000u64 {
        if kept == HIERARCHIES {
            break;
        }
        let seed = n.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let h = hierarchy::random_hierarchy(seed);
        let dir = out.join("hierarchies").join(format!("h{n}"));
        std::fs::create_dir_all(&dir)?;
        std::fs::write(dir.join("plans.rcs"), &h.plans)?;
        std::fs::write(dir.join("rcs.yaml"), &h.manifest)?;
        let Ok(set) = rcs_dsl::load_folder(&dir) else {
            continue;
        };
        let checked = rcs_dsl::check(&set, &rcs_dsl::Options::default());
        let witnessed = checked
            .diagnostics
            .iter()
            .any(|d| d.witness.as_ref().is_some_and(|w| w.system.is_some()));
        if checked.ir.is_none() || !witnessed {
            std::fs::remove_dir_all(&dir)?;
            continue;
        }
        let module = format!("hierarchy_{n}");
        let dest = out.join("hierarchy_sets").join(&module);
        // Their findings are the point: not printed as build warnings.
        rcs_codegen::Config::new()
            .out_dir(&dest)
            .graphs(false)
            .driver(true)
            .compile_with_io(&dir, &mut std::io::sink(), &mut std::io::sink())?;
        let system = format!("h{n}");
        let rust = dest.join("rust").join(format!("{system}.rs"));
        let system_mod = rcs_codegen::ident::ident(&rcs_codegen::ident::snake(&system));
        includes.push_str(&format!(
            "pub mod {module} {{\n    include!({:?});\n}}\n",
            rust.display().to_string()
        ));
        registry.push_str(&format!(
            "    PlanSet {{ path: {:?}, new_driver: {module}::{system_mod}::new_driver, new_system_driver: {module}::{system_mod}::new_system_driver }},\n",
            dir.display().to_string()
        ));
        kept += 1;
    }
    Ok(registry)
}
