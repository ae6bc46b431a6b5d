//! Drawing the console with ratatui: a status line per CPU, the hierarchy as
//! a tree coloured by status, the selected controller's plan table, the
//! prompt / message line, and the help overlay.
//!
//! [`draw`] is a pure function of the [`App`]: tests render it to a
//! `TestBackend` and read the buffer.

use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Cell, Clear, Paragraph, Row, Table};
use ratatui::Frame;

use crate::app::{App, Mode};
use crate::model::CpuSnapshot;
use rcs_runtime::Status;

/// The help overlay's lines.
pub const HELP: &[&str] = &[
    "?        this help (any key closes it)",
    "q        quit (Ctrl-C too)",
    "/        filter controllers by name (Enter keeps, Esc in the tree clears)",
    "Up/Down  move the selection; the plan pane shows the selected controller",
    "Enter    select",
    "p        pause / resume the selected controller's CPU",
    "s        single step: pause, then run exactly one cycle",
    "n        run N cycles (prompt), paused after",
    "c        command the selected controller's root: pick a verb, type",
    "         its parameters (checked against their types before sending)",
];

fn micros(ns: u64) -> String {
    format!("{:.1}", ns as f64 / 1_000.0)
}

/// One CPU's status line.
pub fn cpu_line(cpu: &CpuSnapshot) -> String {
    format!(
        "CPU {} | {} | cycle {} | period {} ms | cycle µs {}/{} max | late µs {}/{} max | overruns {} | missed {}",
        cpu.name,
        match (cpu.silent_ms, cpu.paused) {
            (Some(ms), _) => format!("SILENT {:.1} s", ms as f64 / 1e3),
            (None, true) => "PAUSED".into(),
            (None, false) => "RUN".into(),
        },
        cpu.cycle,
        cpu.period_ns as f64 / 1e6,
        micros(cpu.cycle_last_ns),
        micros(cpu.cycle_max_ns),
        micros(cpu.lateness_last_ns),
        micros(cpu.lateness_max_ns),
        cpu.overruns,
        cpu.missed,
    )
}

fn status_colour(status: Status) -> Color {
    match status {
        Status::NOT_READY => Color::DarkGray,
        Status::EXECUTING => Color::Yellow,
        Status::DONE => Color::Green,
        Status::ERROR => Color::Red,
        _ => Color::Cyan,
    }
}

/// Draw the whole console.
pub fn draw(frame: &mut Frame, app: &App) {
    let cpus = app.model.now.cpus.len().max(1) as u16;
    let [title, cpu_area, body, prompt] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Length(cpus),
        Constraint::Min(3),
        Constraint::Length(1),
    ])
    .areas(frame.area());
    frame.render_widget(
        Paragraph::new(format!(
            "rcsc console | system {} | ? help  q quit",
            app.model.catalog.system
        ))
        .style(Style::new().add_modifier(Modifier::BOLD)),
        title,
    );
    let lines: Vec<Line> = app
        .model
        .now
        .cpus
        .iter()
        .map(|c| {
            let style = if c.paused {
                Style::new().fg(Color::Yellow)
            } else {
                Style::new()
            };
            Line::styled(cpu_line(c), style)
        })
        .collect();
    frame.render_widget(Paragraph::new(lines), cpu_area);
    let [tree_area, plan_area] =
        Layout::horizontal([Constraint::Percentage(55), Constraint::Percentage(45)]).areas(body);
    draw_tree(frame, app, tree_area);
    draw_plan(frame, app, plan_area);
    frame.render_widget(Paragraph::new(prompt_line(app)), prompt);
    match &app.mode {
        Mode::Help => draw_popup(frame, "help", HELP.iter().map(|s| s.to_string()).collect()),
        Mode::PickVerb { root, cursor } => {
            let verbs = app
                .model
                .catalog
                .controller(root)
                .map(|c| {
                    c.verbs
                        .iter()
                        .enumerate()
                        .map(|(i, v)| {
                            let params: Vec<String> = v
                                .params
                                .iter()
                                .map(|(n, t)| format!("{n}: {}", t.name()))
                                .collect();
                            let mark = if i == *cursor { ">" } else { " " };
                            format!("{mark} {}({})", v.name, params.join(", "))
                        })
                        .collect()
                })
                .unwrap_or_default();
            draw_popup(frame, &format!("command {root}: pick a verb, Enter"), verbs);
        }
        _ => {}
    }
}

/// The bottom line: the prompt being typed, else the last message.
pub fn prompt_line(app: &App) -> String {
    match &app.mode {
        Mode::Filter => format!("filter: {}_", app.filter),
        Mode::RunN(t) => format!("run how many cycles? {t}_"),
        Mode::Params {
            root,
            verb,
            done,
            input,
        } => {
            let v = app
                .model
                .catalog
                .controller(root)
                .and_then(|c| c.verbs.get(*verb));
            match v.and_then(|v| v.params.get(done.len()).map(|p| (v, p))) {
                Some((v, (name, ty))) => format!(
                    "{root} <- {}: {name} ({}) = {input}_   {}",
                    v.name,
                    ty.name(),
                    app.message
                ),
                None => app.message.clone(),
            }
        }
        _ if !app.filter.is_empty() => format!("[filter: {}] {}", app.filter, app.message),
        _ => app.message.clone(),
    }
}

fn draw_tree(frame: &mut Frame, app: &App, area: Rect) {
    let selected = app.selected();
    let rows: Vec<Row> = app
        .visible()
        .into_iter()
        .map(|(depth, name)| {
            let (verb, state, status, error) = app.model.names(&name);
            let c = app.model.controller(&name);
            let colour = c.map_or(Color::DarkGray, |c| status_colour(c.status));
            let mut style = Style::new().fg(colour);
            if selected.as_deref() == Some(name.as_str()) {
                style = style.add_modifier(Modifier::REVERSED);
            }
            let stale = c
                .and_then(|c| c.stale_cycles)
                .map_or_else(|| "-".into(), |s| s.to_string());
            let timing = c.map_or_else(
                || "-".into(),
                |c| format!("{}/{}", micros(c.exec_last_ns), micros(c.exec_max_ns)),
            );
            Row::new(vec![
                Cell::from(format!("{}{name}", "  ".repeat(depth))),
                Cell::from(verb),
                Cell::from(state),
                Cell::from(status),
                Cell::from(error),
                Cell::from(stale),
                Cell::from(timing),
                Cell::from(c.map_or(0, |c| c.overruns).to_string()),
            ])
            .style(style)
        })
        .collect();
    let widths = [
        Constraint::Length(12),
        Constraint::Length(10),
        Constraint::Length(8),
        Constraint::Length(10),
        Constraint::Length(18),
        Constraint::Length(5),
        Constraint::Length(15),
        Constraint::Length(4),
    ];
    let header = Row::new(vec![
        "controller",
        "verb",
        "state",
        "status",
        "error",
        "stale",
        "µs last/max",
        "ovr",
    ])
    .style(Style::new().add_modifier(Modifier::BOLD));
    frame.render_widget(
        Table::new(rows, widths)
            .header(header)
            .block(Block::new().borders(Borders::ALL).title("hierarchy")),
        area,
    );
}

fn draw_plan(frame: &mut Frame, app: &App, area: Rect) {
    let Some(name) = app.selected() else {
        frame.render_widget(Block::new().borders(Borders::ALL).title("plan"), area);
        return;
    };
    let (_, state, ..) = app.model.names(&name);
    let Some((verb, _, rows)) = app.model.plan_rows(&name) else {
        frame.render_widget(
            Paragraph::new("no active plan (no command yet, or a controller without plans)").block(
                Block::new()
                    .borders(Borders::ALL)
                    .title(format!("{name}: plan")),
            ),
            area,
        );
        return;
    };
    let table_rows: Vec<Row> = rows
        .iter()
        .map(|r| {
            let mut style = Style::new();
            if r.from_current {
                style = style.fg(Color::Cyan);
            }
            if r.last {
                style = style.fg(Color::Black).bg(Color::Yellow);
            }
            Row::new(vec![
                Cell::from(format!(
                    "{}{}",
                    if r.last { ">" } else { " " },
                    r.text.label
                )),
                Cell::from(r.text.from.clone()),
                Cell::from(r.text.cond.clone()),
                Cell::from(r.text.to.clone()),
                Cell::from(r.hits.to_string()),
            ])
            .style(style)
        })
        .collect();
    let widths = [
        Constraint::Length(5),
        Constraint::Length(8),
        Constraint::Fill(1),
        Constraint::Length(26),
        Constraint::Length(6),
    ];
    let header = Row::new(vec![" row", "from", "when", "to", "hits"])
        .style(Style::new().add_modifier(Modifier::BOLD));
    let title = Line::from(vec![
        Span::raw(format!("{name}: plan {verb}, state ")),
        Span::styled(state, Style::new().add_modifier(Modifier::BOLD)),
    ]);
    frame.render_widget(
        Table::new(table_rows, widths)
            .header(header)
            .block(Block::new().borders(Borders::ALL).title(title)),
        area,
    );
}

fn draw_popup(frame: &mut Frame, title: &str, lines: Vec<String>) {
    let area = frame.area();
    let width = lines
        .iter()
        .map(|l| l.chars().count())
        .chain([title.chars().count()])
        .max()
        .unwrap_or(10) as u16
        + 4;
    let height = lines.len() as u16 + 2;
    let popup = Rect {
        x: area.width.saturating_sub(width) / 2,
        y: area.height.saturating_sub(height) / 2,
        width: width.min(area.width),
        height: height.min(area.height),
    };
    frame.render_widget(Clear, popup);
    frame.render_widget(
        Paragraph::new(lines.into_iter().map(Line::from).collect::<Vec<_>>())
            .block(Block::new().borders(Borders::ALL).title(title.to_owned())),
        popup,
    );
}
