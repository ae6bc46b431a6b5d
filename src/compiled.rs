//! `rcsc test --backend compiled`: the generated Rust of the plan sets,
//! with its scenario driver, built into a small crate under the target
//! folder and run as a child process that serves
//! `rcs_runtime::driver`'s protocol. The scenarios themselves are run by
//! the same runner as on the interpreter (`rcs_dsl::scenario::run_on`),
//! through a `Remote` per controller, so both backends are held to one
//! reading of every scenario.
//!
//! The crate (`<target>/rcsc/driver/`) depends only on `rcs-runtime`,
//! whose source is shipped inside rcsc (`build.rs`) and written beside it
//! (`<target>/rcsc/rcs-runtime/`), so an installed rcsc needs no checkout.
//! Both are rewritten only where their files change and built by cargo
//! with `--offline` first, from a lock file of the versions rcsc was built
//! with, so after the first build a run costs a second or two and needs no
//! network.

use rcs_codegen::writer::OutputLock;
use rcs_dsl::ir::Ir;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

/// The package name, also the binary's.
const PACKAGE: &str = "rcsc-scenario-driver";

/// The lock file of the workspace rcsc was built in: the driver crate
/// starts from it so that cargo resolves the same versions offline.
const WORKSPACE_LOCK: &str = include_str!("../Cargo.lock");

/// A running driver process.
pub struct Driver {
    child: Child,
    /// `Some` between controllers; a `Remote` borrows the pipes while open.
    pipes: Option<(BufReader<ChildStdout>, ChildStdin)>,
    /// The lock on `<target>/rcsc`, held while the driver runs, so that
    /// another run's plan sets cannot rebuild it under this one.
    _lock: OutputLock,
}

/// A controller of the driver process, for one scenario.
pub type Remote = rcs_runtime::driver::Remote<BufReader<ChildStdout>, ChildStdin>;

/// A run of several controllers of the driver process, for one system scenario.
pub type RemoteSystem = rcs_runtime::driver::RemoteSystem<BufReader<ChildStdout>, ChildStdin>;

impl Driver {
    /// A fresh `controller` of plan set number `set` (in the order given to [`build`]).
    pub fn open(&mut self, set: usize, controller: &str) -> Result<Remote, String> {
        let (input, output) = self
            .pipes
            .take()
            .ok_or("the driver connection was lost by an earlier failure")?;
        Remote::open(input, output, set, controller)
    }

    /// Take the pipes back after a scenario.
    pub fn close(&mut self, remote: Remote) {
        self.pipes = Some(remote.into_parts());
    }

    /// A fresh run of `controllers` of plan set number `set`, for a system scenario.
    pub fn open_system(
        &mut self,
        set: usize,
        controllers: &[&str],
    ) -> Result<RemoteSystem, String> {
        let (input, output) = self
            .pipes
            .take()
            .ok_or("the driver connection was lost by an earlier failure")?;
        RemoteSystem::open(input, output, set, controllers)
    }

    /// Take the pipes back after a system scenario.
    pub fn close_system(&mut self, remote: RemoteSystem) {
        self.pipes = Some(remote.into_parts());
    }
}

impl Drop for Driver {
    fn drop(&mut self) {
        // Closing stdin ends the server's loop; wait so no zombie is left.
        self.pipes = None;
        let _ = self.child.wait();
    }
}

/// `rcs-runtime`'s source, shipped inside rcsc by `build.rs`:
/// `RUNTIME_FILES` and `RUNTIME_MANIFEST`.
mod shipped {
    include!(concat!(env!("OUT_DIR"), "/runtime.rs"));
}

/// The folder (beside the driver's) where the shipped runtime is written.
const RUNTIME_DIR: &str = "rcs-runtime";

/// The runtime crate as files: the shipped source and its standalone
/// manifest, each marked generated in its first line (so a file a newer
/// rcsc no longer ships is removed) (pure).
fn runtime_files() -> Vec<rcs_codegen::OutputFile> {
    let generated = rcs_codegen::GENERATED;
    let version = env!("CARGO_PKG_VERSION");
    let note = format!("{generated} {version}: rcs-runtime's source, shipped inside rcsc");
    let mut files = vec![rcs_codegen::OutputFile {
        path: "Cargo.toml".to_string(),
        contents: format!("# {note}.\n{}", shipped::RUNTIME_MANIFEST),
    }];
    files.extend(
        shipped::RUNTIME_FILES
            .iter()
            .map(|(path, contents)| rcs_codegen::OutputFile {
                path: path.to_string(),
                contents: format!("// {note}.\n{contents}"),
            }),
    );
    files
}

/// Where `rcs-runtime` comes from: the folder `RCSC_RUNTIME_PATH` names (a
/// checkout of the runtime, for working on it), else the copy shipped
/// inside rcsc, written under `root` only where its files changed (so
/// cargo sees it unchanged between runs). Returns the dependency's value
/// for the driver's manifest.
fn runtime_dependency(root: &Path) -> Result<String, String> {
    if let Some(local) = std::env::var_os("RCSC_RUNTIME_PATH").map(PathBuf::from) {
        if !local.join("Cargo.toml").is_file() {
            return Err(format!(
                "RCSC_RUNTIME_PATH={} is not a crate folder (no Cargo.toml); \
                 unset it to use the runtime shipped inside rcsc",
                local.display()
            ));
        }
        let local = std::path::absolute(&local).unwrap_or(local);
        // TOML basic strings take `\` escapes; write the path with `/`.
        let path = local.display().to_string().replace('\\', "/");
        return Ok(format!("{{ path = {path:?} }}"));
    }
    rcs_codegen::writer::write_tree(&root.join(RUNTIME_DIR), &runtime_files(), &mut |_| {})
        .map_err(|e| format!("writing the runtime crate: {e}"))?;
    Ok(format!("{{ path = \"../{RUNTIME_DIR}\" }}"))
}

/// The driver crate's files for these plan sets (pure).
fn crate_files(irs: &[&Ir], runtime: &str) -> Vec<rcs_codegen::OutputFile> {
    let generated = rcs_codegen::GENERATED;
    let mut files = vec![rcs_codegen::OutputFile {
        path: "Cargo.toml".to_string(),
        contents: format!(
            "# {generated}: the scenario driver of `rcsc test --backend compiled`.\n\
             [package]\nname = \"{PACKAGE}\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
             [dependencies]\nrcs-runtime = {runtime}\n\n\
             # Its own workspace, wherever the target folder lives.\n[workspace]\n"
        ),
    }];
    let mut modules = String::new();
    let mut factories = String::new();
    let mut system_factories = String::new();
    for (i, ir) in irs.iter().enumerate() {
        let options = rcs_codegen::Options {
            driver: true,
            ..rcs_codegen::Options::default()
        };
        let rust = rcs_codegen::generate_with(ir, &options)
            .into_iter()
            .find(|f| f.path.starts_with("rust/"))
            .expect("the generated Rust");
        let file = format!("set_{i}.rs");
        let system = rcs_codegen::ident::ident(&rcs_codegen::ident::snake(&ir.system));
        modules.push_str(&format!("mod set_{i} {{\n    include!({file:?});\n}}\n"));
        factories.push_str(&format!("        set_{i}::{system}::new_driver,\n"));
        system_factories.push_str(&format!("        set_{i}::{system}::new_system_driver,\n"));
        files.push(rcs_codegen::OutputFile {
            path: format!("src/{file}"),
            contents: rust.contents,
        });
    }
    files.push(rcs_codegen::OutputFile {
        path: "src/main.rs".to_string(),
        contents: format!(
            "// {generated}: serves rcs_runtime::driver's protocol on stdin/stdout.\n\
             #![allow(dead_code)]\n{modules}\n\
             fn main() {{\n    let sets: &[rcs_runtime::driver::Factory] = &[\n{factories}    ];\n    \
             let systems: &[rcs_runtime::driver::SystemFactory] = &[\n{system_factories}    ];\n    \
             let served = rcs_runtime::driver::serve_systems(sets, systems, std::io::stdin().lock(), std::io::stdout().lock());\n    \
             if let Err(e) = served {{\n        eprintln!(\"scenario driver: {{e}}\");\n        std::process::exit(2);\n    }}\n}}\n"
        ),
    });
    files
}

/// Write, build and start the driver for these plan sets. `status` prints
/// a progress line; `blocked` is called before waiting for another run's
/// lock on `<target>/rcsc` (held from the first write until the driver
/// ends, so concurrent runs take turns as cargo's builds do).
pub fn build(
    irs: &[&Ir],
    target_dir: &Path,
    status: &dyn Fn(&str),
    blocked: &mut dyn FnMut(&Path),
) -> Result<Driver, String> {
    let root = target_dir.join("rcsc");
    std::fs::create_dir_all(&root)
        .map_err(|e| format!("cannot create {}: {e}", rcs_dsl::load::display(&root)))?;
    let held = OutputLock::acquire(&root, blocked)
        .map_err(|e| format!("locking the scenario driver's folder: {e}"))?;
    let source = root.join("driver");
    let build_dir = root.join("driver-target");
    let runtime = runtime_dependency(&root)?;
    let mut files = crate_files(irs, &runtime);
    rcs_codegen::rustfmt::format_files(&mut files);
    let report = rcs_codegen::writer::write_tree(&source, &files, &mut |_| {})
        .map_err(|e| format!("writing the scenario driver: {e}"))?;
    let lock = source.join("Cargo.lock");
    if !lock.exists() {
        std::fs::write(&lock, WORKSPACE_LOCK)
            .map_err(|e| format!("cannot write {}: {e}", lock.display()))?;
    }
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let run = |offline: bool| {
        let mut cmd = Command::new(&cargo);
        cmd.arg("build")
            .arg("--quiet")
            .arg("--manifest-path")
            .arg(source.join("Cargo.toml"))
            .arg("--target-dir")
            .arg(&build_dir)
            .env_remove("CARGO_TARGET_DIR")
            .stdin(Stdio::null());
        if offline {
            cmd.arg("--offline");
        }
        cmd.output()
    };
    if !report.written.is_empty() || !binary(&build_dir).exists() {
        status(&format!(
            "scenario driver ({})",
            rcs_dsl::load::display(&source)
        ));
    }
    let mut out = run(true).map_err(|e| format!("cannot run cargo: {e}"))?;
    if !out.status.success() {
        // Offline resolution fails only when a crate is missing locally.
        out = run(false).map_err(|e| format!("cannot run cargo: {e}"))?;
    }
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let mut message = format!(
            "building the scenario driver ({}) failed; cargo said:\n{}",
            rcs_dsl::load::display(&source),
            stderr.trim_end()
        );
        if stderr.contains("offline") || stderr.contains("registry") {
            message.push_str(
                "\nhelp: the driver needs rcs-runtime's dependencies (serde, serde_json, \
                 thiserror, quanta) in cargo's registry cache, as after building or installing \
                 rcsc, or access to crates.io",
            );
        }
        return Err(message);
    }
    let mut child = Command::new(binary(&build_dir))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| format!("cannot start the scenario driver: {e}"))?;
    let (Some(stdin), Some(stdout)) = (child.stdin.take(), child.stdout.take()) else {
        return Err("the scenario driver has no pipes".to_string());
    };
    Ok(Driver {
        child,
        pipes: Some((BufReader::new(stdout), stdin)),
        _lock: held,
    })
}

fn binary(build_dir: &Path) -> PathBuf {
    build_dir
        .join("debug")
        .join(format!("{PACKAGE}{}", std::env::consts::EXE_SUFFIX))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_crate_names_every_set_and_is_marked_generated() {
        let ir = crate::tests::one_controller();
        let files = crate_files(&[&ir, &ir], "{ path = \"../rcs-runtime\" }");
        let paths: Vec<&str> = files.iter().map(|f| f.path.as_str()).collect();
        assert_eq!(
            paths,
            ["Cargo.toml", "src/set_0.rs", "src/set_1.rs", "src/main.rs"]
        );
        assert!(files.iter().all(|f| f
            .contents
            .lines()
            .next()
            .unwrap()
            .contains(rcs_codegen::GENERATED)));
        let main = &files[3].contents;
        assert!(main.contains("set_0::a::new_driver") && main.contains("set_1::a::new_driver"));
        assert!(main.contains("set_1::a::new_system_driver") && main.contains("serve_systems"));
        assert!(files[1]
            .contents
            .contains("impl ::rcs_runtime::driver::Driven for Driver"));
    }

    /// The shipped runtime is the crate in this repository, file for file,
    /// with a manifest cargo reads outside the workspace.
    #[test]
    fn the_shipped_runtime_is_the_real_one() {
        let real = Path::new(env!("CARGO_MANIFEST_DIR")).join("rcs-runtime");
        let mut on_disk = Vec::new();
        let mut folders = vec![real.join("src")];
        while let Some(dir) = folders.pop() {
            for entry in std::fs::read_dir(dir).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    folders.push(path);
                } else {
                    on_disk.push(path);
                }
            }
        }
        let mut shipped: Vec<&str> = shipped::RUNTIME_FILES.iter().map(|f| f.0).collect();
        let mut expected: Vec<String> = on_disk
            .iter()
            .map(|p| {
                p.strip_prefix(&real)
                    .unwrap()
                    .to_str()
                    .unwrap()
                    .replace('\\', "/")
            })
            .collect();
        shipped.sort_unstable();
        expected.sort_unstable();
        assert_eq!(shipped, expected);
        for (path, contents) in shipped::RUNTIME_FILES {
            assert_eq!(*contents, std::fs::read_to_string(real.join(path)).unwrap());
        }

        let manifest = shipped::RUNTIME_MANIFEST;
        assert!(!manifest.contains("workspace"), "{manifest}");
        assert!(
            !manifest.contains("criterion"),
            "no dev-dependencies:\n{manifest}"
        );
        for line in [
            "name = \"rcs-runtime\"",
            &format!("version = \"{}\"", env!("CARGO_PKG_VERSION")),
            "edition = \"2021\"",
            "[dependencies]",
            "serde = { version = \"1\", features = [\"derive\"] }",
            "serde_json = \"1\"",
            "thiserror = \"2\"",
            "quanta = { version = \"0.12\", default-features = false }",
        ] {
            assert!(manifest.lines().any(|l| l == line), "{line}:\n{manifest}");
        }
        // Every file of the written crate is marked, so stale ones go.
        assert!(runtime_files().iter().all(|f| f
            .contents
            .lines()
            .next()
            .unwrap()
            .contains(rcs_codegen::GENERATED)));
    }
}
