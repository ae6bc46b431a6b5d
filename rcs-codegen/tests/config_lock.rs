//! `Config::compile` (a build script) takes the output folder's lock, as
//! `rcsc build` does, and says so when it has to wait.

use rcs_codegen::writer::OutputLock;
use rcs_codegen::Config;
use std::io::Write;
use std::path::Path;
use std::sync::mpsc::{channel, Sender};
use std::time::Duration;

/// A `Write` that sends what is written, line by line, over a channel.
struct Lines(Sender<String>, Vec<u8>);

impl Write for Lines {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.1.extend_from_slice(buf);
        while let Some(end) = self.1.iter().position(|&b| b == b'\n') {
            let line: Vec<u8> = self.1.drain(..=end).collect();
            let _ = self.0.send(String::from_utf8_lossy(&line).into_owned());
        }
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn a_build_script_waits_for_the_output_lock() {
    let dir = std::env::temp_dir().join(format!("rcs-config-lock-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("plans")).unwrap();
    std::fs::write(
        dir.join("plans/a.rcs"),
        "controller A {\n    command GO\n    plan GO {\n        *0 when new_command -> Done\n    }\n}\n",
    )
    .unwrap();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let held = OutputLock::acquire(&out, &mut |_| {}).unwrap();
    let (tx, rx) = channel();
    let config = Config::new()
        .manifest_dir(&dir)
        .out_dir(&out)
        .rustfmt(false)
        .clone();
    let build = std::thread::spawn(move || {
        let mut diagnostics = Lines(tx, Vec::new());
        config
            .compile_with_io(Path::new("plans"), &mut std::io::sink(), &mut diagnostics)
            .map(|r| r.written.len())
            .map_err(|e| e.to_string())
    });
    let line = rx
        .recv_timeout(Duration::from_secs(120))
        .expect("a line saying it waits");
    assert!(
        line.starts_with("    Blocking waiting for file lock on ") && line.contains("out"),
        "{line}"
    );
    assert!(
        !out.join("tables/A.md").exists(),
        "nothing written while waiting"
    );
    drop(held);
    assert_eq!(
        build.join().unwrap(),
        Ok(5),
        "rust, graph, hierarchy, table, include.rs"
    );
    assert!(out.join("tables/A.md").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}
