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

/// What the terminal shows once the console was quit with `q`.
pub struct Quit {
    /// The shell's screen.
    pub screen: String,
    /// The line the shell printed, `console exit status: N`.
    pub exit_line: Option<String>,
    /// tmux's `#{alternate_on}`: `0` once the console left the alternate
    /// screen.
    pub alternate_on: String,
}

impl Session {
    /// Press `q` and wait for the shell's `console exit status: N` line
    /// (the console runs as `…; echo "console exit status: $?"`; the typed
    /// line holds `status: $?`, the printed one starts with the words).
    pub fn quit(&self) -> Quit {
        self.keys(&["q"]);
        let exited = |s: &str| {
            s.lines()
                .find(|l| l.starts_with("console exit status: "))
                .map(str::to_owned)
        };
        let screen = self.wait_for("the shell", |s| exited(s).is_some());
        let alternate = tmux(&["display-message", "-p", "-t", &self.name, "#{alternate_on}"]);
        Quit {
            exit_line: exited(&screen),
            screen,
            alternate_on: String::from_utf8_lossy(&alternate.stdout).trim().to_owned(),
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
