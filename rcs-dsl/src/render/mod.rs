//! The last step for diagnostics: text for people and machines. The library
//! renders to strings; only the CLI (or build.rs `Config`) prints them.
//!
//! - `human`: rustc-like snippets (codespan-reporting), colour optional;
//! - `short`: one `file:line:col: severity[code]: message` line;
//! - `json`: one object per line (see [`json`]).
//!
//! Text from the plans (names, messages, file paths, the source lines of a
//! snippet) may hold control characters. The human and short formats show
//! each as an escape ([`escape_controls`]), so that a plan cannot drive the
//! terminal it is checked on; JSON escapes C0 controls by its grammar, and
//! DEL and C1 here as well (`\u007f`, `\u009b`).

use crate::diagnostic::{Diagnostic, Severity};
use crate::source::{FileId, SourceMap, Span};
mod long_lines;

use codespan_reporting::diagnostic as cs;
use codespan_reporting::files::{Error as FilesError, Files};
use codespan_reporting::term;
use serde::Serialize;
use std::borrow::Cow;
use std::ops::Range;

/// `text` with every control character but newline and tab (ESC, the rest
/// of C0, DEL, C1) written as a Rust escape, `\u{1b}`; borrowed when there
/// is none.
pub fn escape_controls(text: &str) -> Cow<'_, str> {
    let shown = |c: char| !c.is_control() || c == '\n' || c == '\t';
    if text.chars().all(shown) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if shown(c) {
            out.push(c);
        } else {
            out.extend(c.escape_unicode());
        }
    }
    Cow::Owned(out)
}

/// JSON text with DEL and the C1 controls, which JSON leaves as they are,
/// escaped as `\u00XX` (they can only stand inside strings).
fn escape_json_controls(json: String) -> String {
    if !json.chars().any(|c| ('\u{7f}'..='\u{9f}').contains(&c)) {
        return json;
    }
    let mut out = String::with_capacity(json.len() + 12);
    for c in json.chars() {
        if ('\u{7f}'..='\u{9f}').contains(&c) {
            out.push_str(&format!("\\u{:04x}", c as u32));
        } else {
            out.push(c);
        }
    }
    out
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Human { color: bool },
    Short,
    Json,
}

/// Render one diagnostic, ending with a newline.
pub fn render(d: &Diagnostic, sources: &SourceMap, format: Format) -> String {
    match format {
        Format::Human { color } => human(d, sources, color),
        Format::Short => short(d, sources),
        Format::Json => {
            let s = serde_json::to_string(&json(d, sources)).expect("diagnostics serialise");
            let mut s = escape_json_controls(s);
            s.push('\n');
            s
        }
    }
}

/// `N errors, M warnings` style summary; `None` when there is nothing to say.
pub fn summary(errors: usize, warnings: usize) -> Option<String> {
    let plural = |n: usize, w: &str| format!("{n} {w}{}", if n == 1 { "" } else { "s" });
    match (errors, warnings) {
        (0, 0) => None,
        (0, w) => Some(format!("warning: {} emitted", plural(w, "warning"))),
        (e, 0) => Some(format!(
            "error: could not check the plans due to {}",
            plural(e, "error")
        )),
        (e, w) => Some(format!(
            "error: could not check the plans due to {}; {} emitted",
            plural(e, "error"),
            plural(w, "warning")
        )),
    }
}

impl<'a> Files<'a> for SourceMap {
    type FileId = FileId;
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, id: FileId) -> Result<&'a str, FilesError> {
        Ok(&self.get(id).path)
    }

    fn source(&'a self, id: FileId) -> Result<&'a str, FilesError> {
        Ok(&self.get(id).text)
    }

    fn line_index(&'a self, id: FileId, byte_index: usize) -> Result<usize, FilesError> {
        Ok(self.get(id).line_col(byte_index).0 - 1)
    }

    fn line_range(&'a self, id: FileId, line_index: usize) -> Result<Range<usize>, FilesError> {
        let f = self.get(id);
        let starts = f.line_starts();
        let start = *starts.get(line_index).ok_or(FilesError::LineTooLarge {
            given: line_index,
            max: starts.len() - 1,
        })?;
        let end = starts.get(line_index + 1).copied().unwrap_or(f.text.len());
        Ok(start..end)
    }
}

fn to_codespan(d: &Diagnostic) -> cs::Diagnostic<FileId> {
    let severity = match d.severity {
        Severity::Error => cs::Severity::Error,
        Severity::Warning => cs::Severity::Warning,
        Severity::Note => cs::Severity::Note,
    };
    let labels = d
        .labels
        .iter()
        .map(|l| {
            let style = if l.primary {
                cs::LabelStyle::Primary
            } else {
                cs::LabelStyle::Secondary
            };
            cs::Label::new(style, l.span.file, l.span.range())
                .with_message(escape_controls(&l.message))
        })
        .collect();
    let mut notes: Vec<String> = d
        .notes
        .iter()
        .map(|n| format!("note: {}", escape_controls(n)))
        .collect();
    if let Some(h) = &d.help {
        notes.push(format!("help: {}", escape_controls(h)));
    }
    cs::Diagnostic::new(severity)
        .with_code(d.code.name())
        .with_message(escape_controls(&d.message))
        .with_labels(labels)
        .with_notes(notes)
}

fn human(d: &Diagnostic, sources: &SourceMap, color: bool) -> String {
    if long_lines::plain(d, sources) {
        return emit(d, sources, color).unwrap_or_else(|| short(d, sources));
    }
    // The lines the labels stand on, long ones cut and controls escaped;
    // the labels moved to match.
    let cut = long_lines::CutFiles::new(d, sources);
    let mut moved = d.clone();
    for l in &mut moved.labels {
        let f = l.span.file;
        let (start, end) = (l.span.start as usize, l.span.end as usize);
        l.span = Span::new(f, cut.shown_offset(f, start), cut.shown_offset(f, end));
    }
    emit(&moved, &cut, color).unwrap_or_else(|| short(d, sources))
}

/// `d` as a rustc-like snippet over `files`, `None` if codespan fails.
fn emit<'f, F>(d: &Diagnostic, files: &'f F, color: bool) -> Option<String>
where
    F: Files<'f, FileId = FileId>,
{
    let config = term::Config {
        chars: term::Chars::ascii(),
        ..term::Config::default()
    };
    let diag = to_codespan(d);
    if color {
        let styles = term::Styles::default();
        let mut ansi = term::termcolor::Ansi::new(Vec::new());
        let ok = {
            let mut w = term::StylesWriter::new(&mut ansi, &styles);
            term::emit_to_write_style(&mut w, &config, files, &diag).is_ok()
        };
        if ok {
            return Some(String::from_utf8_lossy(&ansi.into_inner()).into_owned());
        }
    }
    term::emit_into_string(&config, files, &diag).ok()
}

fn short(d: &Diagnostic, sources: &SourceMap) -> String {
    let span = d.primary_span();
    let f = sources.get(span.file);
    let (line, col) = f.line_col(span.start as usize);
    format!(
        "{}:{line}:{col}: {}[{}]: {}\n",
        escape_controls(&f.path),
        d.severity.as_str(),
        d.code.name(),
        escape_controls(&d.message)
    )
}

/// A position in the JSON format: 1-based lines and columns (in characters).
#[derive(Serialize)]
pub struct JsonLabel {
    pub file: String,
    pub line: usize,
    pub column: usize,
    pub end_line: usize,
    pub end_column: usize,
    pub message: String,
    pub primary: bool,
}

/// The name in every JSON diagnostic's `format` field.
pub const JSON_FORMAT: &str = "rcsc-diagnostic";

/// The version of the JSON diagnostic format (docs/diagnostics-json.md,
/// `docs/diagnostic.schema.json`). A new field readers may ignore keeps it;
/// a field removed, renamed or given another meaning raises it.
pub const JSON_VERSION: u32 = 1;

/// One diagnostic in the JSON format: the fields, their order and their
/// meaning are the documented, versioned schema.
#[derive(Serialize)]
pub struct JsonDiagnostic {
    /// Always [`JSON_FORMAT`]: lets a reader of mixed output tell a
    /// diagnostic from other JSON lines.
    pub format: &'static str,
    /// Always [`JSON_VERSION`].
    pub version: u32,
    pub code: &'static str,
    pub severity: &'static str,
    pub message: String,
    pub file: String,
    pub line: usize,
    pub column: usize,
    pub end_line: usize,
    pub end_column: usize,
    pub labels: Vec<JsonLabel>,
    pub notes: Vec<String>,
    pub help: Option<String>,
    /// The witness of a "can happen" finding: `{state, inputs: [{name, value}]}`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub witness: Option<crate::diagnostic::Witness>,
}

fn position(sources: &SourceMap, span: Span) -> (String, usize, usize, usize, usize) {
    let f = sources.get(span.file);
    let (line, column) = f.line_col(span.start as usize);
    let (end_line, end_column) = f.line_col(span.end as usize);
    (f.path.clone(), line, column, end_line, end_column)
}

/// The JSON object of one diagnostic.
pub fn json(d: &Diagnostic, sources: &SourceMap) -> JsonDiagnostic {
    let (file, line, column, end_line, end_column) = position(sources, d.primary_span());
    JsonDiagnostic {
        format: JSON_FORMAT,
        version: JSON_VERSION,
        code: d.code.name(),
        severity: d.severity.as_str(),
        message: d.message.clone(),
        file,
        line,
        column,
        end_line,
        end_column,
        labels: d
            .labels
            .iter()
            .map(|l| {
                let (file, line, column, end_line, end_column) = position(sources, l.span);
                JsonLabel {
                    file,
                    line,
                    column,
                    end_line,
                    end_column,
                    message: l.message.clone(),
                    primary: l.primary,
                }
            })
            .collect(),
        notes: d.notes.clone(),
        help: d.help.clone(),
        witness: d.witness.clone(),
    }
}
