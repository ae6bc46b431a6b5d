//! Unit tests: the submarine plan set's catalog, keys against a fake
//! source, and the view rendered to a `TestBackend`.

use std::path::Path;

use ratatui::backend::TestBackend;
use ratatui::crossterm::event::{KeyCode, KeyEvent};
use ratatui::Terminal;
use rcs_runtime::{ErrorCode, Status};

use crate::catalog::{ArgValue, Catalog};
use crate::model::{ControllerSnapshot, CpuSnapshot, Model, Snapshot};
use crate::source::Source;
use crate::App;

fn submarine() -> Catalog {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../plans/submarine");
    match Catalog::load(&path) {
        Ok(c) => c,
        Err(e) => panic!("{e}"),
    }
}

/// Records what the console asked for.
#[derive(Default)]
struct Fake {
    log: Vec<String>,
}

impl Source for Fake {
    fn snapshot(&mut self) -> Snapshot {
        Snapshot::default()
    }
    fn pause(&mut self, cpu: &str) -> Result<(), String> {
        self.log.push(format!("pause {cpu}"));
        Ok(())
    }
    fn step(&mut self, cpu: &str, n: u64) -> Result<(), String> {
        self.log.push(format!("step {cpu} {n}"));
        Ok(())
    }
    fn resume(&mut self, cpu: &str) -> Result<(), String> {
        self.log.push(format!("resume {cpu}"));
        Ok(())
    }
    fn command(&mut self, root: &str, verb: &str, args: &[ArgValue]) -> Result<u32, String> {
        self.log.push(format!("command {root} {verb} {args:?}"));
        Ok(7)
    }
}

fn snapshot(hits: u64) -> Snapshot {
    let ctrl = |name: &str, verb, state, status, last| ControllerSnapshot {
        name: name.into(),
        cpu: "main".into(),
        has_plans: true,
        verb,
        state,
        status,
        error: ErrorCode::NONE,
        stale_cycles: Some(0),
        exec_last_ns: 1_500,
        exec_max_ns: 9_000,
        last_fired: last,
        hits: vec![vec![0; 4], vec![1, 0, hits, 0]],
        ..ControllerSnapshot::default()
    };
    Snapshot {
        cpus: vec![CpuSnapshot {
            name: "main".into(),
            period_ns: 30_000_000,
            cycle: 42,
            ..CpuSnapshot::default()
        }],
        controllers: vec![
            ctrl("SM", 1, 1, Status::EXECUTING, Some((1, 2, 41))),
            ctrl("PR", 2, 0, Status(Status::FIRST_CUSTOM), None),
            ctrl("TB", 0, 0, Status::NOT_READY, None),
        ],
    }
}

fn key(app: &mut App, source: &mut Fake, code: KeyCode) {
    app.key(KeyEvent::from(code), source);
}

fn screen(app: &App) -> String {
    let mut terminal = Terminal::new(TestBackend::new(160, 20)).expect("test backend");
    terminal.draw(|f| crate::view::draw(f, app)).expect("draw");
    let buf = terminal.backend().buffer();
    let mut out = String::new();
    for y in 0..buf.area.height {
        for x in 0..buf.area.width {
            out.push_str(buf[(x, y)].symbol());
        }
        out.push('\n');
    }
    out
}

#[test]
fn the_catalog_names_roots_verbs_and_rows() {
    let cat = submarine();
    assert_eq!(cat.system, "submarine");
    let roots: Vec<_> = cat.roots().map(|c| c.name.as_str()).collect();
    assert_eq!(roots, ["SM"]);
    let sm = cat.controller("SM").expect("SM");
    assert_eq!(sm.verbs[1].name, "TRANSIT");
    let plan = sm.verbs[1].plan.as_ref().expect("TRANSIT's plan");
    assert_eq!(plan.rows[2].label, "E2");
    assert_eq!(plan.rows[2].from, "S1");
    assert_eq!(plan.rows[2].cond, "PR.status == AT_GOAL");
    assert_eq!(plan.rows[2].to, "S2");
    assert_eq!(
        cat.controller("PR").map(|c| c.status_name(Status(4))),
        Some("AT_GOAL".into())
    );
    assert_eq!(
        cat.check_command("SM", "TRANSIT", &["12.5"]),
        Ok(vec![ArgValue::Float(12.5)])
    );
    let e = cat.check_command("PR", "AHEAD", &["3"]).unwrap_err();
    assert!(e.contains("only roots"), "{e}");
    let e = cat.check_command("SM", "TRANSIT", &["fast"]).unwrap_err();
    assert!(e.contains("speed"), "{e}");
}

#[test]
fn the_view_shows_tree_cpu_plan_and_hits_since_attach() {
    let mut model = Model::new(submarine());
    model.update(snapshot(5));
    model.update(snapshot(8));
    let app = App::new(model);
    let s = screen(&app);
    assert!(
        s.contains("CPU main | RUN | cycle 42 | period 30 ms"),
        "{s}"
    );
    let words: String = s.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        words.contains("│SM TRANSIT S1 EXECUTING NONE 0 1.5/9.0 0 │"),
        "{s}"
    );
    assert!(words.contains("│ PR AHEAD S0 AT_GOAL NONE 0"), "{s}");
    assert!(words.contains("│ TB - - NOT_READY NONE 0"), "{s}");
    assert!(s.contains("│    TB"), "TB under PR under SM: {s}");
    assert!(s.contains("SM: plan TRANSIT, state S1"), "{s}");
    // E2 fired last (marked) and 8 - 5 = 3 times since attach.
    let e2 = s.lines().find(|l| l.contains(">E2")).expect("E2 marked");
    let e2: Vec<&str> = e2.split_whitespace().collect();
    assert!(
        e2.ends_with(&["S1", "PR.status", "==", "AT_GOAL", "S2", "3", "│"]),
        "{e2:?}"
    );
}

#[test]
fn keys_step_pause_filter_and_command_a_root_with_checked_parameters() {
    let mut model = Model::new(submarine());
    model.update(snapshot(0));
    let mut app = App::new(model);
    let mut src = Fake::default();
    key(&mut app, &mut src, KeyCode::Char('s'));
    key(&mut app, &mut src, KeyCode::Char('p'));
    key(&mut app, &mut src, KeyCode::Char('n'));
    for ch in "25".chars() {
        key(&mut app, &mut src, KeyCode::Char(ch));
    }
    key(&mut app, &mut src, KeyCode::Enter);
    assert_eq!(src.log, ["step main 1", "pause main", "step main 25"]);

    // Select TB, then `c`: the command goes to TB's root, SM.
    key(&mut app, &mut src, KeyCode::Down);
    key(&mut app, &mut src, KeyCode::Down);
    assert_eq!(app.selected().as_deref(), Some("TB"));
    key(&mut app, &mut src, KeyCode::Char('c'));
    assert!(screen(&app).contains("command SM: pick a verb"));
    key(&mut app, &mut src, KeyCode::Down);
    key(&mut app, &mut src, KeyCode::Enter);
    for ch in "fast".chars() {
        key(&mut app, &mut src, KeyCode::Char(ch));
    }
    key(&mut app, &mut src, KeyCode::Enter);
    assert!(
        app.message.contains("not a finite number"),
        "{}",
        app.message
    );
    assert_eq!(src.log.len(), 3, "a badly typed parameter is not sent");
    for _ in 0..4 {
        key(&mut app, &mut src, KeyCode::Backspace);
    }
    for ch in "12".chars() {
        key(&mut app, &mut src, KeyCode::Char(ch));
    }
    key(&mut app, &mut src, KeyCode::Enter);
    assert_eq!(src.log[3], "command SM TRANSIT [Float(12.0)]");
    assert!(app.message.contains("serial 7"), "{}", app.message);

    key(&mut app, &mut src, KeyCode::Char('/'));
    key(&mut app, &mut src, KeyCode::Char('p'));
    key(&mut app, &mut src, KeyCode::Enter);
    assert_eq!(app.visible(), [(1, "PR".to_owned())]);
    key(&mut app, &mut src, KeyCode::Char('?'));
    assert!(screen(&app).contains("single step"));
    key(&mut app, &mut src, KeyCode::Char('q'));
    assert!(!app.quit, "a key closes the help first");
    key(&mut app, &mut src, KeyCode::Char('q'));
    assert!(app.quit);
}
