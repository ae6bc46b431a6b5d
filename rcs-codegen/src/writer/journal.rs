//! The journal of a write's last step, and the repairs a write makes
//! first: finishing a build that was killed while it renamed, and removing
//! the temporaries of one killed before (see the [writer](super) docs).
//!
//! A write stages every changed file as a temporary (`.rcsc-tmp-…`) beside
//! its target, then writes the journal, `.rcsc-journal` in the output
//! folder (itself through a temporary and a rename, so it is whole or
//! absent), then renames and removes, then deletes the journal. A journal
//! found by the next write (under the lock) therefore names a build whose
//! every new file was complete: `recover` rolls it forward — renames the
//! temporaries still there, removes the stale files still there — so the
//! folder holds that build's complete output before anything else happens.
//!
//! The format is text, one step a line, fields separated by tabs (`→`
//! below), paths relative to the output folder with `%`, tab, CR and LF
//! escaped:
//!
//! ```text
//! rcsc journal 1
//! rename→graphs/A/.rcsc-tmp-4242-0→graphs/A/GO.dot
//! remove→tables/B.md
//! end
//! ```
//!
//! A journal that does not end in `end` or names a path outside the
//! folder is not trusted: it is deleted, and the write that found it
//! rewrites every file anyway.

use super::{guard, io_err, is_generated, safe_relative, WriteError, JOURNAL_FILE, TMP_PREFIX};
use std::io;
use std::path::{Path, PathBuf};

/// One step of a commit.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum Step {
    /// Rename the temporary (first) onto the target (second).
    Rename(String, String),
    /// Remove a stale generated file.
    Remove(String),
}

const HEADER: &str = "rcsc journal 1";

fn escape(path: &str) -> String {
    path.replace('%', "%25")
        .replace('\t', "%09")
        .replace('\n', "%0A")
        .replace('\r', "%0D")
}

fn unescape(path: &str) -> String {
    path.replace("%09", "\t")
        .replace("%0A", "\n")
        .replace("%0D", "\r")
        .replace("%25", "%")
}

/// The journal's text (pure).
pub(super) fn render(steps: &[Step]) -> String {
    let mut text = format!("{HEADER}\n");
    for step in steps {
        match step {
            Step::Rename(tmp, target) => {
                text.push_str(&format!("rename\t{}\t{}\n", escape(tmp), escape(target)))
            }
            Step::Remove(path) => text.push_str(&format!("remove\t{}\n", escape(path))),
        }
    }
    text.push_str("end\n");
    text
}

/// The steps of a journal's text, or `None` when it is incomplete or
/// names a path that would leave the folder (pure).
pub(super) fn parse(text: &str) -> Option<Vec<Step>> {
    let mut lines = text.lines();
    if lines.next()? != HEADER {
        return None;
    }
    let mut steps = Vec::new();
    for line in lines {
        let fields: Vec<String> = line.split('\t').map(unescape).collect();
        let step = match fields.as_slice() {
            [end] if end == "end" => return Some(steps),
            [op, tmp, target] if op == "rename" => Step::Rename(tmp.clone(), target.clone()),
            [op, path] if op == "remove" => Step::Remove(path.clone()),
            _ => return None,
        };
        let paths_ok = match &step {
            Step::Rename(tmp, target) => safe_relative(tmp) && safe_relative(target),
            Step::Remove(path) => safe_relative(path),
        };
        if !paths_ok {
            return None;
        }
        steps.push(step);
    }
    None
}

/// Write the journal of `steps` into `out_dir` (whole or not at all).
pub(super) fn write(out_dir: &Path, steps: &[Step]) -> Result<(), WriteError> {
    let tmp = out_dir.join(format!("{TMP_PREFIX}{}-journal", std::process::id()));
    let path = out_dir.join(JOURNAL_FILE);
    let written = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .and_then(|mut f| io::Write::write_all(&mut f, render(steps).as_bytes()))
        .and_then(|()| std::fs::rename(&tmp, &path));
    written.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io_err(&path, e)
    })
}

/// Remove the journal: the commit it describes is complete.
pub(super) fn finish(out_dir: &Path) -> Result<(), WriteError> {
    let path = out_dir.join(JOURNAL_FILE);
    match std::fs::remove_file(&path) {
        Err(e) if e.kind() != io::ErrorKind::NotFound => Err(io_err(&path, e)),
        _ => Ok(()),
    }
}

/// Carry out `steps` under `out_dir`; stops at the first failure (the
/// journal stays, so the next write tries again). A rename whose
/// temporary is gone was done before. Returns the files removed.
pub(super) fn apply(out_dir: &Path, steps: &[Step]) -> Result<Vec<PathBuf>, WriteError> {
    let mut removed = Vec::new();
    for step in steps {
        match step {
            Step::Rename(tmp, target) => {
                let (tmp, target) = (out_dir.join(tmp), out_dir.join(target));
                match std::fs::rename(&tmp, &target) {
                    Err(e) if e.kind() == io::ErrorKind::NotFound && !tmp.exists() => {}
                    r => r.map_err(|e| io_err(&target, e))?,
                }
            }
            Step::Remove(path) => {
                let path = out_dir.join(path);
                // Only a generated regular file, never a link or a folder.
                let file = std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_file());
                if file && is_generated(&path) {
                    match std::fs::remove_file(&path) {
                        Err(e) if e.kind() != io::ErrorKind::NotFound => {
                            return Err(io_err(&path, e))
                        }
                        _ => removed.push(path),
                    }
                }
            }
        }
    }
    Ok(removed)
}

/// Finish the build a journal in `out_dir` names, if any (call it with the
/// lock held, before [`sweep_temporaries`]); `root` is `out_dir`
/// canonicalised. Returns whether there was one.
///
/// What changed in the folder since the journal was written is checked
/// again: a rename is skipped (its temporary left for the sweep) when its
/// temporary is no longer a regular file, or when its target now leads out
/// through a link or holds a file rcsc did not generate.
pub(super) fn recover(root: &Path, out_dir: &Path) -> Result<bool, WriteError> {
    let path = out_dir.join(JOURNAL_FILE);
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(false),
        // Not UTF-8 or unreadable as text: not a journal rcsc wrote.
        Err(e) if e.kind() == io::ErrorKind::InvalidData => String::new(),
        Err(e) => return Err(io_err(&path, e)),
    };
    if let Some(mut steps) = parse(&text) {
        steps.retain(|step| match step {
            Step::Rename(tmp, target) => still_safe(root, out_dir, tmp, target),
            Step::Remove(_) => true,
        });
        let removed = apply(out_dir, &steps)?;
        super::remove_emptied_folders(out_dir, &removed);
    }
    finish(out_dir)?;
    Ok(true)
}

/// Whether a journalled rename may still be carried out.
fn still_safe(root: &Path, out_dir: &Path, tmp: &str, target: &str) -> bool {
    let tmp_ok = tmp
        .rsplit('/')
        .next()
        .is_some_and(|name| name.starts_with(TMP_PREFIX))
        && std::fs::symlink_metadata(out_dir.join(tmp)).is_ok_and(|m| m.is_file());
    let target_ok = match guard::inspect(root, out_dir, target) {
        Ok(guard::Existing::Nothing) => true,
        Ok(guard::Existing::File(bytes)) => guard::first_line_generated(&bytes),
        Err(_) => false,
    };
    tmp_ok && target_ok
}

/// A temporary's name: `.rcsc-tmp-*`, or `.<name>.rcsc-<pid>.tmp` as
/// rcsc wrote them before this writer (pure).
pub(super) fn is_temporary(name: &str) -> bool {
    let legacy = name
        .strip_prefix('.')
        .and_then(|n| n.strip_suffix(".tmp"))
        .and_then(|n| n.rsplit_once(".rcsc-"))
        .is_some_and(|(_, pid)| !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()));
    name.starts_with(TMP_PREFIX) || legacy
}

/// Remove every temporary below `out_dir` (`.rcsc-tmp-*`, left by a write
/// that was killed), not following symbolic links. Call it with the lock
/// held: the temporaries of a live write are never there then.
pub(super) fn sweep_temporaries(out_dir: &Path) -> Result<Vec<PathBuf>, WriteError> {
    let mut found = Vec::new();
    let mut folders = vec![(out_dir.to_path_buf(), 0)];
    while let Some((dir, depth)) = folders.pop() {
        let entries = match std::fs::read_dir(&dir) {
            Ok(entries) => entries,
            Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
            Err(e) => return Err(io_err(&dir, e)),
        };
        for entry in entries {
            let entry = entry.map_err(|e| io_err(&dir, e))?;
            let path = entry.path();
            let ty = entry.file_type().map_err(|e| io_err(&path, e))?;
            if ty.is_dir() && depth < super::MAX_DEPTH && !guard::another_root(&path) {
                folders.push((path, depth + 1));
            } else if ty.is_file() && is_temporary(&entry.file_name().to_string_lossy()) {
                found.push(path);
            }
        }
    }
    found.sort();
    for path in &found {
        match std::fs::remove_file(path) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => return Err(io_err(path, e)),
            _ => {}
        }
    }
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_journal_reads_back_as_written() {
        let steps = vec![
            Step::Rename("a/.rcsc-tmp-1-0".into(), "a/b%\tc\nd.dot".into()),
            Step::Remove("tables/B.md".into()),
        ];
        assert_eq!(parse(&render(&steps)), Some(steps));
    }

    #[test]
    fn temporaries_are_recognised_by_name() {
        for yes in [
            ".rcsc-tmp-12-0",
            ".rcsc-tmp-1-journal",
            ".PR.md.rcsc-4242.tmp",
        ] {
            assert!(is_temporary(yes), "{yes}");
        }
        for no in [
            "PR.md",
            ".rcsc-lock",
            ".rcsc-journal",
            ".x.rcsc-.tmp",
            "x.rcsc-1.tmp",
        ] {
            assert!(!is_temporary(no), "{no}");
        }
    }

    #[test]
    fn an_incomplete_or_escaping_journal_is_not_trusted() {
        let text = render(&[Step::Remove("x.md".into())]);
        assert_eq!(parse(text.trim_end_matches("end\n")), None);
        assert_eq!(parse(""), None);
        assert_eq!(parse(&render(&[Step::Remove("../x.md".into())])), None);
        assert_eq!(
            parse(&render(&[Step::Rename("t".into(), "/etc/x".into())])),
            None
        );
        assert_eq!(parse("rcsc journal 1\nfrobnicate\tx\nend\n"), None);
    }
}
