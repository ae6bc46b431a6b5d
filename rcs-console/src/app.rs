//! The console's interaction state and what each key does: selection,
//! filter, prompts (run N, command parameters), help, quit.
//!
//! Pure apart from the [`Source`] the actions go to, so that tests drive it
//! with a fake source and keys, then render it to a `TestBackend`.

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

use crate::catalog::check_arg;
use crate::model::Model;
use crate::source::Source;

/// What the keyboard is doing now.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Mode {
    /// Browsing the tree.
    #[default]
    Normal,
    /// The help overlay is open.
    Help,
    /// Typing a filter after `/`.
    Filter,
    /// Typing N after `n`.
    RunN(String),
    /// Picking a verb of `root` after `c`.
    PickVerb {
        /// The root to command.
        root: String,
        /// The verb under the cursor.
        cursor: usize,
    },
    /// Typing the parameters of `root`'s `verb`, one at a time.
    Params {
        /// The root to command.
        root: String,
        /// The verb's index in the catalog.
        verb: usize,
        /// The parameters typed so far (checked).
        done: Vec<String>,
        /// The parameter being typed.
        input: String,
    },
}

/// The console's state. See the module docs.
#[derive(Debug, Default)]
pub struct App {
    /// What is shown.
    pub model: Model,
    /// The selected controller's position among the visible ones.
    pub cursor: usize,
    /// Show only controllers whose name contains this (case-insensitive).
    pub filter: String,
    /// What the keyboard is doing.
    pub mode: Mode,
    /// The last thing said to the operator (an action's result, an error).
    pub message: String,
    /// Set by `q`: the console should exit.
    pub quit: bool,
}

impl App {
    /// A console over `model`.
    pub fn new(model: Model) -> Self {
        Self {
            model,
            message: "? help  q quit".into(),
            ..Self::default()
        }
    }

    /// The controllers shown, in tree order with their depth.
    pub fn visible(&self) -> Vec<(usize, String)> {
        let filter = self.filter.to_lowercase();
        self.model
            .tree()
            .into_iter()
            .filter(|(_, n)| n.to_lowercase().contains(&filter))
            .collect()
    }

    /// The selected controller's name.
    pub fn selected(&self) -> Option<String> {
        let v = self.visible();
        v.get(self.cursor.min(v.len().saturating_sub(1)))
            .map(|(_, n)| n.clone())
    }

    /// The CPU of the selected controller (else the first CPU).
    fn selected_cpu(&self) -> Option<String> {
        self.selected()
            .and_then(|n| self.model.controller(&n).map(|c| c.cpu.clone()))
            .or_else(|| self.model.now.cpus.first().map(|c| c.name.clone()))
    }

    /// The root above the selected controller (the chain of command: only
    /// roots take the operator's commands).
    fn selected_root(&self) -> Option<String> {
        let mut name = self.selected()?;
        for _ in 0..64 {
            match self
                .model
                .catalog
                .controller(&name)
                .and_then(|c| c.supervisor.clone())
            {
                Some(sup) => name = sup,
                None => return Some(name),
            }
        }
        None
    }

    /// Act on one key.
    pub fn key(&mut self, key: KeyEvent, source: &mut dyn Source) {
        if key.modifiers.contains(KeyModifiers::CONTROL) && key.code == KeyCode::Char('c') {
            self.quit = true;
            return;
        }
        match std::mem::take(&mut self.mode) {
            Mode::Normal => self.normal_key(key.code, source),
            Mode::Help => {}
            Mode::Filter => match key.code {
                KeyCode::Enter | KeyCode::Esc => self.cursor = 0,
                KeyCode::Backspace => {
                    self.filter.pop();
                    self.mode = Mode::Filter;
                }
                KeyCode::Char(ch) => {
                    self.filter.push(ch);
                    self.cursor = 0;
                    self.mode = Mode::Filter;
                }
                _ => self.mode = Mode::Filter,
            },
            Mode::RunN(mut text) => match key.code {
                KeyCode::Esc => self.message = "run N: cancelled".into(),
                KeyCode::Enter => match text.trim().parse::<u64>() {
                    Ok(n) if n > 0 => {
                        self.run(source, |s, cpu| s.step(cpu, n), &format!("run {n}"))
                    }
                    _ => self.message = format!("run N: `{text}` is not a positive number"),
                },
                KeyCode::Backspace => {
                    text.pop();
                    self.mode = Mode::RunN(text);
                }
                KeyCode::Char(ch) => {
                    text.push(ch);
                    self.mode = Mode::RunN(text);
                }
                _ => self.mode = Mode::RunN(text),
            },
            Mode::PickVerb { root, cursor } => self.pick_verb_key(key.code, root, cursor),
            Mode::Params {
                root,
                verb,
                done,
                input,
            } => self.params_key(key.code, source, root, verb, done, input),
        }
    }

    fn normal_key(&mut self, code: KeyCode, source: &mut dyn Source) {
        let count = self.visible().len();
        match code {
            KeyCode::Char('q') => self.quit = true,
            KeyCode::Char('?') => self.mode = Mode::Help,
            KeyCode::Char('/') => {
                self.filter.clear();
                self.mode = Mode::Filter;
            }
            KeyCode::Up => self.cursor = self.cursor.saturating_sub(1),
            KeyCode::Down => self.cursor = (self.cursor + 1).min(count.saturating_sub(1)),
            KeyCode::Enter => {
                if let Some(name) = self.selected() {
                    self.message = format!("selected {name}");
                }
            }
            KeyCode::Esc => self.filter.clear(),
            KeyCode::Char('p') => {
                let paused = self
                    .selected_cpu()
                    .and_then(|c| self.model.cpu(&c).map(|c| c.paused))
                    .unwrap_or(false);
                if paused {
                    self.run(source, |s, cpu| s.resume(cpu), "resume");
                } else {
                    self.run(source, |s, cpu| s.pause(cpu), "pause");
                }
            }
            KeyCode::Char('s') => self.run(source, |s, cpu| s.step(cpu, 1), "single step"),
            KeyCode::Char('n') => self.mode = Mode::RunN(String::new()),
            KeyCode::Char('c') => match self.selected_root() {
                Some(root) => {
                    if self
                        .model
                        .catalog
                        .controller(&root)
                        .is_some_and(|c| !c.verbs.is_empty())
                    {
                        self.mode = Mode::PickVerb { root, cursor: 0 };
                    } else {
                        self.message = format!("{root} has no verbs to command");
                    }
                }
                None => self.message = "no controller selected".into(),
            },
            _ => {}
        }
    }

    fn pick_verb_key(&mut self, code: KeyCode, root: String, cursor: usize) {
        let verbs = self
            .model
            .catalog
            .controller(&root)
            .map_or(0, |c| c.verbs.len());
        match code {
            KeyCode::Esc => self.message = "command: cancelled".into(),
            KeyCode::Up => {
                self.mode = Mode::PickVerb {
                    root,
                    cursor: cursor.saturating_sub(1),
                }
            }
            KeyCode::Down => {
                self.mode = Mode::PickVerb {
                    root,
                    cursor: (cursor + 1).min(verbs.saturating_sub(1)),
                }
            }
            KeyCode::Enter => {
                self.mode = Mode::Params {
                    root,
                    verb: cursor,
                    done: Vec::new(),
                    input: String::new(),
                }
            }
            _ => self.mode = Mode::PickVerb { root, cursor },
        }
        // A verb without parameters is sent at once.
        if let Mode::Params { .. } = &self.mode {
            self.mode = self.maybe_send_params(None);
        }
    }

    fn params_key(
        &mut self,
        code: KeyCode,
        source: &mut dyn Source,
        root: String,
        verb: usize,
        mut done: Vec<String>,
        mut input: String,
    ) {
        match code {
            KeyCode::Esc => {
                self.message = "command: cancelled".into();
                return;
            }
            KeyCode::Backspace => {
                input.pop();
            }
            KeyCode::Char(ch) => input.push(ch),
            KeyCode::Enter => {
                let ty = self
                    .model
                    .catalog
                    .controller(&root)
                    .and_then(|c| c.verbs.get(verb))
                    .and_then(|v| v.params.get(done.len()))
                    .map(|(name, ty)| (name.clone(), ty.clone()));
                if let Some((name, ty)) = ty {
                    match check_arg(&ty, input.trim()) {
                        Ok(_) => {
                            done.push(std::mem::take(&mut input));
                            self.message.clear();
                        }
                        Err(e) => self.message = format!("{name}: {e}"),
                    }
                }
            }
            _ => {}
        }
        self.mode = Mode::Params {
            root,
            verb,
            done,
            input,
        };
        self.mode = self.maybe_send_params(Some(source));
    }

    /// With every parameter typed, check the command and send it (when a
    /// source is given); else stay in the prompt.
    fn maybe_send_params(&mut self, source: Option<&mut dyn Source>) -> Mode {
        let Mode::Params {
            root, verb, done, ..
        } = &self.mode
        else {
            return std::mem::take(&mut self.mode);
        };
        let Some(v) = self
            .model
            .catalog
            .controller(root)
            .and_then(|c| c.verbs.get(*verb))
        else {
            self.message = format!("{root}: no such verb");
            return Mode::Normal;
        };
        if done.len() < v.params.len() {
            return std::mem::take(&mut self.mode);
        }
        let Some(source) = source else {
            // Picked a verb without parameters: send on the next key is
            // wrong; ask for Enter to confirm instead.
            self.message = format!("{root} <- {}: Enter sends, Esc cancels", v.name);
            return std::mem::take(&mut self.mode);
        };
        let args: Vec<&str> = done.iter().map(String::as_str).collect();
        let (root, name) = (root.clone(), v.name.clone());
        self.message = match self.model.catalog.check_command(&root, &name, &args) {
            Err(e) => format!("{root} <- {name}: {e}"),
            Ok(values) => match source.command(&root, &name, &values) {
                Ok(serial) => format!("sent {root} <- {name}({}) serial {serial}", args.join(", ")),
                Err(e) => format!("{root} <- {name} not sent: {e}"),
            },
        };
        Mode::Normal
    }

    /// Run an executive action on the selected controller's CPU.
    fn run(
        &mut self,
        source: &mut dyn Source,
        action: impl FnOnce(&mut dyn Source, &str) -> Result<(), String>,
        what: &str,
    ) {
        let Some(cpu) = self.selected_cpu() else {
            self.message = format!("{what}: no executive");
            return;
        };
        self.message = match action(source, &cpu) {
            Ok(()) => format!("{what}: {cpu}"),
            Err(e) => format!("{what}: {e}"),
        };
    }
}
