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
    position_at(text, text.find(needle).expect("needle in text"))
}

/// The LSP position of byte `at` of `text`.
fn position_at(text: &str, at: usize) -> Value {
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

const MODULE: &str = "\
buffer ModuleIo { running: bool, fault: bool, status_word: u16 }

/// An equipment module, one instance per section.
controller type Module(station: u8) {
    reads io: ModuleIo
    command START
    command ABORT
    error FAULTED
    hook io_cmd(word: u16)
    plan START {
        E0: *0 when new_command -> S1 { io_cmd(0x000F | ((station as u16) << 8)) }
        E1: S1 when (io.status_word & 0x006F) == 0x0027 -> Done
        E2: *2 when io.fault -> Error(FAULTED)
    }
    plan ABORT { *0 when new_command -> Done { io_cmd(0x0000) } }
}

controller INFEED = Module(station: 1) { io: infeed_io }
controller FILLER = Module(station: 2) { io: filler_io }
";

const UNIT: &str = "\
enum PackState { Stopped, Idle, Starting, Execute, Aborting, Aborted }

controller UNIT {
    subordinates INFEED, FILLER
    command START
    command ABORT
    error MODULE_FAULT
    error START_TIMEOUT
    status state: PackState = Idle
    var cause: error = MODULE_FAULT

    /// Abort both modules, remembering why.
    jobs abort_all(why: error) { cause = why; state = Aborting; INFEED <- ABORT; FILLER <- ABORT }

    rows on_fault {
        * except Aborting when INFEED.error_code == FAULTED || FILLER.error_code == FAULTED -> Aborting {
            abort_all(MODULE_FAULT)
        }
    }

    plan START {
        E0: *0 when new_command -> Starting { state = Starting; INFEED <- START; FILLER <- START }
        use on_fault
        E2: Starting when INFEED.done && FILLER.done -> Done { state = Execute }
        E3: Starting when state_cycles > 500 -> Aborting { abort_all(START_TIMEOUT) }
        E4: Aborting when INFEED.done && FILLER.done -> Error(cause) { state = Aborted }
    }
    plan ABORT {
        E0: *0 when new_command -> Aborting { abort_all(cause) }
        use on_fault
        E2: Aborting when INFEED.done && FILLER.done -> Done { state = Aborted }
    }
}
";

const START_SCENARIO: &str = "\
name: UNIT starts both modules
controller: UNIT
steps:
  - command: START
    expect: { fired: E0, state: Starting, sent: { INFEED: START, FILLER: START } }
  - subordinates: { INFEED: DONE, FILLER: DONE }
    expect: { fired: E2 }
";

/// The (line, character) of an LSP location's start.
fn start_of(location: &Value) -> Value {
    location["range"]["start"].clone()
}

/// The `n`-th (0-based) occurrence of `needle` in `text`, as a position.
fn nth_position(text: &str, needle: &str, n: usize) -> Value {
    let at = text
        .match_indices(needle)
        .nth(n)
        .map(|(i, _)| i)
        .expect("needle in text");
    position_at(text, at)
}

/// LANGUAGE.md §8's constructs through the same client: definition and
/// references of names that expansion removes (a controller type and its
/// parameter, a job list, a row block, a subordinate's verb and error code
/// through an instance, a buffer type's field), hover on a job list, the
/// quick fixes of a wrong row number and a misspelt name, and semantic
/// tokens.
#[test]
fn section_8_names_navigate_fix_and_colour() {
    let dir = common::scratch(
        "lsp_section_8",
        &[
            ("module.rcs", MODULE),
            ("unit.rcs", UNIT),
            ("scenarios/start.scenario.yaml", START_SCENARIO),
        ],
    );
    let dir = dir.canonicalize().expect("scratch folder");
    let (module, unit) = (uri(&dir.join("module.rcs")), uri(&dir.join("unit.rcs")));
    let mut kept = Vec::new();
    let mut client = Client::start();
    client.request(
        "initialize",
        json!({"processId": null, "rootUri": uri(&dir), "capabilities": {}}),
        &mut kept,
    );
    client.notify("initialized", json!({}));
    client.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": unit, "languageId": "rcs", "version": 1, "text": UNIT}}),
    );
    let diags = client.diagnostics(&unit, &mut kept);
    assert!(diags.iter().all(|d| d["severity"] != 1), "clean: {diags:?}");

    // (file, text, where the cursor is; text of the file it must go to,
    // where the declaration is), every case a name expansion removes or
    // that resolves through an instance.
    let (m, u) = ((&module, MODULE), (&unit, UNIT));
    let cases = [
        // A job list's call → its declaration; its parameter in its body.
        (u, "abort_all(MODULE_FAULT)", u, "abort_all(why"),
        (u, "why;", u, "why: error"),
        // A subordinate's verb, through the instance, into the type.
        (u, "START; FILLER", m, "START\n"),
        // A subordinate's error code compared with its `error_code`.
        (u, "FAULTED ||", m, "FAULTED\n"),
        // The instance as a subordinate → the instance; its type → the type.
        (u, "INFEED, FILLER", m, "INFEED ="),
        (m, "Module(station: 1", m, "Module(station: u8"),
        // The type's parameter, used in a row; a buffer type's field.
        (m, "station as", m, "station: u8"),
        (m, "fault ->", m, "fault: bool"),
        // A variant named bare (`state = Starting`) → the enum's variant.
        (u, "Starting; INFEED", u, "Starting, Execute"),
    ];
    for ((from, from_text), at, (to, to_text), decl) in cases {
        let def = client.request(
            "textDocument/definition",
            json!({"textDocument": {"uri": from}, "position": position_of(from_text, at)}),
            &mut kept,
        );
        assert_eq!(def["uri"], to.as_str(), "{at}: {def}");
        assert_eq!(start_of(&def), position_of(to_text, decl), "{at}: {def}");
    }

    // The row block: declared once, placed by two plans.
    let refs = client.request(
        "textDocument/references",
        json!({"textDocument": {"uri": unit}, "position": position_of(UNIT, "on_fault {"), "context": {"includeDeclaration": true}}),
        &mut kept,
    );
    assert_eq!(refs.as_array().map(Vec::len), Some(3), "{refs}");
    let without = client.request(
        "textDocument/references",
        json!({"textDocument": {"uri": unit}, "position": position_of(UNIT, "on_fault {"), "context": {"includeDeclaration": false}}),
        &mut kept,
    );
    assert_eq!(without.as_array().map(Vec::len), Some(2), "{without}");

    // Hover on a job list: its line and its doc comment.
    let hover = client.request(
        "textDocument/hover",
        json!({"textDocument": {"uri": unit}, "position": nth_position(UNIT, "abort_all", 2)}),
        &mut kept,
    );
    let text = hover["contents"]["value"].as_str().expect("hover text");
    assert!(text.contains("jobs abort_all(why: error)"), "{text}");
    assert!(text.contains("Abort both modules"), "{text}");

    // Quick fixes: a misspelt name (found while lowering) and a row
    // number (a check, which runs only once lowering succeeded), each
    // offered for its diagnostic and giving the plan back when applied.
    let cases = [
        (
            "cause = why",
            "casue = why",
            "`casue` with `cause`",
            "unknown_name",
        ),
        (
            "E2: Starting",
            "E5: Starting",
            "`E5` with `E2`",
            "row_number",
        ),
    ];
    for (version, (good, bad, title, code)) in (2..).zip(cases) {
        let broken = UNIT.replace(good, bad);
        client.notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": unit, "version": version}, "contentChanges": [{"text": broken}]}),
        );
        let diags = client.diagnostics(&unit, &mut kept);
        let codes: Vec<&str> = diags.iter().filter_map(|d| d["code"].as_str()).collect();
        assert!(codes.contains(&code), "{codes:?}");
        let whole =
            json!({"start": {"line": 0, "character": 0}, "end": {"line": 999, "character": 0}});
        let actions = client.request(
            "textDocument/codeAction",
            json!({"textDocument": {"uri": unit}, "range": whole, "context": {"diagnostics": []}}),
            &mut kept,
        );
        let replacing: Vec<&Value> = actions
            .as_array()
            .expect("actions")
            .iter()
            .filter(|a| {
                a["title"]
                    .as_str()
                    .is_some_and(|t| t.starts_with("Replace"))
            })
            .collect();
        assert_eq!(replacing.len(), 1, "{actions:?}");
        let action = replacing[0];
        assert_eq!(action["kind"], "quickfix", "{action}");
        assert!(
            action["title"].as_str().unwrap_or("").contains(title),
            "{action}"
        );
        assert_eq!(action["diagnostics"][0]["code"], code, "{action}");
        let edits = action["edit"]["changes"][unit.as_str()]
            .as_array()
            .expect("edits");
        assert_eq!(edits.len(), 1, "{edits:?}");
        let e = &edits[0];
        let line = e["range"]["start"]["line"].as_u64().expect("line") as usize;
        let from = e["range"]["start"]["character"].as_u64().expect("col") as usize;
        let to = e["range"]["end"]["character"].as_u64().expect("col") as usize;
        let mut lines: Vec<String> = broken.lines().map(str::to_string).collect();
        lines[line].replace_range(from..to, e["newText"].as_str().expect("text"));
        assert_eq!(lines.join("\n") + "\n", UNIT, "the fix gives the plan back");
    }

    // A row inserted without a label: the three after it are numbered
    // wrong, and one action renumbers them and the scenario that names one.
    let inserted = UNIT.replace(
        "        E2: Starting when INFEED.done",
        "        Starting when INFEED.error || FILLER.error -> Aborting { abort_all(MODULE_FAULT) }\n        E2: Starting when INFEED.done",
    );
    client.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": unit, "version": 8}, "contentChanges": [{"text": inserted}]}),
    );
    let diags = client.diagnostics(&unit, &mut kept);
    let wrong = diags.iter().filter(|d| d["code"] == "row_number").count();
    assert_eq!(wrong, 3, "{diags:?}");
    let actions = client.request(
        "textDocument/codeAction",
        json!({"textDocument": {"uri": unit}, "range": {"start": {"line": 0, "character": 0}, "end": {"line": 999, "character": 0}}, "context": {"diagnostics": []}}),
        &mut kept,
    );
    let all = actions.as_array().expect("actions");
    let renumber = all
        .iter()
        .find(|a| {
            a["title"]
                .as_str()
                .is_some_and(|t| t.starts_with("Renumber"))
        })
        .unwrap_or_else(|| panic!("a renumbering action in {all:?}"));
    assert_eq!(renumber["diagnostics"].as_array().map(Vec::len), Some(3));
    let changes = &renumber["edit"]["changes"];
    let scenario = uri(&dir.join("scenarios/start.scenario.yaml"));
    let new_unit = changes[unit.as_str()][0]["newText"].as_str().expect("unit");
    let new_scenario = changes[scenario.as_str()][0]["newText"]
        .as_str()
        .expect("the scenario");
    assert!(
        new_unit.contains("E3: Starting when INFEED.done"),
        "{new_unit}"
    );
    assert!(new_unit.contains("E5: Aborting when"), "{new_unit}");
    assert!(new_scenario.contains("fired: E3"), "{new_scenario}");
    assert!(!new_scenario.contains("fired: E2"), "{new_scenario}");

    // Semantic tokens: the job list's call is a macro, the subordinate a
    // namespace, the hook a function, a declaration marked so.
    client.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": unit, "version": 9}, "contentChanges": [{"text": UNIT}]}),
    );
    let _ = client.diagnostics(&unit, &mut kept);
    let found = client.request(
        "textDocument/semanticTokens/full",
        json!({"textDocument": {"uri": module}}),
        &mut kept,
    );
    let data: Vec<u64> = found["data"]
        .as_array()
        .expect("data")
        .iter()
        .filter_map(Value::as_u64)
        .collect();
    assert_eq!(data.len() % 5, 0);
    // Decode to (line, col, len, type, modifiers).
    let mut tokens = Vec::new();
    let (mut line, mut col) = (0, 0);
    for t in data.chunks(5) {
        if t[0] > 0 {
            col = 0;
        }
        line += t[0];
        col += t[1];
        tokens.push((line, col, t[2], t[3], t[4]));
    }
    let token_at = |needle: &str, n: usize| {
        let p = nth_position(MODULE, needle, n);
        let (l, c) = (
            p["line"].as_u64().expect("l"),
            p["character"].as_u64().expect("c"),
        );
        tokens
            .iter()
            .find(|t| t.0 == l && t.1 == c)
            .copied()
            .unwrap_or_else(|| panic!("a token at {needle}: {tokens:?}"))
    };
    // Legend order (tokens.rs): 0 namespace … 7 method, 8 parameter, 9 function.
    let hook_decl = token_at("io_cmd", 0);
    assert_eq!((hook_decl.2, hook_decl.3, hook_decl.4 & 1), (6, 9, 1));
    let hook_call = token_at("io_cmd", 1);
    assert_eq!((hook_call.3, hook_call.4 & 1), (9, 0));
    assert_eq!(token_at("INFEED", 0).3, 0, "an instance is a controller");
    assert_eq!(token_at("station as", 0).3, 8, "a type parameter");

    let done = client.request("shutdown", json!(null), &mut kept);
    assert!(done.is_null());
    client.notify("exit", json!(null));
    let status = client.child.wait().expect("rcsc lsp exits");
    assert!(status.success(), "{status}");
}
