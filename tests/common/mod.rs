//! What the end-to-end tests of the `rcsc` binary share: running it, its
//! output as text, scratch plan-set folders and what a build left in one.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Run `rcsc` in `cwd`, without colour.
#[allow(dead_code)] // each test binary compiles this module; not all use it
pub fn rcsc_in(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rcsc"))
        .args(args)
        .current_dir(cwd)
        .env("NO_COLOR", "1")
        .output()
        .expect("rcsc runs")
}

/// Run `rcsc` in the repository root (cargo's working folder for tests).
#[allow(dead_code)] // each test binary compiles this module; not all use it
pub fn rcsc(args: &[&str]) -> Output {
    rcsc_in(Path::new("."), args)
}

pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A fresh temporary folder holding `files` (paths may have folders). Its
/// name carries the test binary, the process and `name`, so tests running
/// in parallel never share one.
#[allow(dead_code)] // each test binary compiles this module; not all use it
pub fn scratch(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let binary = std::env::current_exe()
        .ok()
        .and_then(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .unwrap_or_default();
    let dir = std::env::temp_dir().join(format!("rcsc-{binary}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (path, body) in files {
        let p = dir.join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, body).unwrap();
    }
    dir
}

/// `cp -r from to`.
#[allow(dead_code)] // each test binary compiles this module; not all use it
pub fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let dest = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_tree(&p, &dest);
        } else {
            std::fs::copy(&p, &dest).unwrap();
        }
    }
}

/// Every file below `dir`: `/`-separated relative path → bytes.
#[allow(dead_code)] // each test binary compiles this module; not all use it
pub fn tree(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    if !dir.exists() {
        return out;
    }
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p
                    .strip_prefix(dir)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

#[allow(dead_code)] // each test binary compiles this module; not all use it
pub mod site_links;
