//! An installed `rcsc` needs no checkout, and installs from what cargo
//! publishes: package the published crates (`cargo package`, the `.crate`
//! files `cargo publish` would upload), check what each holds, unpack them
//! into a folder of their own, `cargo install` rcsc from the unpacked
//! package into a temporary root with the unpacked rcs-dsl, rcs-codegen and
//! rcs-runtime patched in for crates.io (where they are not yet), delete
//! the unpacked crates, then run the compiled backend on a plan set in
//! another folder, offline. No file of the checkout takes part but through
//! a `.crate`: a package that leaves out something rcsc needs fails here.
//!
//! Slow (the one `cargo install` of the suite builds rcsc and its
//! dependencies from scratch on a first run, minutes) but not ignored: the
//! README's test command and CI run it. Needs cargo with rcsc's
//! dependencies in its registry cache (true once rcsc has been built, which
//! running this test implies) and `tar` (to unpack a `.crate`, as cargo
//! does). The unpacked crates sit at one path per checkout in the
//! temporary folder, and the install builds into a folder under cargo's
//! target folder kept between runs
//! (`installed-build`), so a second run rebuilds only what changed; the
//! driver builds into `installed-drivers`, also kept.

#[allow(dead_code)] // not every helper is used here
mod common;

use common::{scratch, text};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A folder under cargo's target folder, kept between test runs.
fn kept(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(name)
}

/// A folder of this checkout's own outside its workspace (a package below
/// the workspace root would be taken for an unlisted member), at one path
/// for this checkout, kept between test runs.
fn outside_the_workspace(name: &str) -> PathBuf {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    repo().hash(&mut hasher);
    std::env::temp_dir().join(format!("rcsc-{name}-{:016x}", hasher.finish()))
}

/// Cargo as a user runs it: without what `cargo test` set for this test
/// process. `OUT_DIR` above all: rustc reads `env!` from the environment
/// cargo passes on, so an inherited `OUT_DIR` would let a package whose
/// build script is missing compile against this checkout's build output.
fn cargo() -> Command {
    let mut cargo = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    for (name, _) in std::env::vars_os() {
        let name = name.to_string_lossy();
        let set_by_cargo_test = name == "OUT_DIR"
            || name == "CARGO_TARGET_DIR"
            || name == "CARGO_TARGET_TMPDIR"
            || name == "CARGO_PRIMARY_PACKAGE"
            || [
                "CARGO_PKG_",
                "CARGO_MANIFEST_",
                "CARGO_CRATE_",
                "CARGO_BIN_",
            ]
            .iter()
            .any(|prefix| name.starts_with(prefix));
        if set_by_cargo_test {
            cargo.env_remove(&*name);
        }
    }
    cargo
}

/// The crates `cargo publish --workspace` uploads, in dependency order.
const PUBLISHED: [&str; 5] = [
    "rcs-runtime",
    "rcs-dsl",
    "rcs-codegen",
    "rcs-console",
    "rcsc",
];

/// The workspace's members with `publish` unset: the published ones.
fn publishable_members() -> Vec<String> {
    let out = cargo()
        .args([
            "metadata",
            "--offline",
            "--no-deps",
            "--format-version",
            "1",
        ])
        .current_dir(repo())
        .output()
        .expect("cargo runs");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let metadata: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let mut names: Vec<String> = metadata["packages"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["publish"].is_null())
        .map(|p| p["name"].as_str().unwrap().to_string())
        .collect();
    names.sort();
    names
}

/// `cargo package --list` of `package`: what its `.crate` holds.
fn package_list(package: &str) -> Vec<String> {
    let out = cargo()
        .args([
            "package",
            "--list",
            "--offline",
            "--allow-dirty",
            "-p",
            package,
        ])
        .current_dir(repo())
        .output()
        .expect("cargo runs");
    assert!(out.status.success(), "{package}: {}", text(&out.stderr));
    text(&out.stdout).lines().map(str::to_string).collect()
}

/// Each published package holds its sources, manifest, readme and both
/// licenses, and none of the repository's test corpora, build output,
/// criterion results, snapshots, benches or plan sets.
fn check_package_contents() {
    let mut expected: Vec<String> = PUBLISHED.iter().map(|s| s.to_string()).collect();
    expected.sort();
    assert_eq!(
        publishable_members(),
        expected,
        "every other workspace member has `publish = false`"
    );
    for package in PUBLISHED {
        let files = package_list(package);
        for needed in [
            "Cargo.toml",
            "README.md",
            "LICENSE-MIT",
            "LICENSE-APACHE",
            "src/lib.rs",
        ] {
            let needed = if package == "rcsc" && needed == "src/lib.rs" {
                "src/main.rs"
            } else {
                needed
            };
            assert!(
                files.iter().any(|f| f == needed),
                "{package} lacks {needed}: {files:?}"
            );
        }
        // Cargo leaves out a build script `include` misses with only a
        // warning: rcsc's embeds the runtime, the runtime's names its folder.
        if package == "rcsc" || package == "rcs-runtime" {
            assert!(
                files.iter().any(|f| f == "build.rs"),
                "{package} lacks build.rs: {files:?}"
            );
        }
        for file in &files {
            let unwanted = [
                "tests/",
                "target/",
                "benches/",
                "examples/",
                "plans/",
                "rcs-runtime/",
            ]
            .iter()
            .any(|folder| file.starts_with(folder))
                || file.contains("criterion")
                || file.ends_with(".snap");
            assert!(!unwanted, "{package}'s package holds {file}");
        }
    }
    // The licenses in each package folder are the root's, word for word.
    for package in ["rcs-runtime", "rcs-dsl", "rcs-codegen", "rcs-console"] {
        for license in ["LICENSE-MIT", "LICENSE-APACHE"] {
            assert_eq!(
                std::fs::read_to_string(repo().join(package).join(license)).unwrap(),
                std::fs::read_to_string(repo().join(license)).unwrap(),
                "{package}/{license} is a copy of the root's"
            );
        }
    }
}

/// The published crates as `cargo package` writes them (no verification
/// build: installing rcsc from them below is the verification), unpacked
/// into `into/<name>-<version>/`. Returns those folders by crate name.
fn package_and_unpack(into: &Path) -> Vec<(&'static str, PathBuf)> {
    let target = into.join("package-target");
    let mut package = cargo();
    package.args(["package", "--offline", "--no-verify", "--allow-dirty"]);
    for name in PUBLISHED {
        package.args(["-p", name]);
    }
    let out = package
        .arg("--target-dir")
        .arg(&target)
        .current_dir(repo())
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo package failed:\n{}",
        text(&out.stderr)
    );
    let version = env!("CARGO_PKG_VERSION");
    let unpacked = PUBLISHED
        .iter()
        .map(|name| {
            let file = target
                .join("package")
                .join(format!("{name}-{version}.crate"));
            let untar = Command::new("tar")
                .arg("xzf")
                .arg(&file)
                .arg("-C")
                .arg(into)
                .output()
                .expect("tar runs (this test needs tar on PATH)");
            assert!(untar.status.success(), "{}", text(&untar.stderr));
            (*name, into.join(format!("{name}-{version}")))
        })
        .collect();
    std::fs::remove_dir_all(&target).unwrap();
    unpacked
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let path = entry.path();
        if path.is_dir() {
            copy_dir(&path, &to.join(entry.file_name()));
        } else {
            std::fs::copy(&path, to.join(entry.file_name())).unwrap();
        }
    }
}

/// `rcsc test` as a user runs it: in `cwd`, offline, without what cargo
/// sets for this test process.
fn rcsc_test(rcsc: &Path, cwd: &Path, args: &[&str]) -> Output {
    Command::new(rcsc)
        .arg("test")
        .args(args)
        .current_dir(cwd)
        .env("NO_COLOR", "1")
        .env("CARGO_NET_OFFLINE", "true")
        .env_remove("CARGO")
        .env_remove("CARGO_TARGET_DIR")
        .env_remove("OUT_DIR")
        .env_remove("RCSC_RUNTIME_PATH")
        .output()
        .expect("rcsc runs")
}

#[test]
fn rcsc_installed_from_its_packages_runs_the_compiled_backend() {
    check_package_contents();
    let tmp = scratch("installed", &[]);
    // The unpacked crates live at one path kept between runs (and are
    // deleted after the install): cargo keys its build of a path package
    // on that path, so a second run reuses the first's.
    let crates = outside_the_workspace("installed-crates");
    let _ = std::fs::remove_dir_all(&crates);
    std::fs::create_dir_all(&crates).unwrap();
    let unpacked = package_and_unpack(&crates);
    // What a registry would serve, by `[patch.crates-io]`: cargo install
    // reads no configuration from the current folder, so it comes by
    // `--config FILE`.
    let mut patch = String::from("[patch.crates-io]\n");
    let (rcsc_entry, libraries) = unpacked.split_last().expect("rcsc is packaged last");
    for (name, dir) in libraries {
        let dir = dir.to_str().unwrap().replace('\\', "/");
        patch.push_str(&format!("{name} = {{ path = {dir:?} }}\n"));
    }
    let config = tmp.join("patch.toml");
    std::fs::write(&config, patch).unwrap();
    let (_, rcsc_package) = rcsc_entry;
    let root = tmp.join("root");

    let started = Instant::now();
    let install = cargo()
        .args(["install", "--locked", "--offline", "--debug", "--quiet"])
        .arg("--config")
        .arg(&config)
        .arg("--path")
        .arg(rcsc_package)
        .arg("--root")
        .arg(&root)
        .arg("--target-dir")
        .arg(kept("installed-build"))
        .env_remove("CARGO_INSTALL_ROOT")
        .current_dir(&tmp)
        .output()
        .expect("cargo runs");
    assert!(
        install.status.success(),
        "cargo install failed:\n{}",
        text(&install.stderr)
    );
    eprintln!("cargo install: {:.1?}", started.elapsed());
    std::fs::remove_dir_all(&crates).unwrap();
    assert!(!crates.exists());

    // A plan set with its scenarios, alone in another folder.
    let work = tmp.join("work");
    copy_dir(&repo().join("plans/submarine"), &work);
    let scenarios = std::fs::read_dir(work.join("scenarios")).unwrap().count();
    let rcsc = root
        .join("bin")
        .join(format!("rcsc{}", std::env::consts::EXE_SUFFIX));
    let drivers = kept("installed-drivers");
    let drivers = drivers.to_str().unwrap();

    let started = Instant::now();
    let compiled = rcsc_test(
        &rcsc,
        &work,
        &[".", "--backend", "compiled", "--target-dir", drivers],
    );
    eprintln!("rcsc test --backend compiled: {:.1?}", started.elapsed());
    let report = text(&compiled.stdout);
    assert_eq!(
        compiled.status.code(),
        Some(0),
        "{report}{}",
        text(&compiled.stderr)
    );
    assert!(
        report.ends_with(&format!("\n{scenarios} passed, 0 failed\n")),
        "{report}"
    );
    let interp = rcsc_test(&rcsc, &work, &["."]);
    assert_eq!(interp.status.code(), Some(0));
    assert_eq!(
        report,
        text(&interp.stdout),
        "the same report on both backends"
    );

    // The driver builds against the runtime rcsc carries, not a checkout.
    let manifest = std::fs::read_to_string(Path::new(drivers).join("rcsc/driver/Cargo.toml"))
        .expect("the driver crate");
    assert!(
        manifest.contains("rcs-runtime = { path = \"../rcs-runtime\" }"),
        "{manifest}"
    );
    let lib = std::fs::read_to_string(Path::new(drivers).join("rcsc/rcs-runtime/src/lib.rs"))
        .expect("the shipped runtime");
    assert!(lib.lines().next().unwrap().contains("@generated by rcsc"));
    let _ = std::fs::remove_dir_all(&tmp);
}

/// When the runtime cannot be built (here: cargo offline with an empty
/// registry cache), `rcsc test` says why and exits 2.
#[test]
fn a_runtime_that_cannot_be_built_is_a_clear_error() {
    let tmp = scratch("no-registry", &[]);
    let empty_home = tmp.join("cargo-home");
    std::fs::create_dir_all(&empty_home).unwrap();
    let target = tmp.join("target");
    // The compiled backend on figure13, with `env` (name, value or unset).
    let compiled = |env: &[(&str, Option<&Path>)]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_rcsc"));
        cmd.args(["test", "plans/figure13", "--backend", "compiled"])
            .arg("--target-dir")
            .arg(&target)
            .env("NO_COLOR", "1");
        for (name, value) in env {
            match value {
                Some(v) => cmd.env(name, v),
                None => cmd.env_remove(name),
            };
        }
        let out = cmd.output().expect("rcsc runs");
        assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
        (text(&out.stdout), text(&out.stderr))
    };

    let (stdout, stderr) = compiled(&[
        ("CARGO_HOME", Some(&empty_home)),
        ("CARGO_NET_OFFLINE", Some(Path::new("true"))),
        ("RCSC_RUNTIME_PATH", None),
    ]);
    assert!(
        stderr.contains("building the scenario driver (")
            && stderr.contains(") failed; cargo said:"),
        "{stderr}"
    );
    assert!(
        stderr.contains("help: the driver needs rcs-runtime's dependencies"),
        "{stderr}"
    );
    assert!(stdout.is_empty(), "no scenario ran:\n{stdout}");

    // A runtime folder that is not a crate is refused before cargo runs.
    let (_, stderr) = compiled(&[("RCSC_RUNTIME_PATH", Some(&empty_home))]);
    assert!(
        stderr.contains("is not a crate folder (no Cargo.toml)"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&tmp);
}
