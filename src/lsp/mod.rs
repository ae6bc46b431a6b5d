//! `rcsc lsp`: the language server, JSON-RPC over stdio (lsp-server and
//! lsp-types, as rust-analyzer's own crates).
//!
//! It sits beside the other commands, over the same library pipeline: each
//! edit re-checks the open file's plan set with the editor's texts
//! ([`documents`]) and publishes the diagnostics `rcsc check` would print —
//! same codes, spans, notes and help, secondary labels and witnesses as
//! related information. Navigation ([`navigate`]) reads the checked IR's
//! spans: definition, references, hover, document symbols, completion;
//! formatting is `rcsc fmt`'s (rcs-dsl's `fmt`).
//! Positions are UTF-16, as LSP defaults to ([`position`]).
//!
//! The server is synchronous: one message at a time, a check per edit.
//! Checking a 100-controller plan set takes milliseconds (BENCHMARKS.md),
//! so there is nothing to cancel.

mod actions;
mod documents;
mod navigate;
mod position;
mod symbols;
mod tokens;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use lsp_server::{Connection, ErrorCode, Message, Notification, Request, Response};
use lsp_types::notification::{
    DidChangeTextDocument, DidCloseTextDocument, DidOpenTextDocument, Notification as _,
    PublishDiagnostics,
};
use lsp_types::request::{
    CodeActionRequest, Completion, DocumentSymbolRequest, Formatting, GotoDefinition, HoverRequest,
    References, Request as _, SemanticTokensFullRequest,
};
use lsp_types::{
    CodeActionProviderCapability, CompletionOptions, CompletionResponse,
    DiagnosticRelatedInformation, DiagnosticSeverity, DocumentSymbolResponse,
    GotoDefinitionResponse, Hover, HoverContents, HoverProviderCapability, Location, MarkupContent,
    MarkupKind, NumberOrString, OneOf, PositionEncodingKind, PublishDiagnosticsParams,
    SemanticTokensFullOptions, SemanticTokensOptions, SemanticTokensResult, ServerCapabilities,
    TextDocumentPositionParams, TextDocumentSyncCapability, TextDocumentSyncKind, Uri,
};
use rcs_dsl::source::{FileId, Span};
use rcs_dsl::{Diagnostic, Severity};

use documents::{analyse, Analysis, Documents};
use position::LineIndex;

/// Serve on stdin/stdout until the client says `exit`.
pub fn lsp() -> ExitCode {
    let (connection, io_threads) = Connection::stdio();
    let served = serve(&connection);
    drop(connection);
    let joined = io_threads.join();
    match served
        .map_err(|e| e.to_string())
        .and(joined.map_err(|e| e.to_string()))
    {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rcsc lsp: {e}");
            ExitCode::from(2)
        }
    }
}

fn capabilities() -> ServerCapabilities {
    ServerCapabilities {
        position_encoding: Some(PositionEncodingKind::UTF16),
        text_document_sync: Some(TextDocumentSyncCapability::Kind(TextDocumentSyncKind::FULL)),
        hover_provider: Some(HoverProviderCapability::Simple(true)),
        definition_provider: Some(OneOf::Left(true)),
        references_provider: Some(OneOf::Left(true)),
        document_symbol_provider: Some(OneOf::Left(true)),
        completion_provider: Some(CompletionOptions::default()),
        document_formatting_provider: Some(OneOf::Left(true)),
        code_action_provider: Some(CodeActionProviderCapability::Simple(true)),
        semantic_tokens_provider: Some(
            SemanticTokensOptions {
                legend: tokens::legend(),
                full: Some(SemanticTokensFullOptions::Bool(true)),
                range: None,
                ..SemanticTokensOptions::default()
            }
            .into(),
        ),
        ..ServerCapabilities::default()
    }
}

fn serve(connection: &Connection) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let (id, _params) = connection.initialize_start()?;
    let result = serde_json::json!({
        "capabilities": capabilities(),
        "serverInfo": { "name": "rcsc", "version": env!("CARGO_PKG_VERSION") },
    });
    connection.initialize_finish(id, result)?;
    let mut server = Server::default();
    for message in &connection.receiver {
        match message {
            Message::Request(request) => {
                if connection.handle_shutdown(&request)? {
                    return Ok(());
                }
                let response = server.request(request);
                connection.sender.send(Message::Response(response))?;
            }
            Message::Notification(notification) => {
                for out in server.notify(notification) {
                    connection.sender.send(Message::Notification(out))?;
                }
            }
            Message::Response(_) => {}
        }
    }
    Ok(())
}

#[derive(Default)]
struct Server {
    docs: Documents,
    /// The last analysis, for the file it was made for (cleared by every
    /// edit).
    cache: Option<(PathBuf, Analysis)>,
}

impl Server {
    fn analysis(&mut self, path: &Path) -> &Analysis {
        if self.cache.as_ref().is_none_or(|(p, _)| p != path) {
            self.cache = Some((path.to_path_buf(), analyse(&self.docs, path)));
        }
        match &self.cache {
            Some((_, a)) => a,
            None => unreachable!("just filled"),
        }
    }

    fn notify(&mut self, n: Notification) -> Vec<Notification> {
        let path = match n.method.as_str() {
            DidOpenTextDocument::METHOD => params::<lsp_types::DidOpenTextDocumentParams>(n.params)
                .ok()
                .map(|p| {
                    let path = uri_path(&p.text_document.uri);
                    self.docs.open(path.clone(), p.text_document.text);
                    path
                }),
            DidChangeTextDocument::METHOD => {
                params::<lsp_types::DidChangeTextDocumentParams>(n.params)
                    .ok()
                    .map(|p| {
                        let path = uri_path(&p.text_document.uri);
                        // Full sync: the last change holds the whole text.
                        if let Some(change) = p.content_changes.into_iter().last() {
                            self.docs.open(path.clone(), change.text);
                        }
                        path
                    })
            }
            DidCloseTextDocument::METHOD => {
                params::<lsp_types::DidCloseTextDocumentParams>(n.params)
                    .ok()
                    .map(|p| {
                        let path = uri_path(&p.text_document.uri);
                        self.docs.close(&path);
                        path
                    })
            }
            _ => None,
        };
        let Some(path) = path else {
            return Vec::new();
        };
        self.cache = None;
        if path.extension().is_none_or(|e| e != "rcs" && e != "yaml") {
            return Vec::new();
        }
        let analysis = self.analysis(&path);
        publish(analysis)
    }

    fn request(&mut self, r: Request) -> Response {
        let id = r.id.clone();
        match self.answer(r) {
            Ok(value) => Response::new_ok(id, value),
            Err(message) => Response::new_err(id, ErrorCode::InvalidParams as i32, message),
        }
    }

    fn answer(&mut self, r: Request) -> Result<serde_json::Value, String> {
        match r.method.as_str() {
            HoverRequest::METHOD => {
                let p: lsp_types::HoverParams = params(r.params)?;
                let hover = self.at(&p.text_document_position_params, |a, file, offset| {
                    let text = hover_text(a, file, offset)?;
                    Some(Hover {
                        contents: HoverContents::Markup(MarkupContent {
                            kind: MarkupKind::Markdown,
                            value: text,
                        }),
                        range: None,
                    })
                });
                Ok(to_json(&hover))
            }
            GotoDefinition::METHOD => {
                let p: lsp_types::GotoDefinitionParams = params(r.params)?;
                let found = self.at(&p.text_document_position_params, |a, file, offset| {
                    let span = navigate::definition(a, file, offset)?;
                    location(a, span).map(GotoDefinitionResponse::Scalar)
                });
                Ok(to_json(&found))
            }
            References::METHOD => {
                let p: lsp_types::ReferenceParams = params(r.params)?;
                let declaration = p.context.include_declaration;
                let found = self.at(&p.text_document_position, |a, file, offset| {
                    let spans = navigate::references(a, file, offset, declaration);
                    Some(
                        spans
                            .into_iter()
                            .filter_map(|s| location(a, s))
                            .collect::<Vec<_>>(),
                    )
                });
                Ok(to_json(&found))
            }
            DocumentSymbolRequest::METHOD => {
                let p: lsp_types::DocumentSymbolParams = params(r.params)?;
                let path = uri_path(&p.text_document.uri);
                let a = self.analysis(&path);
                let symbols = a.file_of(&path).and_then(|file| {
                    let ir = a.ir()?;
                    Some(DocumentSymbolResponse::Nested(navigate::symbols(
                        a, ir, file,
                    )))
                });
                Ok(to_json(&symbols))
            }
            Completion::METHOD => {
                let p: lsp_types::CompletionParams = params(r.params)?;
                let items = self.at(&p.text_document_position, |a, file, offset| {
                    Some(CompletionResponse::Array(navigate::completion(
                        a.ir()?,
                        file,
                        offset,
                    )))
                });
                Ok(to_json(&items))
            }
            Formatting::METHOD => {
                let p: lsp_types::DocumentFormattingParams = params(r.params)?;
                let path = uri_path(&p.text_document.uri);
                let text = self
                    .docs
                    .current(&path)
                    .ok_or_else(|| format!("{} is neither open nor readable", path.display()))?;
                Ok(to_json(&format_edits(&path, &text)?))
            }
            CodeActionRequest::METHOD => {
                let p: lsp_types::CodeActionParams = params(r.params)?;
                let path = uri_path(&p.text_document.uri);
                let a = self.analysis(&path);
                let actions = a.file_of(&path).map(|file| {
                    let lines = LineIndex::new(a.text(file));
                    let (from, to) = (lines.offset(p.range.start), lines.offset(p.range.end));
                    let mut found = actions::quick_fixes(a, file, from, to);
                    found.extend(actions::renumber(a, file));
                    found
                });
                Ok(to_json(&actions))
            }
            SemanticTokensFullRequest::METHOD => {
                let p: lsp_types::SemanticTokensParams = params(r.params)?;
                let path = uri_path(&p.text_document.uri);
                let a = self.analysis(&path);
                let found = a
                    .file_of(&path)
                    .map(|file| SemanticTokensResult::Tokens(tokens::tokens(a, file)));
                Ok(to_json(&found))
            }
            other => Err(format!("`{other}` is not a request rcsc lsp answers")),
        }
    }

    /// Run `f` on the analysis of the document at `at`, with the byte
    /// offset of its position.
    fn at<T>(
        &mut self,
        at: &TextDocumentPositionParams,
        f: impl FnOnce(&Analysis, FileId, usize) -> Option<T>,
    ) -> Option<T> {
        let path = uri_path(&at.text_document.uri);
        let a = self.analysis(&path);
        let file = a.file_of(&path)?;
        let offset = LineIndex::new(a.text(file)).offset(at.position);
        f(a, file, offset)
    }
}

/// The hover at `offset`: the checked IR's account of a controller,
/// buffer, state or row (with the row's findings), else the declaration
/// of any other name the index knows.
fn hover_text(a: &Analysis, file: FileId, offset: usize) -> Option<String> {
    let index = a.symbols();
    let named = index.at(file, offset);
    let from_ir = a.ir().and_then(|ir| {
        let target = navigate::target_at(a, ir, file, offset)?;
        let findings = match target {
            // Inside a row, a name other than a state is hovered as itself.
            navigate::Target::Row(..) if named.is_some() => return None,
            navigate::Target::Row(ci, pi, ri) => {
                findings_in(a, ir.controllers[ci].plans[pi].rows[ri].span)
            }
            _ => Vec::new(),
        };
        navigate::hover(ir, target, &findings)
    });
    from_ir.or_else(|| named.map(|id| index.hover(id)))
}

/// `rcsc fmt` of `text` as one edit replacing the whole document (none
/// when it is formatted already; `None` when it does not parse: its
/// diagnostics say why).
fn format_edits(path: &Path, text: &str) -> Result<Option<Vec<lsp_types::TextEdit>>, String> {
    let (options, _) = rcs_dsl::fmt::config::options_for(path)?;
    match rcs_dsl::fmt::format(text, &options) {
        Ok(formatted) if formatted == text => Ok(Some(Vec::new())),
        Ok(formatted) => {
            let whole = LineIndex::new(text).range(0, text.len());
            Ok(Some(vec![lsp_types::TextEdit::new(whole, formatted)]))
        }
        Err(rcs_dsl::fmt::FmtError::Syntax(_)) => Ok(None),
        Err(e) => Err(e.to_string()),
    }
}

/// An answer as JSON (`None` is `null`, as LSP wants for "nothing").
fn to_json<T: serde::Serialize>(value: &T) -> serde_json::Value {
    serde_json::to_value(value).unwrap_or(serde_json::Value::Null)
}

fn params<T: serde::de::DeserializeOwned>(v: serde_json::Value) -> Result<T, String> {
    serde_json::from_value(v).map_err(|e| format!("bad parameters: {e}"))
}

/// The messages of the diagnostics whose primary span lies in `row`.
fn findings_in(a: &Analysis, row: Span) -> Vec<String> {
    a.checked
        .diagnostics
        .iter()
        .filter(|d| {
            primary(d)
                .is_some_and(|s| s.file == row.file && s.start >= row.start && s.end <= row.end)
        })
        .map(|d| format!("{}[{}]: {}", d.severity.as_str(), d.code.name(), d.message))
        .collect()
}

pub(crate) fn primary(d: &Diagnostic) -> Option<Span> {
    d.labels
        .iter()
        .find(|l| l.primary)
        .or(d.labels.first())
        .map(|l| l.span)
}

fn location(a: &Analysis, span: Span) -> Option<Location> {
    let path = a.path(span.file)?;
    let range = LineIndex::new(a.text(span.file)).range(span.start as usize, span.end as usize);
    Some(Location::new(path_uri(path)?, range))
}

/// `textDocument/publishDiagnostics` for every file of the set (an empty
/// list clears a file's old ones).
fn publish(a: &Analysis) -> Vec<Notification> {
    let mut by_file: Vec<Vec<lsp_types::Diagnostic>> = vec![Vec::new(); a.paths.len()];
    for d in &a.checked.diagnostics {
        let Some(span) = primary(d) else { continue };
        let Some(list) = by_file.get_mut(span.file.0 as usize) else {
            continue;
        };
        list.push(convert(a, d, span));
    }
    a.paths
        .iter()
        .zip(by_file)
        .filter_map(|(path, diagnostics)| {
            let uri = path_uri(path)?;
            Some(Notification::new(
                PublishDiagnostics::METHOD.to_owned(),
                PublishDiagnosticsParams::new(uri, diagnostics, None),
            ))
        })
        .collect()
}

pub(crate) fn convert(a: &Analysis, d: &Diagnostic, span: Span) -> lsp_types::Diagnostic {
    let range = LineIndex::new(a.text(span.file)).range(span.start as usize, span.end as usize);
    let mut message = d.message.clone();
    for note in &d.notes {
        message.push_str(&format!("\nnote: {note}"));
    }
    if let Some(help) = &d.help {
        message.push_str(&format!("\nhelp: {help}"));
    }
    let mut related: Vec<DiagnosticRelatedInformation> = d
        .labels
        .iter()
        .filter(|l| !l.primary && !l.message.is_empty())
        .filter_map(|l| {
            Some(DiagnosticRelatedInformation {
                location: location(a, l.span)?,
                message: l.message.clone(),
            })
        })
        .collect();
    if let Some(w) = &d.witness {
        let inputs: Vec<String> = w
            .inputs
            .iter()
            .map(|i| format!("{} = {}", i.name, i.value))
            .collect();
        if let Some(location) = location(a, span) {
            related.push(DiagnosticRelatedInformation {
                location,
                message: format!("witness: in {}, with {}", w.state, inputs.join(", ")),
            });
        }
    }
    lsp_types::Diagnostic {
        range,
        severity: Some(match d.severity {
            Severity::Error => DiagnosticSeverity::ERROR,
            Severity::Warning => DiagnosticSeverity::WARNING,
            Severity::Note => DiagnosticSeverity::INFORMATION,
        }),
        code: Some(NumberOrString::String(d.code.name().to_owned())),
        source: Some("rcsc".to_owned()),
        message,
        related_information: (!related.is_empty()).then_some(related),
        ..lsp_types::Diagnostic::default()
    }
}

/// The path of a `file:` URI (percent-decoded); other schemes are kept as
/// a path of their text, which no plan set holds.
fn uri_path(uri: &Uri) -> PathBuf {
    let s = uri.as_str();
    let Some(rest) = s.strip_prefix("file://") else {
        return PathBuf::from(s);
    };
    // `file://host/path`: only the local host (empty or `localhost`).
    let rest = rest.strip_prefix("localhost").unwrap_or(rest);
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| char::from(b).to_digit(16);
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                out.push(u8::try_from(h * 16 + l).unwrap_or(b'?'));
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    PathBuf::from(String::from_utf8_lossy(&out).into_owned())
}

/// The `file:` URI of an absolute path, percent-encoding what a URI path
/// may not hold.
pub(crate) fn path_uri(path: &Path) -> Option<Uri> {
    let mut s = String::from("file://");
    for b in path.to_string_lossy().bytes() {
        if b.is_ascii_alphanumeric() || b"/-._~".contains(&b) {
            s.push(char::from(b));
        } else {
            s.push_str(&format!("%{b:02X}"));
        }
    }
    s.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_uris_round_trip_with_escapes() {
        let path = Path::new("/tmp/a b/ü%.rcs");
        let uri = path_uri(path).expect("a valid URI");
        assert_eq!(uri.as_str(), "file:///tmp/a%20b/%C3%BC%25.rcs");
        assert_eq!(uri_path(&uri), path);
        let host: Uri = "file://localhost/tmp/x.rcs".parse().expect("a URI");
        assert_eq!(uri_path(&host), Path::new("/tmp/x.rcs"));
    }
}
