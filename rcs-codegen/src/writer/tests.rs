//! Unit tests of the [writer](super): each promise, and failures injected
//! part-way (staging errors, a build killed between renames).

use super::*;
use std::cell::Cell;
use std::collections::BTreeMap;

thread_local! {
    static STAGE_FAILS_AT: Cell<Option<usize>> = const { Cell::new(None) };
    static CRASH_AFTER: Cell<Option<usize>> = const { Cell::new(None) };
}

/// An injected I/O error when staging file number `n`.
pub(super) fn fault(what: &str, n: usize) -> Result<(), WriteError> {
    if STAGE_FAILS_AT.get() == Some(n) {
        return Err(io_err(
            Path::new(what),
            io::Error::other("injected failure"),
        ));
    }
    Ok(())
}

/// After how many steps of the commit the build "is killed".
pub(super) fn crash_after() -> Option<usize> {
    CRASH_AFTER.get()
}

pub(super) fn crashed() -> WriteError {
    io_err(Path::new("commit"), io::Error::other("killed"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rcs-writer-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn file(path: &str, body: &str) -> OutputFile {
    OutputFile {
        path: path.to_string(),
        contents: format!("// {GENERATED}\n{body}"),
    }
}

fn quiet(_: &Path) {}

/// Every file below `dir`, relative path → contents.
fn tree(dir: &Path) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let rel = p.strip_prefix(dir).unwrap().to_string_lossy().into_owned();
            if std::fs::symlink_metadata(&p).unwrap().is_dir() {
                stack.push(p);
            } else {
                out.insert(rel, std::fs::read_to_string(&p).unwrap_or_default());
            }
        }
    }
    out
}

#[test]
fn writes_only_what_changed() {
    let dir = scratch("changed");
    let files = [file("a/x.dot", "1"), file("y.md", "2")];
    let r = write_files(&dir, &files, &mut quiet).unwrap();
    assert_eq!(r.written.len(), 2);
    let r = write_files(&dir, &files, &mut quiet).unwrap();
    assert_eq!((r.written.len(), r.unchanged.len()), (0, 2));
    let r = write_files(&dir, &[file("a/x.dot", "3")], &mut quiet).unwrap();
    assert_eq!(r.written, vec![dir.join("a/x.dot")]);
    assert_eq!(
        tree(&dir).into_keys().collect::<Vec<_>>(),
        ["a/x.dot", "y.md"],
        "no lock, journal or temporary left"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn refuses_paths_leaving_the_folder_or_colliding() {
    let dir = scratch("outside");
    for bad in ["../x", "/etc/x", "", "a/../../x"] {
        let err = write_files(&dir, &[file("ok", ""), file(bad, "")], &mut quiet).unwrap_err();
        assert!(matches!(err, WriteError::OutsideOutput(_)), "{bad}");
    }
    let err = write_files(&dir, &[file("a/.rcsc-lock", "")], &mut quiet).unwrap_err();
    assert!(matches!(err, WriteError::Reserved(_)), "{err}");
    let err = write_files(
        &dir,
        &[file("t/PR.md", ""), file("t/Pr.md", "")],
        &mut quiet,
    )
    .unwrap_err();
    assert!(err.to_string().contains("`t/PR.md` and `t/Pr.md`"), "{err}");
    assert!(!dir.join("ok").exists(), "nothing written before the check");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn removes_stale_generated_files_only() {
    let dir = scratch("stale");
    write_tree(
        &dir,
        &[file("graphs/A/GO.dot", ""), file("graphs/h.dot", "")],
        &mut quiet,
    )
    .unwrap();
    std::fs::write(dir.join("graphs/A/notes.txt"), "mine").unwrap();
    std::fs::create_dir_all(dir.join("old")).unwrap();
    std::fs::write(dir.join("old/x.md"), format!("<!-- {GENERATED} -->")).unwrap();
    std::fs::write(dir.join("late.md"), format!("one\n{GENERATED}")).unwrap();
    let r = write_tree(&dir, &[file("graphs/h.dot", "")], &mut quiet).unwrap();
    assert_eq!(
        r.removed,
        vec![dir.join("graphs/A/GO.dot"), dir.join("old/x.md")]
    );
    assert!(dir.join("graphs/A/notes.txt").exists(), "no marker: kept");
    assert!(
        dir.join("late.md").exists(),
        "marker not on the first line: kept"
    );
    assert!(!dir.join("old").exists(), "emptied folder removed");
    assert!(dir.join("graphs/A").exists(), "non-empty folder kept");
    assert!(dir.join("graphs/h.dot").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_missing_output_folder_is_created() {
    let dir = scratch("missing").join("deep/er");
    let r = write_tree(&dir, &[file("x.dot", "")], &mut quiet).unwrap();
    assert_eq!(r.written.len(), 1);
    assert!(r.removed.is_empty());
    let _ = std::fs::remove_dir_all(dir.parent().unwrap().parent().unwrap());
}

#[test]
fn a_hand_written_file_is_never_overwritten() {
    let dir = scratch("hand");
    write_tree(
        &dir,
        &[file("tables/A.md", "old"), file("x.dot", "old")],
        &mut quiet,
    )
    .unwrap();
    std::fs::write(dir.join("tables/PR.md"), "# my notes\n").unwrap();
    let before = tree(&dir);
    let err = write_tree(
        &dir,
        &[file("tables/PR.md", "new"), file("x.dot", "new")],
        &mut quiet,
    )
    .unwrap_err();
    assert!(
        matches!(&err, WriteError::NotGenerated(p) if p.len() == 1),
        "{err}"
    );
    let message = err.to_string();
    assert!(message.contains("tables/PR.md"), "{message}");
    assert!(message.contains("nothing was written"), "{message}");
    assert_eq!(tree(&dir), before, "nothing written, nothing removed");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_failure_while_staging_leaves_the_old_outputs_whole() {
    let dir = scratch("stage-fails");
    let old = [
        file("a/x.dot", "old"),
        file("b.md", "old"),
        file("gone.md", ""),
    ];
    write_tree(&dir, &old, &mut quiet).unwrap();
    let before = tree(&dir);
    let new = [
        file("a/x.dot", "new"),
        file("b.md", "new"),
        file("c/d/e.md", "new"),
    ];
    for at in 0..3 {
        STAGE_FAILS_AT.set(Some(at));
        let err = write_tree(&dir, &new, &mut quiet).unwrap_err();
        STAGE_FAILS_AT.set(None);
        assert!(err.to_string().contains("injected"), "{err}");
        assert_eq!(
            tree(&dir),
            before,
            "failing at {at}: the old outputs, no temporaries"
        );
        assert!(!dir.join("c").exists(), "folders made for it removed");
    }
    write_tree(&dir, &new, &mut quiet).unwrap();
    assert_eq!(tree(&dir).len(), 3);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_build_killed_while_renaming_is_finished_by_the_next() {
    let old = [
        file("a.md", "old"),
        file("b/c.md", "old"),
        file("d.md", "old"),
    ];
    let new = [
        file("a.md", "new"),
        file("b/c.md", "new"),
        file("e.md", "new"),
    ];
    let complete = |dir: &Path| {
        let t = tree(dir);
        assert_eq!(t.keys().collect::<Vec<_>>(), ["a.md", "b/c.md", "e.md"]);
        assert!(t.values().all(|v| v.ends_with("new")), "{t:?}");
    };
    // Killed before the first step, between any two, or after the last.
    for k in 0..=4 {
        let dir = scratch(&format!("killed-{k}"));
        write_tree(&dir, &old, &mut quiet).unwrap();
        CRASH_AFTER.set(Some(k));
        assert!(write_tree(&dir, &new, &mut quiet).is_err());
        CRASH_AFTER.set(None);
        assert!(
            dir.join(JOURNAL_FILE).exists(),
            "the journal says a build is unfinished"
        );
        // The next build, of another version, first finishes the killed one.
        let r = write_tree(&dir, &old[..1], &mut quiet).unwrap();
        assert!(r.recovered);
        assert!(r.swept.is_empty(), "every temporary was in the journal");
        let t = tree(&dir);
        assert_eq!(t.keys().collect::<Vec<_>>(), ["a.md"], "{k}: {t:?}");
        // And a build of the same version finds it done.
        let dir2 = scratch(&format!("killed-same-{k}"));
        write_tree(&dir2, &old, &mut quiet).unwrap();
        CRASH_AFTER.set(Some(k));
        assert!(write_tree(&dir2, &new, &mut quiet).is_err());
        CRASH_AFTER.set(None);
        let r = write_tree(&dir2, &new, &mut quiet).unwrap();
        assert!(r.recovered && r.written.is_empty(), "{r:?}");
        complete(&dir2);
        let _ = std::fs::remove_dir_all(&dir);
        let _ = std::fs::remove_dir_all(&dir2);
    }
}

#[test]
fn stray_temporaries_are_swept_and_a_bad_journal_is_dropped() {
    let dir = scratch("stray");
    write_tree(&dir, &[file("a/b.md", "")], &mut quiet).unwrap();
    std::fs::write(dir.join("a/.rcsc-tmp-999-0"), "").unwrap();
    std::fs::write(dir.join(".rcsc-tmp-999-journal"), "rcsc journal 1\n").unwrap();
    std::fs::write(dir.join(JOURNAL_FILE), "rcsc journal 1\nremove\ta/b.md\n").unwrap();
    let r = write_tree(&dir, &[file("a/b.md", "")], &mut quiet).unwrap();
    assert!(r.recovered);
    assert_eq!(r.swept.len(), 2);
    assert_eq!(tree(&dir).into_keys().collect::<Vec<_>>(), ["a/b.md"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn links_leading_out_are_refused_and_links_inside_followed() {
    use std::os::unix::fs::symlink;
    let dir = scratch("links");
    let out = dir.join("out");
    let elsewhere = dir.join("elsewhere");
    std::fs::create_dir_all(out.join("graphs")).unwrap();
    std::fs::create_dir_all(&elsewhere).unwrap();
    symlink("../../elsewhere", out.join("graphs/PR")).unwrap();
    let err = write_tree(
        &out,
        &[file("graphs/PR/GO.dot", ""), file("a.md", "")],
        &mut quiet,
    )
    .unwrap_err();
    assert!(matches!(err, WriteError::Symlink { .. }), "{err}");
    assert!(err.to_string().contains("graphs/PR"), "{err}");
    assert!(tree(&elsewhere).is_empty() && !out.join("a.md").exists());
    // A linked file leading out.
    std::fs::remove_file(out.join("graphs/PR")).unwrap();
    std::fs::write(elsewhere.join("t.md"), format!("{GENERATED}\n")).unwrap();
    symlink(elsewhere.join("t.md"), out.join("t.md")).unwrap();
    let err = write_tree(&out, &[file("t.md", "")], &mut quiet).unwrap_err();
    assert!(matches!(err, WriteError::Symlink { .. }), "{err}");
    std::fs::remove_file(out.join("t.md")).unwrap();
    // Stale generated files behind a link are never removed.
    symlink(&elsewhere, out.join("linked")).unwrap();
    write_tree(&out, &[file("a.md", "")], &mut quiet).unwrap();
    assert!(elsewhere.join("t.md").exists());
    // The output folder itself behind a link is fine, and so is a link inside.
    std::fs::remove_file(out.join("linked")).unwrap();
    symlink(&out, dir.join("via")).unwrap();
    std::fs::create_dir_all(out.join("real")).unwrap();
    symlink("real", out.join("alias")).unwrap();
    write_tree(&dir.join("via"), &[file("alias/x.md", "")], &mut quiet).unwrap();
    assert!(out.join("real/x.md").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_folder_where_a_file_goes_is_refused_before_anything_changes() {
    let dir = scratch("in-the-way");
    write_tree(
        &dir,
        &[file("a.md", "old"), file("b.md", "old")],
        &mut quiet,
    )
    .unwrap();
    std::fs::create_dir_all(dir.join("c.md")).unwrap();
    let before = tree(&dir);
    let err = write_tree(&dir, &[file("a.md", "new"), file("c.md", "")], &mut quiet).unwrap_err();
    assert!(matches!(err, WriteError::InTheWay { .. }), "{err}");
    assert_eq!(tree(&dir), before);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_second_writer_waits_for_the_lock() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let dir = scratch("lock");
    let held = OutputLock::acquire(&dir, &mut quiet).unwrap();
    let waited = Arc::new(AtomicBool::new(false));
    let (d, w) = (dir.clone(), waited.clone());
    let other = std::thread::spawn(move || {
        write_files(&d, &[file("x.md", "")], &mut |_| {
            w.store(true, Ordering::SeqCst)
        })
        .unwrap()
    });
    // Bounded: the other writer reports that it waits, then we let go.
    for _ in 0..3000 {
        if waited.load(Ordering::SeqCst) {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(
        waited.load(Ordering::SeqCst),
        "the second writer said it was blocked"
    );
    assert!(
        !dir.join("x.md").exists(),
        "and wrote nothing while blocked"
    );
    drop(held);
    let report = other.join().unwrap();
    assert_eq!(report.written, vec![dir.join("x.md")]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn recovery_checks_again_what_changed_since_the_crash() {
    let dir = scratch("recheck");
    write_tree(
        &dir,
        &[file("a.md", "old"), file("b.md", "old")],
        &mut quiet,
    )
    .unwrap();
    CRASH_AFTER.set(Some(0));
    assert!(write_tree(
        &dir,
        &[file("a.md", "new"), file("b.md", "new")],
        &mut quiet
    )
    .is_err());
    CRASH_AFTER.set(None);
    // Meanwhile someone writes b.md by hand.
    std::fs::write(dir.join("b.md"), "mine\n").unwrap();
    let r = write_files(&dir, &[file("c.md", "")], &mut quiet).unwrap();
    assert!(r.recovered);
    assert_eq!(r.swept.len(), 1, "b.md's temporary, not renamed");
    assert!(tree(&dir)["a.md"].ends_with("new"));
    assert_eq!(tree(&dir)["b.md"], "mine\n", "the hand-written file kept");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_folder_another_build_is_writing_is_left_to_it() {
    let dir = scratch("nested");
    write_tree(&dir, &[file("a.md", "")], &mut quiet).unwrap();
    let inner = dir.join("inner");
    std::fs::create_dir_all(&inner).unwrap();
    let held = OutputLock::acquire(&inner, &mut quiet).unwrap();
    std::fs::write(inner.join(".rcsc-tmp-1-0"), "").unwrap();
    std::fs::write(inner.join("x.md"), format!("{GENERATED}\n")).unwrap();
    let r = write_tree(&dir, &[file("a.md", "")], &mut quiet).unwrap();
    assert!(r.swept.is_empty() && r.removed.is_empty(), "{r:?}");
    drop(held);
    // On Unix the lock file goes with the lock; elsewhere it stays, and
    // the folder stays another build's.
    if cfg!(unix) {
        let r = write_tree(&dir, &[file("a.md", "")], &mut quiet).unwrap();
        assert_eq!((r.swept.len(), r.removed.len()), (1, 1), "{r:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn one_named_file_follows_the_rules_of_a_build() {
    let dir = scratch("single");
    let inputs_dir = dir.join("plans");
    std::fs::create_dir_all(&inputs_dir).unwrap();
    let plan = inputs_dir.join("a.rcs");
    std::fs::write(&plan, format!("// {GENERATED}, says the plan\n")).unwrap();
    let mut inputs = Inputs::new();
    inputs.add(&plan);
    let body = format!("// {GENERATED}\nnew\n");

    // A file read is refused, under any name, marker or not.
    let err = write_file(&plan, &body, &inputs, &mut quiet).unwrap_err();
    assert!(matches!(err, WriteError::Input { .. }), "{err}");
    let other_name = inputs_dir.join("../plans/a.rcs");
    assert!(write_file(&other_name, &body, &inputs, &mut quiet).is_err());
    #[cfg(unix)]
    {
        let hard = dir.join("hard.rcs");
        std::fs::hard_link(&plan, &hard).unwrap();
        assert!(write_file(&hard, &body, &inputs, &mut quiet).is_err());
    }
    assert!(std::fs::read_to_string(&plan)
        .unwrap()
        .ends_with("says the plan\n"));

    // A hand-written file is refused; a folder is in the way.
    let out = dir.join("out.txt");
    std::fs::write(&out, "mine\n").unwrap();
    let err = write_file(&out, &body, &inputs, &mut quiet).unwrap_err();
    assert!(matches!(err, WriteError::NotGenerated(_)), "{err}");
    assert_eq!(err.code(), Some("not_generated"));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "mine\n");
    let err = write_file(&inputs_dir, &body, &Inputs::new(), &mut quiet).unwrap_err();
    assert!(matches!(err, WriteError::InTheWay { .. }), "{err}");

    // Its own output is replaced, unchanged bytes are left alone, and no
    // lock or temporary is left behind.
    std::fs::remove_file(&out).unwrap();
    let report = write_file(&out, &body, &inputs, &mut quiet).unwrap();
    assert_eq!(report.written, vec![out.clone()]);
    let report = write_file(&out, &body, &inputs, &mut quiet).unwrap();
    assert_eq!(report.unchanged, vec![out.clone()]);
    let newer = format!("// {GENERATED}\nnewer\n");
    write_file(&out, &newer, &inputs, &mut quiet).unwrap();
    assert_eq!(std::fs::read_to_string(&out).unwrap(), newer);
    let left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(RESERVED_PREFIX))
        .collect();
    assert!(left.is_empty(), "{left:?}");

    // A link to a generated file is followed: the file it names is replaced.
    #[cfg(unix)]
    {
        let link = dir.join("link.txt");
        std::os::unix::fs::symlink("out.txt", &link).unwrap();
        write_file(&link, &body, &inputs, &mut quiet).unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&out).unwrap(), body);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// An MCAP recording's magic bytes end in a newline: its marker is looked
/// for in its header's `library` field instead of its first line.
#[test]
fn the_marker_of_an_mcap_recording_is_in_its_header() {
    fn mcap(profile: &str, library: &str) -> Vec<u8> {
        let mut b = b"\x89MCAP0\r\n".to_vec();
        b.push(0x01);
        let len = 8 + profile.len() + library.len();
        b.extend_from_slice(&(len as u64).to_le_bytes());
        for s in [profile, library] {
            b.extend_from_slice(&(s.len() as u32).to_le_bytes());
            b.extend_from_slice(s.as_bytes());
        }
        b.extend_from_slice(b"\n@generated by rcsc, but in a message");
        b
    }
    let library = "@generated by rcsc test --trace; rcs-runtime 0.1.0";
    let ours = mcap("", library);
    assert!(super::guard::first_line_generated(&ours));
    // Only the library field counts: not the profile, not later bytes.
    assert!(!super::guard::first_line_generated(&mcap(
        "@generated by rcsc",
        "another"
    )));
    assert!(!super::guard::first_line_generated(&mcap("", "mcap-rs")));
    // Cut short inside the header: not generated, no panic.
    let header_end = 8 + 1 + 8 + 4 + 4 + library.len();
    for len in 0..header_end {
        assert!(!super::guard::first_line_generated(&ours[..len]), "{len}");
    }
    assert!(super::guard::first_line_generated(&ours[..header_end]));
}
