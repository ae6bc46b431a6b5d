//! What is under the cursor, and what the editor asks of it: definition,
//! references, hover, document symbols and completion.
//!
//! Definition and references of names come from the index of names as
//! written ([`super::symbols`]: it also knows types, instances, job lists,
//! row blocks and parameters, which expansion removes); rows, the hover of
//! controllers, buffers, states and rows, symbols and completion read the
//! checked IR's spans (rcs-dsl keeps a span for every controller, buffer
//! declaration, plan, row and each row's `from` and target).

use lsp_types::{CompletionItem, CompletionItemKind, DocumentSymbol, SymbolKind};

use rcs_dsl::ir::{Controller, Ir, Plan, Row};
use rcs_dsl::pretty::Printer;
use rcs_dsl::source::{FileId, Span};

use super::documents::Analysis;

/// A name the cursor can be on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    Controller(usize),
    Buffer(usize),
    /// Controller, plan, state.
    State(usize, usize, usize),
    /// Controller, plan, row (the cursor elsewhere in a row).
    Row(usize, usize, usize),
}

fn contains(span: Span, file: FileId, offset: usize) -> bool {
    span.file == file && (span.start as usize) <= offset && offset <= span.end as usize
}

/// The identifier around `offset` in `text`, with its byte range.
pub fn word_at(text: &str, offset: usize) -> Option<(usize, usize)> {
    let is_word = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let offset = offset.min(text.len());
    let start = text[..offset]
        .char_indices()
        .rev()
        .take_while(|&(_, c)| is_word(c))
        .last()
        .map_or(offset, |(i, _)| i);
    let end = text[offset..]
        .char_indices()
        .find(|&(_, c)| !is_word(c))
        .map_or(text.len(), |(i, _)| offset + i);
    (start < end).then_some((start, end))
}

/// What is at `offset` of `file`.
pub fn target_at(a: &Analysis, ir: &Ir, file: FileId, offset: usize) -> Option<Target> {
    let text = a.text(file);
    let word = word_at(text, offset).map(|(s, e)| &text[s..e]);
    for (ci, c) in ir.controllers.iter().enumerate() {
        if contains(c.name_span, file, offset) {
            return Some(Target::Controller(ci));
        }
        for (k, span) in c.subordinate_spans.iter().enumerate() {
            if contains(*span, file, offset) {
                return c.subordinates.get(k).map(|s| Target::Controller(s.index()));
            }
        }
        for (b, span) in &c.buffer_spans {
            if contains(*span, file, offset) {
                return Some(Target::Buffer(b.index()));
            }
        }
        for (pi, p) in c.plans.iter().enumerate() {
            for (ri, r) in p.rows.iter().enumerate() {
                if !contains(r.span, file, offset) {
                    continue;
                }
                if contains(r.from_span, file, offset) || contains(r.to_span, file, offset) {
                    if let Some(si) = word.and_then(|w| p.states.iter().position(|s| s.name == w)) {
                        return Some(Target::State(ci, pi, si));
                    }
                }
                return Some(Target::Row(ci, pi, ri));
            }
        }
    }
    None
}

/// Where the name at `offset` of `file` is declared: any name the index
/// knows ([`super::symbols`]), else a row's label.
pub fn definition(a: &Analysis, file: FileId, offset: usize) -> Option<Span> {
    let index = a.symbols();
    if let Some(id) = index.at(file, offset) {
        return Some(index.symbols[id].def);
    }
    let ir = a.ir()?;
    match target_at(a, ir, file, offset)? {
        Target::Row(ci, pi, ri) => {
            let r = ir.controllers.get(ci)?.plans.get(pi)?.rows.get(ri)?;
            Some(r.label_span.unwrap_or(r.span))
        }
        _ => None,
    }
}

/// Every place the name at `offset` is written, its declaration first
/// (left out unless `declaration`); a row is named only where it is.
pub fn references(a: &Analysis, file: FileId, offset: usize, declaration: bool) -> Vec<Span> {
    let index = a.symbols();
    match index.at(file, offset) {
        Some(id) => {
            let mut spans = index.references(id);
            if !declaration {
                spans.remove(0);
            }
            spans
        }
        None => definition(a, file, offset).into_iter().collect(),
    }
}

fn docs(lines: &[String]) -> String {
    lines.join("\n")
}

fn verb_name(c: &Controller, p: &Plan) -> String {
    c.commands
        .get(p.verb.index())
        .map_or_else(|| "?".into(), |v| v.name.clone())
}

/// A row as the language writes it.
pub fn row_text(ir: &Ir, c: &Controller, p: &Plan, r: &Row) -> String {
    let pr = Printer::new(ir, c, Some(p));
    let jobs: Vec<String> = r.jobs.iter().map(|j| pr.job(j)).collect();
    let jobs = if jobs.is_empty() {
        String::new()
    } else {
        format!(" {{ {} }}", jobs.join("; "))
    };
    format!(
        "{}: {} when {} -> {}{jobs}",
        pr.label(r),
        pr.from(r),
        pr.condition(r),
        pr.target(r)
    )
}

/// The hover text of `target` (Markdown), with `findings` (the messages of
/// the diagnostics inside a row) for a row.
pub fn hover(ir: &Ir, target: Target, findings: &[String]) -> Option<String> {
    let text = match target {
        Target::Controller(ci) => {
            let c = ir.controllers.get(ci)?;
            let verbs: Vec<&str> = c.commands.iter().map(|v| v.name.as_str()).collect();
            let mut s = format!("```rcs\ncontroller {}\n```\n", c.name);
            if let Some(t) = &c.title {
                s.push_str(&format!("**{t}**\n\n"));
            }
            s.push_str(&docs(&c.docs));
            s.push_str(&format!("\n\nverbs: {}", verbs.join(", ")));
            if let Some(sup) = c.supervisor {
                s.push_str(&format!(
                    "; supervisor: {}",
                    ir.controllers[sup.index()].name
                ));
            }
            if !c.subordinates.is_empty() {
                let subs: Vec<&str> = c
                    .subordinates
                    .iter()
                    .map(|s| ir.controllers[s.index()].name.as_str())
                    .collect();
                s.push_str(&format!("; subordinates: {}", subs.join(", ")));
            }
            s
        }
        Target::Buffer(b) => {
            let buf = ir.buffers.get(b)?;
            let ty = &ir.buffer_types[buf.ty.index()];
            let writer = buf.writer.map_or("an external input".to_owned(), |w| {
                format!("written by {}", ir.controllers[w.index()].name)
            });
            let readers: Vec<&str> = buf
                .readers
                .iter()
                .map(|r| ir.controllers[r.index()].name.as_str())
                .collect();
            format!(
                "```rcs\n{}: {}\n```\n{}\n\n{writer}; read by {}",
                buf.name,
                ty.name,
                docs(&ty.docs),
                if readers.is_empty() {
                    "none".into()
                } else {
                    readers.join(", ")
                }
            )
        }
        Target::State(ci, pi, si) => {
            let c = ir.controllers.get(ci)?;
            let p = c.plans.get(pi)?;
            let state = p.states.get(si)?;
            let pr = Printer::new(ir, c, Some(p));
            let leaving: Vec<String> = p
                .rows
                .iter()
                .filter(|r| {
                    pr.from(r)
                        .split(|ch: char| !ch.is_ascii_alphanumeric() && ch != '_')
                        .any(|w| w == state.name)
                })
                .map(|r| format!("- `{}`", row_text(ir, c, p, r)))
                .collect();
            format!(
                "state `{}` of plan `{}` of `{}`\n\nrows from it:\n{}",
                state.name,
                verb_name(c, p),
                c.name,
                if leaving.is_empty() {
                    "(none)".into()
                } else {
                    leaving.join("\n")
                }
            )
        }
        Target::Row(ci, pi, ri) => {
            let c = ir.controllers.get(ci)?;
            let p = c.plans.get(pi)?;
            let r = p.rows.get(ri)?;
            let mut s = format!(
                "```rcs\n{}\n```\nrow {} of plan `{}` of `{}`",
                row_text(ir, c, p, r),
                r.position,
                verb_name(c, p),
                c.name
            );
            if !r.docs.is_empty() {
                s.push_str(&format!("\n\n{}", docs(&r.docs)));
            }
            for f in findings {
                s.push_str(&format!("\n\n- {f}"));
            }
            s
        }
    };
    Some(text)
}

/// Controllers → plans → rows of `file`. A controller type's plans are
/// listed once, under its first instance.
#[allow(deprecated)] // `DocumentSymbol::deprecated` has to be written.
pub fn symbols(a: &Analysis, ir: &Ir, file: FileId) -> Vec<DocumentSymbol> {
    let index = super::position::LineIndex::new(a.text(file));
    let range = |s: Span| index.range(s.start as usize, s.end as usize);
    let mut shown = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for c in &ir.controllers {
        let mut plans = Vec::new();
        for p in &c.plans {
            if p.span.file != file || !shown.insert((p.span.start, p.span.end)) {
                continue;
            }
            let rows = p
                .rows
                .iter()
                .filter(|r| r.span.file == file)
                .map(|r| DocumentSymbol {
                    name: Printer::new(ir, c, Some(p)).label(r),
                    detail: Some(row_text(ir, c, p, r)),
                    kind: SymbolKind::EVENT,
                    tags: None,
                    deprecated: None,
                    range: range(r.span),
                    selection_range: range(r.label_span.unwrap_or(r.from_span)),
                    children: None,
                })
                .collect();
            plans.push(DocumentSymbol {
                name: format!("plan {}", verb_name(c, p)),
                detail: None,
                kind: SymbolKind::METHOD,
                tags: None,
                deprecated: None,
                range: range(p.span),
                selection_range: range(p.header),
                children: Some(rows),
            });
        }
        if c.span.file != file {
            // A type's plans in this file, its instance in another.
            out.extend(plans);
            continue;
        }
        out.push(DocumentSymbol {
            name: c.name.clone(),
            detail: c.title.clone(),
            kind: SymbolKind::CLASS,
            tags: None,
            deprecated: None,
            range: range(c.span),
            selection_range: range(c.name_span),
            children: Some(plans),
        });
    }
    out
}

/// Names in scope at `offset`: the plan's states where the cursor is in a
/// plan, the controller's verbs, buffers it reads or writes and its vars;
/// every controller and buffer of the set.
pub fn completion(ir: &Ir, file: FileId, offset: usize) -> Vec<CompletionItem> {
    let item = |label: &str, kind: CompletionItemKind, detail: String| CompletionItem {
        label: label.to_owned(),
        kind: Some(kind),
        detail: Some(detail),
        ..CompletionItem::default()
    };
    let mut items = Vec::new();
    for c in &ir.controllers {
        items.push(item(
            &c.name,
            CompletionItemKind::CLASS,
            "controller".into(),
        ));
        if !contains(c.span, file, offset)
            && !c.plans.iter().any(|p| contains(p.span, file, offset))
        {
            continue;
        }
        for v in &c.commands {
            items.push(item(
                &v.name,
                CompletionItemKind::METHOD,
                format!("verb of {}", c.name),
            ));
        }
        for v in &c.vars {
            items.push(item(
                &v.name,
                CompletionItemKind::VARIABLE,
                format!("var of {}", c.name),
            ));
        }
        for p in c.plans.iter().filter(|p| contains(p.span, file, offset)) {
            for s in &p.states {
                items.push(item(
                    &s.name,
                    CompletionItemKind::ENUM_MEMBER,
                    format!("state of {}", verb_name(c, p)),
                ));
            }
        }
    }
    for b in &ir.buffers {
        items.push(item(
            &b.name,
            CompletionItemKind::FIELD,
            format!("buffer: {}", ir.buffer_types[b.ty.index()].name),
        ));
    }
    let mut seen = std::collections::BTreeSet::new();
    items.retain(|i| seen.insert((i.label.clone(), i.detail.clone())));
    items
}
