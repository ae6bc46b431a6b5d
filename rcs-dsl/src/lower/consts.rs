//! Stage 2, first: constants. Every `const NAME: TYPE = EXPR` (file and
//! controller level) is folded to its value here, before buffer types and
//! controllers are lowered, so that array lengths can use them and every
//! later stage sees a constant as the literal it stands for (`lower::expr`
//! substitutes the value: the IR has no constants, and each backend and
//! the analysis treat them exactly as literals).
//!
//! Folding follows the language's arithmetic ([`crate::arith`],
//! [`crate::builtin`]) exactly as a run-time evaluation would: integer
//! literals take the type their context fixes and the arithmetic wraps in
//! that type. Names in a constant expression are other constants (of the
//! controller, then of the file; a file-level constant sees only file-level
//! ones), enum variants and built-in functions; constants may be declared
//! in any order, and a cycle among them is an error (`const_cycle`).

mod fold;

use super::Globals;
use crate::arith;
use crate::ast::{self, BinOp, UnOp};
use crate::builtin::{apply, Builtin, Signature};
use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use crate::ir::{EnumId, FloatTy, IntTy, Type};
use crate::source::Span;
use rcs_runtime::driver::Value;
use std::collections::BTreeMap;

/// A folded constant.
#[derive(Clone, Debug)]
pub(crate) struct Const {
    pub ty: Type,
    pub value: Value,
}

/// Every constant's value: file level, and per controller (in `Globals`
/// order). A constant whose definition has an error has type `()`.
#[derive(Default)]
pub(crate) struct ConstTable {
    file: BTreeMap<String, Const>,
    ctrl: Vec<BTreeMap<String, Const>>,
    /// `const NAME: duration = 50ms` (LANGUAGE.md §8): nanoseconds. Kept
    /// apart, since a duration is no run-time value (see `lower::time`).
    pub durations: Durations,
}

/// The `duration` constants, file level and per controller.
#[derive(Clone, Default)]
pub(crate) struct Durations {
    file: BTreeMap<String, u64>,
    ctrl: Vec<BTreeMap<String, u64>>,
}

impl Durations {
    /// The duration constant `name` as seen from controller `ctrl` (its
    /// own first, then the file's), in nanoseconds.
    pub fn get(&self, ctrl: Option<usize>, name: &str) -> Option<u64> {
        ctrl.and_then(|c| self.ctrl.get(c))
            .and_then(|m| m.get(name))
            .or_else(|| self.file.get(name))
            .copied()
    }
}

/// Whether a constant is declared `: duration` (no user type may take the
/// name: it is not among the primitive types, so an enum or buffer called
/// `duration` is still read as one).
fn is_duration(def: &ast::ConstDef, g: &Globals) -> bool {
    matches!(&def.ty, ast::TypeExpr::Named(n) if n.text == "duration")
        && !g.names.contains_key("duration")
}

/// Fold the `duration` constants: each is a duration literal (in
/// parentheses or not); anything else is reported.
fn fold_durations(
    g: &Globals,
    defs: &BTreeMap<(Scope, String), &ast::ConstDef>,
    diags: &mut Diagnostics,
) -> Durations {
    let mut out = Durations {
        file: BTreeMap::new(),
        ctrl: vec![BTreeMap::new(); g.controllers.len()],
    };
    for ((scope, name), def) in defs {
        if !is_duration(def, g) {
            continue;
        }
        let mut e = &def.value;
        while let ast::ExprKind::Paren(x) = &e.kind {
            e = x;
        }
        let ns = match &e.kind {
            ast::ExprKind::Duration(ns) => *ns,
            _ => {
                diags.push(
                    Diagnostic::error(
                        Code::TypeMismatch,
                        format!("duration constant `{name}` must be a duration literal"),
                        def.value.span,
                        "not a duration literal",
                    )
                    .with_help("write it with a unit: `50ms`, `1.5s`, `250us`"),
                );
                0
            }
        };
        match scope {
            Some(i) => out.ctrl[*i].insert(name.clone(), ns),
            None => out.file.insert(name.clone(), ns),
        };
    }
    out
}

impl ConstTable {
    /// The constant `name` as seen from controller `ctrl` (its own first,
    /// then the file's) or from file level (`None`).
    pub fn get(&self, ctrl: Option<usize>, name: &str) -> Option<&Const> {
        ctrl.and_then(|c| self.ctrl.get(c))
            .and_then(|m| m.get(name))
            .or_else(|| self.file.get(name))
    }

    /// The names of the constants seen from controller `ctrl` (or from
    /// file level), for "did you mean".
    pub fn names(&self, ctrl: Option<usize>) -> impl Iterator<Item = &str> {
        ctrl.and_then(|c| self.ctrl.get(c))
            .into_iter()
            .flat_map(|m| m.keys())
            .chain(self.file.keys())
            .map(String::as_str)
    }

    /// Whether a file-level constant has this name.
    pub fn is_file_const(&self, name: &str) -> bool {
        self.file.contains_key(name)
    }
}

/// A constant's scope: file level (`None`) or a controller.
type Scope = Option<usize>;

/// A value being folded: typed, or a literal still waiting for its type.
#[derive(Clone, Debug)]
enum Ty {
    Known(Type),
    IntLit,
    FloatLit,
}

struct Folded {
    value: Value,
    ty: Ty,
}

/// Fold every constant of the plan set.
pub(super) fn fold_all(g: &Globals, diags: &mut Diagnostics) -> ConstTable {
    let mut defs: BTreeMap<(Scope, String), &ast::ConstDef> = BTreeMap::new();
    for c in &g.consts {
        defs.entry((None, c.name.text.to_string())).or_insert(c);
    }
    for (i, ctrl) in g.controllers.iter().enumerate() {
        for e in &ctrl.entries {
            if let ast::EntryKind::Const(c) = &e.kind {
                defs.entry((Some(i), c.name.text.to_string())).or_insert(c);
            }
        }
    }
    let durations = fold_durations(g, &defs, diags);
    defs.retain(|_, d| !is_duration(d, g));
    let mut f = Folder {
        g,
        defs,
        durations: durations.clone(),
        table: ConstTable {
            file: BTreeMap::new(),
            ctrl: vec![BTreeMap::new(); g.controllers.len()],
            durations,
        },
        done: BTreeMap::new(),
        busy: Vec::new(),
        diags,
    };
    let keys: Vec<(Scope, String)> = f.defs.keys().cloned().collect();
    for k in keys {
        f.constant(&k);
    }
    f.table
}

/// An array length written as a constant expression: an integer from 1 to
/// 65536, or `None` after a diagnostic.
pub(super) fn array_len(
    g: &Globals,
    scope: Option<usize>,
    e: &ast::Expr,
    diags: &mut Diagnostics,
) -> Option<u64> {
    let mut f = Folder {
        g,
        defs: BTreeMap::new(),
        durations: g.consts_table.durations.clone(),
        table: ConstTable::default(),
        done: BTreeMap::new(),
        busy: Vec::new(),
        diags,
    };
    let v = f.settled(scope, e, None)?;
    match (v.value, v.ty) {
        (Value::Int(n), _) if (1..=65_536).contains(&n) => Some(n as u64),
        (Value::Int(n), _) => {
            f.diags.push(
                Diagnostic::error(
                    Code::TypeMismatch,
                    format!("array length {n} is out of range"),
                    e.span,
                    "length must be 1 to 65536",
                )
                .with_help("Global Memory buffers are fixed-size plain data"),
            );
            None
        }
        (_, ty) => {
            let found = f.ty_name(&ty);
            f.diags.push(Diagnostic::error(
                Code::TypeMismatch,
                format!("an array length must be an integer, found {found}"),
                e.span,
                "not an integer",
            ));
            None
        }
    }
}

struct Folder<'a, 'g> {
    g: &'a Globals<'g>,
    /// Definitions not folded yet (empty when folding an array length:
    /// every constant is in `g.consts_table` by then).
    defs: BTreeMap<(Scope, String), &'g ast::ConstDef>,
    /// The `duration` constants, to say so when a number uses one.
    durations: Durations,
    table: ConstTable,
    /// Folded definitions: `false` for those with an error.
    done: BTreeMap<(Scope, String), bool>,
    /// The constants being folded, outermost first (to report cycles).
    busy: Vec<(Scope, String)>,
    diags: &'a mut Diagnostics,
}

impl Folder<'_, '_> {
    fn lookup(&self, key: &(Scope, String)) -> Option<&Const> {
        let own = match key.0 {
            Some(c) => self.table.ctrl.get(c).and_then(|m| m.get(&key.1)),
            None => self.table.file.get(&key.1),
        };
        own.or_else(|| self.g.consts_table.get(key.0, &key.1))
    }

    /// Fold the definition `key`; `false` if it has an error.
    fn constant(&mut self, key: &(Scope, String)) -> bool {
        if let Some(ok) = self.done.get(key) {
            return *ok;
        }
        let Some(def) = self.defs.get(key).copied() else {
            return self.lookup(key).is_some_and(|c| c.ty != Type::Unit);
        };
        self.busy.push(key.clone());
        let ok = self.define(key.0, def);
        self.busy.pop();
        self.done.insert(key.clone(), ok.is_some());
        // A constant with an error stays declared, typed `()`, so that its
        // uses report nothing more.
        let c = ok.unwrap_or(Const {
            ty: Type::Unit,
            value: Value::Unit,
        });
        match key.0 {
            Some(i) => self.table.ctrl[i].insert(key.1.clone(), c),
            None => self.table.file.insert(key.1.clone(), c),
        };
        self.done[key]
    }

    fn define(&mut self, scope: Scope, def: &ast::ConstDef) -> Option<Const> {
        let ty = self.const_type(&def.ty)?;
        let v = self.settled(scope, &def.value, Some(&ty))?;
        let Ty::Known(found) = &v.ty else {
            return None;
        };
        if *found != ty {
            let (want, found) = (self.type_name(&ty), self.type_name(found));
            self.diags.push(Diagnostic::error(
                Code::TypeMismatch,
                format!("expected `{want}`, found `{found}`"),
                def.value.span,
                format!("expected `{want}`"),
            ));
            return None;
        }
        if let Value::Float(f) = v.value {
            if !f.is_finite() {
                self.diags.push(
                    Diagnostic::error(
                        Code::NotConstant,
                        format!(
                            "constant `{}` is {}",
                            def.name.text,
                            crate::pretty::float(f)
                        ),
                        def.value.span,
                        "not a finite number",
                    )
                    .with_help(
                        "a constant must be a finite number; compute NaN or infinity at run time",
                    ),
                );
                return None;
            }
        }
        Some(Const { ty, value: v.value })
    }

    /// The declared type of a constant: `bool`, a number or an enum.
    fn const_type(&mut self, t: &ast::TypeExpr) -> Option<Type> {
        let ty = super::resolve_type(self.g, t, self.diags)?;
        if matches!(
            ty,
            Type::Bool | Type::Int(_) | Type::Float(_) | Type::Enum(_)
        ) {
            return Some(ty);
        }
        self.diags.push(
            Diagnostic::error(
                Code::TypeMismatch,
                format!("a constant cannot have type `{}`", self.type_name(&ty)),
                t.span(),
                "not a constant type",
            )
            .with_help("constants are `bool`, numbers or enums"),
        );
        None
    }

    fn type_name(&self, t: &Type) -> String {
        match t {
            Type::Enum(e) => self.g.enums[e.index()].name.text.to_string(),
            Type::Bool => "bool".to_string(),
            Type::Int(i) => i.name().to_string(),
            Type::Float(f) => f.name().to_string(),
            _ => "a non-constant type".to_string(),
        }
    }

    fn ty_name(&self, t: &Ty) -> String {
        match t {
            Ty::Known(t) => format!("`{}`", self.type_name(t)),
            Ty::IntLit => "an integer literal".to_string(),
            Ty::FloatLit => "a float literal".to_string(),
        }
    }

    fn not_constant(&mut self, span: Span, what: &str) -> Option<Folded> {
        self.diags.push(
            Diagnostic::error(
                Code::NotConstant,
                format!("{what} is not a constant"),
                span,
                "not a constant",
            )
            .with_help("a constant expression uses literals, other constants, enum variants, operators, `as` and built-in functions"),
        );
        None
    }

    fn mismatch(&mut self, span: Span, message: String, label: &str) -> Option<Folded> {
        self.diags
            .push(Diagnostic::error(Code::TypeMismatch, message, span, label));
        None
    }
}

/// The enums (by index) that have a variant `name`, with its index in each.
pub(super) fn variant_owners<'a, V: Iterator<Item = &'a str>>(
    enums: impl Iterator<Item = V>,
    name: &str,
) -> Vec<(usize, usize)> {
    enums
        .enumerate()
        .filter_map(|(ei, mut variants)| variants.position(|v| v == name).map(|vi| (ei, vi)))
        .collect()
}

/// `wrong_arguments`: a built-in called with the wrong number of arguments.
pub(super) fn arity(b: Builtin, given: usize, span: Span) -> Diagnostic {
    let n = b.arity();
    Diagnostic::error(
        Code::WrongArguments,
        format!(
            "`{}` takes {n} argument{} but {given} {} given",
            b.name(),
            if n == 1 { "" } else { "s" },
            if given == 1 { "was" } else { "were" }
        ),
        span,
        format!("expected {n} argument{}", if n == 1 { "" } else { "s" }),
    )
}

/// `type_mismatch`: a built-in's arguments are not of one allowed type.
pub(super) fn arguments(b: Builtin, found: &[String], span: Span) -> Diagnostic {
    let wants = match b.signature() {
        Signature::Numeric => "arguments of one numeric type",
        _ => "float arguments of one type",
    };
    Diagnostic::error(
        Code::TypeMismatch,
        format!(
            "`{}` takes {wants}, found {}",
            b.name(),
            found.join(" and ")
        ),
        span,
        "wrong argument types",
    )
    .with_help(match b.signature() {
        Signature::Numeric => "convert the arguments to one type with `as`",
        _ => "convert integers with `as f64` (or `as f32`)",
    })
}

/// `reserved_name`: a declaration takes a built-in function's name.
pub(super) fn reserved(name: &ast::Name) -> Option<Diagnostic> {
    Builtin::from_name(&name.text).map(|b| {
        Diagnostic::error(
            Code::ReservedName,
            format!("`{}` is the name of a built-in function", b.name()),
            name.span,
            "reserved for the built-in function",
        )
        .with_help("choose another name")
    })
}
