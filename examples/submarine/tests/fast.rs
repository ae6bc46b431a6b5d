//! End to end: the submarine example with `--fast` reaches AT_GOAL, and the
//! ship's speed converges inside PR's dead band.

use std::process::{Command, Output};

const ORDERED_KN: f64 = 15.0;
const DEAD_BAND_KN: f64 = 0.1;

fn run(args: &[&str]) -> (Output, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_submarine"))
        .args(args)
        .output()
        .expect("run the submarine example");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    (out, stdout)
}

/// A table row: its cycle, its PR cell and its ship speed.
struct Row {
    cycle: u64,
    pr: String,
    ship_kn: f64,
}

fn rows(stdout: &str) -> Vec<Row> {
    stdout
        .lines()
        .filter_map(|line| {
            let cells: Vec<&str> = line.split('|').map(str::trim).collect();
            let cycle = cells.first()?.parse().ok()?;
            Some(Row {
                cycle,
                pr: cells.get(2)?.to_string(),
                ship_kn: cells.last()?.parse().ok()?,
            })
        })
        .collect()
}

#[test]
fn fast_run_reaches_at_goal_inside_the_dead_band() {
    let (out, stdout) = run(&["--fast"]);
    assert!(out.status.success(), "exit {:?}\n{stdout}", out.status);
    assert!(stdout.contains("PR reports AT_GOAL at cycle"), "{stdout}");
    let rows = rows(&stdout);
    assert!(rows.len() > 5, "{stdout}");
    let last = rows.last().unwrap();
    assert_eq!(last.pr, "AHEAD S1 AT_GOAL", "{stdout}");
    assert!(
        (last.ship_kn - ORDERED_KN).abs() <= DEAD_BAND_KN,
        "last speed {} outside the dead band\n{stdout}",
        last.ship_kn
    );
    // The loop had work to do: the ship started outside the band.
    assert!(rows[0].ship_kn < ORDERED_KN - DEAD_BAND_KN, "{stdout}");
}

#[test]
fn speed_holds_inside_the_dead_band_after_at_goal() {
    let (out, stdout) = run(&["--fast", "--hold", "60", "--every", "1"]);
    assert!(out.status.success(), "exit {:?}\n{stdout}", out.status);
    let rows = rows(&stdout);
    let goal = rows
        .iter()
        .position(|r| r.pr.ends_with("AT_GOAL"))
        .expect("an AT_GOAL row");
    let after = &rows[goal..];
    assert!(after.len() > 60, "{stdout}");
    for row in after {
        assert_eq!(row.pr, "AHEAD S1 AT_GOAL", "cycle {}\n{stdout}", row.cycle);
        assert!(
            (row.ship_kn - ORDERED_KN).abs() <= DEAD_BAND_KN,
            "cycle {}: {} kn outside the dead band\n{stdout}",
            row.cycle,
            row.ship_kn
        );
    }
    // SM saw PR at its goal and holds the transit (TRANSIT's S2).
    assert!(stdout.contains("TRANSIT S2 EXECUTING"), "{stdout}");
}

#[test]
fn too_few_cycles_fail_with_a_message() {
    let (out, stdout) = run(&["--fast", "5"]);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("did not report AT_GOAL within 5 cycles"),
        "{stderr}"
    );
}

/// The README's sample of `--fast` (section "Run the examples"): every line
/// of it is a line of the real output, in the same order (the sample leaves
/// rows out, never changes one).
#[test]
fn the_readme_sample_is_what_fast_prints() {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../README.md"))
        .expect("README.md");
    let start = readme
        .find("```text\ncycle | SM")
        .expect("README.md shows a --fast table")
        + "```text\n".len();
    let end = start + readme[start..].find("```").expect("the block ends");
    let sample: Vec<&str> = readme[start..end].lines().collect();
    let (out, stdout) = run(&["--fast"]);
    assert!(out.status.success(), "exit {:?}\n{stdout}", out.status);
    let mut lines = stdout.lines().map(str::trim_end);
    for want in &sample {
        assert!(
            lines.any(|l| l == want.trim_end()),
            "README.md's --fast sample has a line the run does not print (in this order):\n{want}\n\nthe run printed:\n{stdout}"
        );
    }
}
