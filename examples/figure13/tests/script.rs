//! End to end: the figure13 example drives GX through the principal
//! sequence and the exception loop, and ends in Done.

use std::process::Command;

#[test]
fn scripted_events_walk_figure_13_to_done() {
    let out = Command::new(env!("CARGO_BIN_EXE_figure13"))
        .output()
        .expect("run the figure13 example");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "exit {:?}\n{stdout}", out.status);
    assert!(
        stdout.contains("rows fired: E0 E10 E2 E3 E4 E5 E10 E6 E3 E7 E8 E9\n"),
        "{stdout}"
    );
    let transitions: Vec<&str> = stdout
        .lines()
        .filter_map(|l| l.split('|').nth(3).map(str::trim))
        .filter(|t| t.contains("->"))
        .collect();
    assert_eq!(
        transitions,
        [
            "- -> S1",
            "S1 -> S1",
            "S1 -> S1",
            "S1 -> S2",
            "S2 -> S3",
            "S3 -> S3",
            "S3 -> S3",
            "S3 -> S1",
            "S1 -> S2",
            "S2 -> S4",
            "S4 -> S4",
            "S4 -> Done",
            "Done -> Done",
        ],
        "{stdout}"
    );
    assert!(stdout.contains("GX: DONE after 13 cycles"), "{stdout}");
}
