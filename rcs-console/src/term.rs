//! The console in a real terminal: raw mode and the alternate screen
//! (crossterm, through ratatui), a snapshot and a redraw about ten times a
//! second, keys to the [`App`]; the terminal is restored on the way out,
//! also when drawing fails.

use std::io;
use std::time::{Duration, Instant};

use ratatui::crossterm::event::{self, Event, KeyEventKind};

use crate::app::App;
use crate::catalog::Catalog;
use crate::model::Model;
use crate::source::Source;

/// How often the console takes a snapshot and redraws.
const REFRESH: Duration = Duration::from_millis(100);

/// Run the console on this terminal until the operator quits.
pub fn run(catalog: Catalog, source: &mut dyn Source) -> io::Result<()> {
    let mut terminal = ratatui::try_init()?;
    let result = run_loop(&mut terminal, catalog, source);
    let restored = ratatui::try_restore();
    result.and(restored)
}

fn run_loop(
    terminal: &mut ratatui::DefaultTerminal,
    catalog: Catalog,
    source: &mut dyn Source,
) -> io::Result<()> {
    let mut app = App::new(Model::new(catalog));
    let mut next = Instant::now();
    loop {
        if Instant::now() >= next {
            app.model.update(source.snapshot());
            terminal.draw(|f| crate::view::draw(f, &app))?;
            next = Instant::now() + REFRESH;
        }
        let wait = next.saturating_duration_since(Instant::now());
        if event::poll(wait)? {
            if let Event::Key(key) = event::read()? {
                if key.kind != KeyEventKind::Release {
                    app.key(key, source);
                    // Show the key's effect at once, with fresh figures.
                    next = Instant::now();
                }
            }
        }
        if app.quit {
            return Ok(());
        }
    }
}
