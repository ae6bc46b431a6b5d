//! Every name of a plan set as written, before `expand`: what each name
//! declares and where each use of it points. Definition, references,
//! hover of declarations and semantic tokens read this index.
//!
//! The checked IR knows only what survives expansion: controller types,
//! instances, job lists, row blocks and the parameters of each are gone
//! from it, and a row placed by `use` points into its block. The index is
//! built from the syntax tree instead ([`declare`] then [`resolve`]), with
//! the scoping rules `lower` applies. Where a use could mean more than one
//! thing (a bare name that is a variant of two enums, a verb of a
//! subordinate a type binds per instance), it is left unresolved: going
//! to a wrong definition is worse than going nowhere.

mod declare;
mod resolve;

use rcs_dsl::ast;
use rcs_dsl::source::{FileId, Span};

/// What a name is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Controller,
    ControllerType,
    /// A const parameter of a controller type (`station` in `Module(station: u8)`).
    TypeParam,
    /// A Global Memory buffer (a `reads`/`writes` name; in a type, the
    /// local name an instance binds).
    Buffer,
    BufferType,
    Field,
    Enum,
    Variant,
    Const,
    Verb,
    /// A parameter of a verb, hook or job list.
    Param,
    Hook,
    JobList,
    RowBlock,
    Var,
    StatusField,
    /// A status word (`status AT_GOAL`).
    Status,
    ErrorCode,
    State,
    /// A subordinate of a controller type, bound per instance.
    SubordinateSlot,
}

impl Kind {
    /// How hover and symbols name the kind.
    pub fn word(self) -> &'static str {
        match self {
            Kind::Controller => "controller",
            Kind::ControllerType => "controller type",
            Kind::TypeParam => "type parameter",
            Kind::Buffer => "buffer",
            Kind::BufferType => "buffer type",
            Kind::Field => "field",
            Kind::Enum => "enum",
            Kind::Variant => "variant",
            Kind::Const => "const",
            Kind::Verb => "command",
            Kind::Param => "parameter",
            Kind::Hook => "hook",
            Kind::JobList => "job list",
            Kind::RowBlock => "rows",
            Kind::Var => "var",
            Kind::StatusField => "status field",
            Kind::Status => "status",
            Kind::ErrorCode => "error",
            Kind::State => "state",
            Kind::SubordinateSlot => "subordinate",
        }
    }
}

pub type SymbolId = usize;

/// One declared name.
#[derive(Clone, Debug)]
pub struct Symbol {
    pub name: String,
    pub kind: Kind,
    /// The name where it is declared (a state: where its plan first names it).
    pub def: Span,
    /// The declaration it belongs to (a field's buffer type, a verb's
    /// controller, a parameter's verb or hook), for hover.
    pub parent: Option<SymbolId>,
    /// The declaration as written, one line (`var rpm: f64`), for hover.
    pub signature: String,
    pub docs: Vec<String>,
}

/// The names of a plan set and their uses.
#[derive(Default)]
pub struct Index {
    pub symbols: Vec<Symbol>,
    /// Each use of a name (declarations included), by where it is written.
    /// A state in a shared row block is a use of that state in every plan
    /// that places the block.
    pub uses: Vec<(Span, SymbolId)>,
}

impl Index {
    /// Index the parsed files of a plan set (files that do not parse are
    /// left out: their diagnostics say why).
    pub fn build(files: &[(FileId, &str, ast::File)]) -> Index {
        let mut index = Index::default();
        let scopes = declare::declare(&mut index, files);
        resolve::resolve(&mut index, &scopes, files);
        for (id, s) in index.symbols.iter().enumerate() {
            index.uses.push((s.def, id));
        }
        index
            .uses
            .sort_by_key(|(s, id)| (s.file.0, s.start, s.end, *id));
        index.uses.dedup();
        index
    }

    /// Index every `.rcs` file of `set` that parses.
    pub fn of_set(set: &rcs_dsl::load::PlanSet) -> Index {
        let files: Vec<(FileId, &str, ast::File)> = set
            .rcs_files
            .iter()
            .filter_map(|&id| {
                let text = set.sources.get(id).text.as_str();
                rcs_dsl::parser::parse_file(id, text)
                    .ok()
                    .map(|f| (id, text, f))
            })
            .collect();
        Index::build(&files)
    }

    /// The symbol named at `offset` of `file` (the innermost use).
    pub fn at(&self, file: FileId, offset: usize) -> Option<SymbolId> {
        self.uses
            .iter()
            .filter(|(s, _)| {
                s.file == file && s.start as usize <= offset && offset <= s.end as usize
            })
            .min_by_key(|(s, _)| s.end - s.start)
            .map(|&(_, id)| id)
    }

    /// Where `id` is named, its declaration first, then in file order.
    pub fn references(&self, id: SymbolId) -> Vec<Span> {
        let def = self.symbols[id].def;
        std::iter::once(def)
            .chain(
                self.uses
                    .iter()
                    .filter(|&&(s, u)| u == id && s != def)
                    .map(|&(s, _)| s),
            )
            .collect()
    }

    /// Every use in `file`, in order, for semantic tokens.
    pub fn in_file(&self, file: FileId) -> impl Iterator<Item = (Span, &Symbol)> {
        self.uses
            .iter()
            .filter(move |(s, _)| s.file == file)
            .map(|&(s, id)| (s, &self.symbols[id]))
    }

    /// Hover for a declaration: its line as written, what it belongs to,
    /// its doc comment (Markdown).
    pub fn hover(&self, id: SymbolId) -> String {
        let s = &self.symbols[id];
        let mut text = format!("```rcs\n{}\n```\n", s.signature);
        if let Some(p) = s.parent {
            let p = &self.symbols[p];
            text.push_str(&format!(
                "{} of {} `{}`\n\n",
                s.kind.word(),
                p.kind.word(),
                p.name
            ));
        }
        if !s.docs.is_empty() {
            text.push_str(&s.docs.join("\n"));
            text.push('\n');
        }
        let uses = self.references(id).len() - 1;
        text.push_str(&format!("\n{uses} use{}", if uses == 1 { "" } else { "s" }));
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// Every plan set of the repository: each use names its symbol's name
    /// exactly, every symbol is used at its own declaration, and names
    /// that resolve are most of what is written (the index is not
    /// vacuously empty).
    #[test]
    fn every_use_in_the_repository_names_its_symbol() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut sets = Vec::new();
        for top in ["plans", "examples", "tests/data/ok"] {
            let mut stack = vec![root.join(top)];
            while let Some(dir) = stack.pop() {
                let Ok(entries) = std::fs::read_dir(&dir) else {
                    continue;
                };
                let mut has_rcs = false;
                for e in entries.flatten() {
                    let p = e.path();
                    if p.is_dir() && !p.ends_with("target") {
                        stack.push(p);
                    } else if p.extension().is_some_and(|x| x == "rcs") {
                        has_rcs = true;
                    }
                }
                if has_rcs {
                    sets.push(dir);
                }
            }
        }
        // The golden cases, each file a plan set of its own.
        let loose: Vec<_> = std::fs::read_dir(root.join("tests/data/ok"))
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "rcs"))
            .collect();
        assert!(sets.len() >= 8 && loose.len() >= 100, "{sets:?}");
        let (mut uses, mut kinds) = (0, std::collections::BTreeSet::new());
        let sets = sets
            .into_iter()
            .filter_map(|d| rcs_dsl::load::load_folder(&d).ok());
        let loose = loose.iter().filter_map(|p| {
            let text = std::fs::read_to_string(p).ok()?;
            let name = p.to_string_lossy().into_owned();
            Some(rcs_dsl::load::PlanSet::from_texts(
                "case",
                [(name.as_str(), text.as_str())],
                None,
            ))
        });
        for set in sets.chain(loose) {
            let dir = &set.name;
            let index = Index::of_set(&set);
            for (span, id) in &index.uses {
                let text = &set.sources.get(span.file).text;
                let written = &text[span.start as usize..span.end as usize];
                let s = &index.symbols[*id];
                assert_eq!(written, s.name, "{} at {span:?} in {dir}", s.name);
                uses += 1;
                kinds.insert(s.kind.word());
            }
        }
        assert!(uses > 5_000, "{uses} uses");
        // Every kind of name occurs in the repository's plans.
        assert!(kinds.len() >= 18, "{kinds:?}");
    }
}
