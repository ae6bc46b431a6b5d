//! `rcsc lsp` through a real client conversation over stdio: the test
//! starts the binary, speaks JSON-RPC with `Content-Length` framing as an
//! editor does, and checks what comes back — diagnostics as the file is
//! typed (the right code and range, then cleared by the fix), hover,
//! definition, references, completion, document symbols, formatting, and a
//! clean shutdown. Nothing here calls the server's handlers directly.

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::Duration;

use serde_json::{json, Value};

/// How long to wait for any one answer (generous: the machine may be loaded).
const WAIT: Duration = Duration::from_secs(120);

struct Client {
    child: Child,
    stdin: ChildStdin,
    messages: Receiver<Value>,
    next_id: i64,
}

fn read_message(out: &mut BufReader<ChildStdout>) -> Option<Value> {
    let mut length = None;
    loop {
        let mut line = String::new();
        if out.read_line(&mut line).ok()? == 0 {
            return None;
        }
        let line = line.trim_end();
        if line.is_empty() {
            break;
        }
        if let Some(v) = line.strip_prefix("Content-Length: ") {
            length = v.parse::<usize>().ok();
        }
    }
    let mut body = vec![0; length?];
    out.read_exact(&mut body).ok()?;
    serde_json::from_slice(&body).ok()
}

impl Client {
    fn start() -> Client {
        let mut child = Command::new(env!("CARGO_BIN_EXE_rcsc"))
            .arg("lsp")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("rcsc lsp starts");
        let stdin = child.stdin.take().expect("stdin");
        let mut stdout = BufReader::new(child.stdout.take().expect("stdout"));
        let (tx, messages) = mpsc::channel();
        std::thread::spawn(move || {
            while let Some(m) = read_message(&mut stdout) {
                if tx.send(m).is_err() {
                    break;
                }
            }
        });
        Client {
            child,
            stdin,
            messages,
            next_id: 1,
        }
    }

    fn send(&mut self, message: &Value) {
        let body = message.to_string();
        write!(self.stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).expect("write");
        self.stdin.flush().expect("flush");
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(&json!({"jsonrpc": "2.0", "method": method, "params": params}));
    }

    /// Send a request and wait for its response (notifications that come
    /// first are kept for `diagnostics`).
    fn request(&mut self, method: &str, params: Value, kept: &mut Vec<Value>) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        self.send(&json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}));
        loop {
            let m = self.messages.recv_timeout(WAIT).expect("an answer in time");
            if m.get("id") == Some(&json!(id)) {
                assert!(m.get("error").is_none(), "{method} failed: {m}");
                return m["result"].clone();
            }
            kept.push(m);
        }
    }

    /// The next diagnostics published for `uri`.
    fn diagnostics(&mut self, uri: &str, kept: &mut Vec<Value>) -> Vec<Value> {
        if let Some(i) = kept.iter().position(|m| is_diagnostics_for(m, uri)) {
            let m = kept.remove(i);
            return m["params"]["diagnostics"]
                .as_array()
                .cloned()
                .unwrap_or_default();
        }
        loop {
            let m = self
                .messages
                .recv_timeout(WAIT)
                .expect("diagnostics in time");
            if is_diagnostics_for(&m, uri) {
                return m["params"]["diagnostics"]
                    .as_array()
                    .cloned()
                    .unwrap_or_default();
            }
        }
    }
}

fn is_diagnostics_for(m: &Value, uri: &str) -> bool {
    m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == uri
}

fn uri(path: &Path) -> String {
    format!("file://{}", path.display())
}

/// The LSP position (line, UTF-16 column) of the first `needle` in `text`.
fn position_of(text: &str, needle: &str) -> Value {
    let at = text.find(needle).expect("needle in text");
    let line = text[..at].matches('\n').count();
    let col: usize = text[..at]
        .rsplit('\n')
        .next()
        .unwrap_or("")
        .chars()
        .map(char::len_utf16)
        .sum();
    json!({"line": line, "character": col})
}

const HELM: &str = "\
/// The helm: commands the engine.
controller HELM {
    subordinates ENGINE
    command GO
    error STALLED
    plan GO {
        E0: *0 when new_command -> S1 { ENGINE <- RUN }
        E1: S1 when ENGINE.done -> Done
        E2: S1 when ENGINE.error || state_cycles > 99 -> Error(STALLED)
    }
}
";

const ENGINE: &str = "\
controller ENGINE {
    reads shaft: Shaft
    command RUN
    plan RUN {
        E0: *0 when new_command -> Spinning
        E1: Spinning when shaft.rpm > 100 -> Done
    }
}

buffer Shaft { rpm: u32 }
";

#[test]
fn a_client_conversation_over_stdio() {
    let dir = common::scratch(
        "lsp_conversation",
        &[("helm.rcs", HELM), ("engine.rcs", ENGINE)],
    );
    let dir = dir.canonicalize().expect("scratch folder");
    let helm_path = dir.join("helm.rcs");
    let engine_path = dir.join("engine.rcs");
    let (helm, engine) = (uri(&helm_path), uri(&engine_path));
    let mut kept = Vec::new();
    let mut client = Client::start();

    let init = client.request(
        "initialize",
        json!({"processId": null, "rootUri": uri(&dir), "capabilities": {}}),
        &mut kept,
    );
    assert_eq!(init["serverInfo"]["name"], "rcsc");
    let caps = &init["capabilities"];
    for cap in [
        "hoverProvider",
        "definitionProvider",
        "referencesProvider",
        "documentSymbolProvider",
        "completionProvider",
    ] {
        assert!(!caps[cap].is_null(), "capability {cap} announced: {caps}");
    }
    client.notify("initialized", json!({}));

    // Open the helm with a typo: `ENGINE.dnoe` is no status field.
    let broken = HELM.replace("ENGINE.done", "ENGINE.dnoe");
    client.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": helm, "languageId": "rcs", "version": 1, "text": broken}}),
    );
    let diags = client.diagnostics(&helm, &mut kept);
    let errors: Vec<&Value> = diags.iter().filter(|d| d["severity"] == 1).collect();
    assert_eq!(errors.len(), 1, "one error: {diags:?}");
    let e = errors[0];
    assert_eq!(e["source"], "rcsc");
    let code = e["code"].as_str().expect("a code");
    assert!(!code.is_empty());
    // The range covers the misspelt name, on its line.
    let start = position_of(&broken, "dnoe");
    assert_eq!(e["range"]["start"]["line"], start["line"], "{e}");
    let (from, to) = (
        e["range"]["start"]["character"].as_u64().unwrap(),
        e["range"]["end"]["character"].as_u64().unwrap(),
    );
    let col = start["character"].as_u64().unwrap();
    assert!(
        from <= col && col < to,
        "range {from}..{to} covers column {col}: {e}"
    );
    // The same code as `rcsc check` gives for the file on disk.
    std::fs::write(&helm_path, &broken).expect("write");
    let cli = common::rcsc(&["check", "--message-format", "short", dir.to_str().unwrap()]);
    assert!(
        common::text(&cli.stdout).contains(code) || common::text(&cli.stderr).contains(code),
        "rcsc check reports `{code}` too"
    );
    std::fs::write(&helm_path, HELM).expect("write");

    // Fix it in the editor (unsaved: the server uses the editor's text).
    std::fs::write(&helm_path, &broken).expect("write");
    client.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": helm, "version": 2}, "contentChanges": [{"text": HELM}]}),
    );
    let diags = client.diagnostics(&helm, &mut kept);
    assert!(diags.iter().all(|d| d["severity"] != 1), "fixed: {diags:?}");

    // Hover on a row: the edge in words.
    let at = position_of(HELM, "E1: S1");
    let hover = client.request(
        "textDocument/hover",
        json!({"textDocument": {"uri": helm}, "position": at}),
        &mut kept,
    );
    let text = hover["contents"]["value"].as_str().expect("hover text");
    assert!(text.contains("S1 when ENGINE.done -> Done"), "{text}");
    // Hover on the controller: its doc comment.
    let hover = client.request(
        "textDocument/hover",
        json!({"textDocument": {"uri": helm}, "position": position_of(HELM, "HELM {")}),
        &mut kept,
    );
    assert!(
        hover["contents"]["value"]
            .as_str()
            .unwrap_or("")
            .contains("The helm: commands the engine."),
        "{hover}"
    );

    // Definition of the subordinate: the controller in the other file.
    let def = client.request(
        "textDocument/definition",
        json!({"textDocument": {"uri": helm}, "position": position_of(HELM, "ENGINE\n")}),
        &mut kept,
    );
    assert_eq!(def["uri"], engine.as_str(), "{def}");
    assert_eq!(def["range"]["start"], position_of(ENGINE, "ENGINE {"));

    // References of state S1 of plan GO: three rows name it.
    let refs = client.request(
        "textDocument/references",
        json!({"textDocument": {"uri": helm}, "position": position_of(HELM, "S1 when ENGINE.done"), "context": {"includeDeclaration": true}}),
        &mut kept,
    );
    assert_eq!(refs.as_array().map(Vec::len), Some(3), "{refs}");
    // References of the buffer from its declaration in ENGINE.
    client.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": engine, "languageId": "rcs", "version": 1, "text": ENGINE}}),
    );
    let _ = client.diagnostics(&engine, &mut kept);
    let def = client.request(
        "textDocument/definition",
        json!({"textDocument": {"uri": engine}, "position": position_of(ENGINE, "Spinning when")}),
        &mut kept,
    );
    assert_eq!(
        def["range"]["start"],
        position_of(ENGINE, "Spinning\n"),
        "{def}"
    );

    // Completion inside plan RUN offers its states, the buffer and the verbs.
    let items = client.request(
        "textDocument/completion",
        json!({"textDocument": {"uri": engine}, "position": position_of(ENGINE, "Spinning when")}),
        &mut kept,
    );
    let labels: Vec<&str> = items
        .as_array()
        .expect("items")
        .iter()
        .filter_map(|i| i["label"].as_str())
        .collect();
    for want in ["Spinning", "shaft", "RUN", "HELM", "ENGINE"] {
        assert!(labels.contains(&want), "{want} in {labels:?}");
    }

    // Document symbols: controller → plan → rows.
    let symbols = client.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": helm}}),
        &mut kept,
    );
    let top = &symbols[0];
    assert_eq!(top["name"], "HELM");
    assert_eq!(top["children"][0]["name"], "plan GO");
    let rows: Vec<&str> = top["children"][0]["children"]
        .as_array()
        .expect("rows")
        .iter()
        .filter_map(|r| r["name"].as_str())
        .collect();
    assert_eq!(rows, ["E0", "E1", "E2"]);

    // Formatting: `rcsc fmt`'s layout as one edit; none once formatted.
    let messy = HELM.replace("    command GO", "  command   GO");
    client.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": helm, "version": 3}, "contentChanges": [{"text": messy}]}),
    );
    let _ = client.diagnostics(&helm, &mut kept);
    let edits = client.request(
        "textDocument/formatting",
        json!({"textDocument": {"uri": helm}, "options": {"tabSize": 4, "insertSpaces": true}}),
        &mut kept,
    );
    let edits = edits.as_array().expect("edits");
    assert_eq!(edits.len(), 1, "{edits:?}");
    let formatted = edits[0]["newText"].as_str().expect("new text");
    assert!(formatted.contains("\n    command GO\n"), "{formatted}");
    assert_eq!(
        edits[0]["range"]["start"],
        json!({"line": 0, "character": 0})
    );
    client.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": helm, "version": 4}, "contentChanges": [{"text": formatted}]}),
    );
    let _ = client.diagnostics(&helm, &mut kept);
    let again = client.request(
        "textDocument/formatting",
        json!({"textDocument": {"uri": helm}, "options": {"tabSize": 4, "insertSpaces": true}}),
        &mut kept,
    );
    assert_eq!(again, json!([]), "formatted text needs no edit");

    // Shutdown and exit: the server ends cleanly.
    let done = client.request("shutdown", json!(null), &mut kept);
    assert!(done.is_null());
    client.notify("exit", json!(null));
    let status = client.child.wait().expect("rcsc lsp exits");
    assert!(status.success(), "{status}");
}
