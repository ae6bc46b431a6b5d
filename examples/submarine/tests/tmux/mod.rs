//! Driving a terminal UI through tmux as a person would (`send-keys`,
//! `capture-pane`), and reading the console's screen: shared by the
//! console tests of this example and of `submarine-split`
//! (`#[path]`-included there).

#![allow(dead_code)] // each test includes what it uses

use std::process::{Command, Output};
use std::thread::sleep;
use std::time::{Duration, Instant};

pub fn tmux(args: &[&str]) -> Output {
    match Command::new("tmux").args(args).output() {
        Ok(out) => out,
        Err(e) => panic!("tmux {args:?}: {e}"),
    }
}

/// A tmux session killed when the test ends, however it ends; `wait_for`
/// gives up after `deadline`.
pub struct Session {
    pub name: String,
    pub deadline: Duration,
}

impl Session {
    pub fn screen(&self) -> String {
        String::from_utf8_lossy(&tmux(&["capture-pane", "-p", "-t", &self.name]).stdout)
            .into_owned()
    }

    pub fn keys(&self, keys: &[&str]) {
        let mut args = vec!["send-keys", "-t", &self.name];
        args.extend_from_slice(keys);
        assert!(tmux(&args).status.success(), "send-keys {keys:?}");
    }

    pub fn type_text(&self, text: &str) {
        assert!(
            tmux(&["send-keys", "-t", &self.name, "-l", text])
                .status
                .success(),
            "send-keys -l {text:?}"
        );
    }

    /// Poll the screen until `ok` holds; the screen then, or a panic with
    /// the last screen at the deadline.
    pub fn wait_for(&self, what: &str, mut ok: impl FnMut(&str) -> bool) -> String {
        let start = Instant::now();
        loop {
            let screen = self.screen();
            if ok(&screen) {
                return screen;
            }
            if start.elapsed() > self.deadline {
                panic!(
                    "waited {:?} for {what}; the screen:\n{screen}",
                    self.deadline
                );
            }
            sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        let _ = Command::new("tmux")
            .args(["kill-session", "-t", &self.name])
            .output();
    }
}

/// The cycle count on the `CPU NAME` line.
pub fn cycle(screen: &str, cpu: &str) -> Option<u64> {
    let line = screen
        .lines()
        .find(|l| l.starts_with(&format!("CPU {cpu} |")))?;
    let rest = &line[line.find("| cycle ")? + "| cycle ".len()..];
    rest.split_whitespace().next()?.parse().ok()
}

/// The tree row of `name` (the line whose first cell is `name`, indented).
pub fn tree_row<'a>(screen: &'a str, indent: usize, name: &str) -> Option<&'a str> {
    let cell = format!("│{}{name} ", " ".repeat(indent));
    screen.lines().find(|l| l.starts_with(&cell))
}

/// The `stale` cell of a tree row (columns: name, verb, state, status,
/// error, stale, timing, overruns; each one word).
pub fn stale(row: &str) -> Option<u64> {
    let cells: Vec<&str> = row.trim_matches('│').split_whitespace().collect();
    cells.get(5)?.parse().ok()
}

pub fn tmux_available() -> bool {
    Command::new("tmux")
        .arg("-V")
        .output()
        .is_ok_and(|o| o.status.success())
}
