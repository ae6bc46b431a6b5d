//! Stage 2, second half: plans, rows (state patterns, conditions,
//! targets), jobs, sends and assignment places, checked through the
//! expression checker of `lower::expr`.

use super::expr::{Cx, Subscript, Value};
use super::state_sets::{from_names, intern, is_terminal, row_number};
use super::*;
use crate::ast::{self, AssignOp, BinOp};
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::*;
use crate::source::Span;

impl Cx<'_, '_> {
    pub(in crate::lower) fn plan(
        &mut self,
        p: &ast::PlanDef,
        ast_rows: Vec<ast::Row>,
        cmd: CommandId,
        outer: &ast::Outer,
    ) -> Plan {
        let mut states = vec![State {
            name: "S0".to_string(),
            span: None,
        }];
        let mut names = ByName::default();
        names.first_or_insert("S0", 0);
        // The plan's states first, in order of first mention: the `from`s
        // of its own rows and every target. A state named only in the
        // `from` of shared rows (`use NAME`) is not one of them (§8).
        for r in &ast_rows {
            if r.shared.is_none() {
                for n in from_names(&r.from) {
                    if !is_terminal(n) {
                        intern(&mut states, &mut names, n);
                    }
                }
            }
            if let ast::Target::State(n) = &r.target {
                if n.text != "Done" {
                    intern(&mut states, &mut names, n);
                }
            }
        }
        let mut rows = Vec::with_capacity(ast_rows.len());
        for (pos, r) in ast_rows.iter().enumerate() {
            if let Some(row) = self.row(r, pos as u32, (&mut states, &mut names)) {
                rows.push(row);
            }
        }
        let span = ast_rows
            .last()
            .map(|r| p.header.to(r.span))
            .unwrap_or(p.header);
        Plan {
            verbs: vec![cmd],
            verb: cmd,
            docs: outer.docs.clone(),
            states,
            rows,
            lints: outer.lints.iter().map(|(l, _)| *l).collect(),
            header: p.header,
            span,
        }
    }

    pub(in crate::lower) fn row(
        &mut self,
        r: &ast::Row,
        position: u32,
        (states, names): (&mut Vec<State>, &mut ByName),
    ) -> Option<Row> {
        let (from, from_span) = match &r.from {
            ast::From::DontCare(n, s) => (From::DontCare(n.map(row_number)), *s),
            ast::From::Implicit => (From::DontCare(None), r.cond_span),
            ast::From::State(n) if is_terminal(n) => {
                self.terminal_from(n);
                (From::DontCare(None), n.span)
            }
            ast::From::State(n) if r.shared.is_some() => {
                let set = self.state_set(std::slice::from_ref(n), r, (states, names));
                match set.as_slice() {
                    [s] => (From::State(*s), n.span),
                    _ => (From::States(set), n.span),
                }
            }
            ast::From::State(n) => (From::State(intern(states, names, n)), n.span),
            ast::From::States(list, s) => {
                (From::States(self.state_set(list, r, (states, names))), *s)
            }
            ast::From::Except(n, list, s) => {
                let out = self.state_set(list, r, (states, names));
                if out.len() == states.len() {
                    self.except_everything(list, *s, states.len());
                }
                (From::Except(n.map(row_number), out), *s)
            }
        };
        let (cond, is_entry) = match &r.cond {
            None => (Condition::Otherwise, false),
            Some(c) => {
                let e = self.check(c, &Type::Bool);
                let entry = has_new_command_conjunct(&e);
                (Condition::When(e), entry)
            }
        };
        let to = match &r.target {
            ast::Target::Same(_) => Target::Same,
            ast::Target::Error(None, _) => Target::Error(None),
            ast::Target::Error(Some(code), _) => match self.error_code(code) {
                Some(ErrorRef::Held(v)) => Target::ErrorOf(v),
                Some(ErrorRef::Declared(e)) => Target::Error(Some(e)),
                None => Target::Error(None),
            },
            ast::Target::State(n) if n.text == "Done" => Target::Done,
            ast::Target::State(n) => Target::State(intern(states, names, n)),
        };
        // Sized once: `filter_map` gives no lower bound, and a vector grown
        // from empty holds four jobs (700 bytes) for the usual one or two.
        let mut jobs = Vec::with_capacity(r.jobs.len());
        jobs.extend(r.jobs.iter().filter_map(|j| self.job(j)));
        Some(Row {
            position,
            label: r.label.map(|(n, _)| row_number(n)),
            docs: r.docs.clone(),
            from,
            cond,
            is_entry,
            to,
            jobs,
            line: 0,
            span: r.span,
            from_span,
            cond_span: r.cond_span,
            to_span: r.target.span(),
            label_span: r.label.map(|(_, s)| s),
            shared: r.shared.as_ref().map(|o| crate::ir::SharedRow {
                block: o.block.text.to_string(),
                use_span: o.use_span,
            }),
        })
    }

    pub(in crate::lower) fn job(&mut self, j: &ast::Job) -> Option<Job> {
        match j {
            ast::Job::ReportCode(name, code, span) => self.report_code(name, code, *span),
            ast::Job::Report(name, span) => match self.names().statuses.get(&name.text) {
                // `report DONE`, `report EXECUTING`, `report ERROR`: the
                // plan goes on (LANGUAGE.md §7); NOT_READY stays the runtime's.
                Some(i) if i != StatusId::NOT_READY.index() => Some(Job::Report {
                    status: StatusId(i as u32),
                    span: *span,
                    error: None,
                    error_of: None,
                }),
                Some(_) => {
                    let target = "the runtime sets it; report `EXECUTING`, `DONE`, `ERROR(CODE)` or a custom status instead";
                    self.diags.push(
                        Diagnostic::error(
                            Code::UnknownName,
                            format!("`report {}` is not allowed", name.text),
                            name.span,
                            "built-in status",
                        )
                        .with_help(target.to_string()),
                    );
                    None
                }
                None => {
                    self.diags.push(
                        Diagnostic::error(
                            Code::UnknownName,
                            format!("controller `{}` has no status `{}`", self.c.name, name.text),
                            name.span,
                            "not declared",
                        )
                        .with_help(format!("declare it: `status {}`", name.text))
                        .suggest(&name.text, self.c.statuses.iter().map(|s| s.name.as_str())),
                    );
                    None
                }
            },
            ast::Job::Call(e) => {
                let (x, _) = self.infer(e, None);
                Some(Job::Call(x))
            }
            ast::Job::Assign {
                place,
                op,
                value,
                span,
            } => {
                let p = self.place(place)?;
                if *op != AssignOp::Set && !matches!(p.ty, Type::Int(_) | Type::Float(_)) {
                    self.mismatch(
                        *span,
                        format!(
                            "`{}` needs a number, but the target is `{}`",
                            if *op == AssignOp::Add { "+=" } else { "-=" },
                            self.type_name(&p.ty)
                        ),
                        "not a number".to_string(),
                    );
                    self.infer_untyped(value);
                    return None;
                }
                let v = self.check(value, &p.ty);
                Some(Job::Assign {
                    place: p,
                    op: *op,
                    value: v,
                    span: *span,
                })
            }
            ast::Job::Send {
                sub,
                verb,
                args,
                span,
            } => self.send(sub, verb, args, *span),
            ast::Job::Forward { sub, span } => self.forward(sub, *span),
        }
    }

    /// The subordinate `sub` names, or `None` with `unknown_subordinate`.
    pub(in crate::lower) fn subordinate_named(&mut self, sub: &ast::Name) -> Option<CtrlId> {
        match self
            .c
            .subordinates
            .iter()
            .find(|s| self.ir.controllers[s.index()].name == sub.text)
        {
            Some(s) => Some(*s),
            None => {
                let help = if matches!(
                    self.g.names.get(sub.text.as_str()),
                    Some((ItemRef::Controller(_), _))
                ) {
                    format!(
                        "add `{}` to `{}`'s `subordinates` list",
                        sub.text, self.c.name
                    )
                } else {
                    "commands go only to controllers listed in `subordinates`".to_string()
                };
                self.diags.push(
                    Diagnostic::error(
                        Code::UnknownSubordinate,
                        format!("`{}` is not a subordinate of `{}`", sub.text, self.c.name),
                        sub.span,
                        "not a subordinate",
                    )
                    .with_help(help)
                    .suggest(&sub.text, self.subordinate_names()),
                );
                None
            }
        }
    }

    pub(in crate::lower) fn send(
        &mut self,
        sub: &ast::Name,
        verb: &ast::Name,
        args: &[(ast::Name, ast::Expr)],
        span: Span,
    ) -> Option<Job> {
        let infer_all = |cx: &mut Self| {
            for (_, a) in args {
                cx.infer_untyped(a);
            }
        };
        let Some(sid) = self.subordinate_named(sub) else {
            infer_all(self);
            return None;
        };
        let target = &self.ir.controllers[sid.index()];
        let Some(ci) = self.ix.controllers[sid.index()].commands.get(&verb.text) else {
            self.diags.push(
                Diagnostic::error(
                    Code::UnknownCommand,
                    format!("`{}` has no command `{}`", target.name, verb.text),
                    verb.span,
                    "no such command",
                )
                .with_help(format!(
                    "`{}` accepts: {}",
                    target.name,
                    target
                        .commands
                        .iter()
                        .map(|c| c.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
                .suggest(&verb.text, target.commands.iter().map(|c| c.name.as_str())),
            );
            infer_all(self);
            return None;
        };
        let command = &target.commands[ci];
        let mut slots: Vec<Option<Expr>> = vec![None; command.params.len()];
        let mut seen: Vec<Option<Span>> = vec![None; command.params.len()];
        let mut ok = true;
        for (n, a) in args {
            match self.ix.controllers[sid.index()].params[ci].get(&n.text) {
                None => {
                    self.diags.push(
                        Diagnostic::error(
                            Code::WrongArguments,
                            format!(
                                "command `{}` of `{}` has no parameter `{}`",
                                command.name, target.name, n.text
                            ),
                            n.span,
                            "unknown parameter",
                        )
                        .with_secondary(command.span, "command declared here"),
                    );
                    self.infer_untyped(a);
                    ok = false;
                }
                Some(pi) => {
                    if let Some(first) = seen[pi] {
                        self.diags.push(
                            Diagnostic::error(
                                Code::WrongArguments,
                                format!("parameter `{}` is given twice", n.text),
                                n.span,
                                "repeated argument",
                            )
                            .with_secondary(first, "first given here"),
                        );
                        self.infer_untyped(a);
                        ok = false;
                        continue;
                    }
                    seen[pi] = Some(n.span);
                    let ty = command.params[pi].ty.clone();
                    slots[pi] = Some(if ty == Type::Unit {
                        self.infer_untyped(a).0
                    } else {
                        self.check(a, &ty)
                    });
                }
            }
        }
        let missing: Vec<&str> = command
            .params
            .iter()
            .zip(&slots)
            .filter(|(_, s)| s.is_none())
            .map(|(p, _)| p.name.as_str())
            .collect();
        if !missing.is_empty() && ok {
            self.diags.push(
                Diagnostic::error(
                    Code::WrongArguments,
                    format!(
                        "command `{}` of `{}` is missing {}",
                        command.name,
                        target.name,
                        missing
                            .iter()
                            .map(|m| format!("`{m}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                    span,
                    "missing arguments",
                )
                .with_secondary(command.span, "command declared here")
                .with_help(format!(
                    "pass every parameter by name: `{} <- {}({})`",
                    target.name,
                    command.name,
                    command
                        .params
                        .iter()
                        .map(|p| format!("{}: …", p.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            );
            return None;
        }
        if !ok {
            return None;
        }
        Some(Job::Send {
            sub: sid,
            command: CommandId(ci as u32),
            args: slots.into_iter().map(|s| s.expect("all filled")).collect(),
            span,
        })
    }

    /// Resolve an assignment target, reporting `assign_to_input` for inputs.
    pub(in crate::lower) fn place(&mut self, e: &ast::Expr) -> Option<Place> {
        let input = |cx: &mut Self, what: String, help: &str| {
            cx.diags.push(
                Diagnostic::error(
                    Code::AssignToInput,
                    format!("cannot assign to {what}"),
                    e.span,
                    "an input of this controller",
                )
                .with_help(help.to_string()),
            );
            None
        };
        match &e.kind {
            ast::ExprKind::Paren(i) => self.place(i),
            ast::ExprKind::Path(None, n) => match self.value(&n.text) {
                Some(Value::Var(v)) => {
                    let ty = self.c.vars[v.index()].ty.clone();
                    (ty != Type::Unit).then_some(Place { root: PlaceRoot::Var(v), path: Vec::new(), ty, span: e.span, indices: Vec::new() })
                }
                Some(Value::Buffer(b, true)) => Some(Place { root: PlaceRoot::Buffer(b), path: Vec::new(), ty: Type::Buffer(self.ir.buffers[b.index()].ty), span: e.span, indices: Vec::new() }),
                Some(Value::Buffer(_, false)) => input(self, format!("`{}`, a buffer this controller reads", n.text), "only `writes` buffers and `var`s can be assigned; another controller or an external writer owns this one"),
                Some(Value::Sub) => input(self, format!("subordinate `{}`", n.text), "command a subordinate with `X <- VERB(…)`"),
                Some(Value::Hook(_)) => input(self, format!("hook `{}`", n.text), "hooks are functions; call them"),
                None => {
                    self.infer(e, None);
                    None
                }
            },
            ast::ExprKind::CmdParam(p) => input(self, format!("`cmd.{}`", p.text), "the command buffer belongs to the supervisor; copy the value into a `var`"),
            ast::ExprKind::Field(base, f) => {
                if let ast::ExprKind::Path(None, x) = &base.kind {
                    if let Some((ItemRef::Controller(_), _)) = self.g.names.get(x.text.as_str()) {
                        if self.value(&x.text).is_none() || matches!(self.value(&x.text), Some(Value::Sub)) {
                            return input(self, format!("`{}.{}`", x.text, f.text), "a subordinate's status is written by the subordinate");
                        }
                    }
                }
                let mut p = self.place(base)?;
                match &p.ty {
                    Type::Buffer(bid) => {
                        let bty = &self.ir.buffer_types[bid.index()];
                        match self.ix.fields[bid.index()].get(&f.text) {
                            Some(fi) => {
                                p.ty = bty.fields[fi].ty.clone();
                                if p.ty == Type::Unit {
                                    return None; // its type did not resolve; already reported
                                }
                                p.path.push(Projection::Field(fi as u32));
                                p.span = e.span;
                                Some(p)
                            }
                            None => {
                                self.diags.push(Diagnostic::error(Code::UnknownName, format!("buffer type `{}` has no field `{}`", bty.name, f.text), f.span, "no such field")
                                    .with_help(format!("the fields are: {}", bty.fields.iter().map(|f| f.name.as_str()).collect::<Vec<_>>().join(", ")))
                                    .suggest(&f.text, bty.fields.iter().map(|f| f.name.as_str())));
                                None
                            }
                        }
                    }
                    t => {
                        let t = self.type_name(t);
                        self.mismatch(f.span, format!("`{t}` has no fields"), format!("no field `{}`", f.text));
                        None
                    }
                }
            }
            ast::ExprKind::Index(base, idx) => {
                let mut p = self.place(base)?;
                let n = match self.index(idx)? {
                    Subscript::Const(n) => n,
                    Subscript::Value(i) => {
                        let Type::Array(elem, _) = p.ty.clone() else {
                            let t = self.type_name(&p.ty);
                            self.mismatch(base.span, format!("cannot index into `{t}`"), "not an array".to_string());
                            return None;
                        };
                        p.ty = *elem;
                        p.path.push(Projection::IndexBy(p.indices.len() as u32));
                        p.indices.push(i);
                        p.span = e.span;
                        return Some(p);
                    }
                };
                match p.ty.clone() {
                    Type::Array(elem, len) => {
                        if n >= len as u64 {
                            self.mismatch(idx.span, format!("index {n} is out of bounds for an array of length {len}"), format!("valid indices are 0 to {}", len - 1));
                            return None;
                        }
                        p.ty = *elem;
                        p.path.push(Projection::Index(n as u32));
                        p.span = e.span;
                        Some(p)
                    }
                    t => {
                        let t = self.type_name(&t);
                        self.mismatch(base.span, format!("cannot index into `{t}`"), "not an array".to_string());
                        None
                    }
                }
            }
            _ => input(self, "this expression".to_string(), "assign to a `var`, a `writes` buffer, or a field or element of one"),
        }
    }
}

/// Whether `new_command` is a top-level conjunct of a condition.
pub fn has_new_command_conjunct(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::NewCommand => true,
        ExprKind::Binary(BinOp::And, operands) => {
            let [l, r] = &**operands;
            has_new_command_conjunct(l) || has_new_command_conjunct(r)
        }
        _ => false,
    }
}

impl Cx<'_, '_> {
    /// The controller's error code `code` (in `-> Error(CODE)` and
    /// `report ERROR(CODE)`), or `None` after reporting it undeclared.
    /// The code of `-> Error(NAME)` or `report ERROR(NAME)`: an error
    /// this controller declares, or a var (or status field) of type
    /// `error` that holds one (§8).
    pub(in crate::lower) fn error_code(&mut self, code: &ast::Name) -> Option<ErrorRef> {
        if let Some(i) = self.names().errors.get(&code.text) {
            return Some(ErrorRef::Declared(ErrorId(i as u32)));
        }
        let held = self
            .c
            .vars
            .iter()
            .position(|v| v.name == code.text)
            .map(|i| (VarId(i as u32), &self.c.vars[i]));
        let (message, label, help) = match held {
            Some((id, v)) if v.ty == Type::ErrorCode(self.ctrl) => {
                return Some(ErrorRef::Held(id));
            }
            Some((_, v)) => (
                format!(
                    "`{}` is {}, not an error code",
                    code.text,
                    self.type_name(&v.ty)
                ),
                "not of type `error`",
                format!(
                    "a var that holds an error code has the type `error` (`var {}: error`); or end with a declared code: {}",
                    code.text,
                    self.declared_errors()
                ),
            ),
            None if crate::error_codes::is_builtin(&code.text) => (
                format!("`{}` is a built-in error the runtime reports", code.text),
                "not one of this controller's codes",
                format!(
                    "a plan ends with a code its controller declares: `error MY_CODE` then `-> Error(MY_CODE)`; {}",
                    self.declared_errors()
                ),
            ),
            None => (
                format!(
                    "controller `{}` has no error code `{}`",
                    self.c.name, code.text
                ),
                "not declared",
                format!("declare it: `error {}`", code.text),
            ),
        };
        self.diags.push(
            Diagnostic::error(Code::UnknownName, message, code.span, label)
                .with_help(help)
                .suggest(&code.text, self.c.errors.iter().map(|e| e.name.as_str())),
        );
        None
    }

    /// "its codes are …" for a help.
    fn declared_errors(&self) -> String {
        if self.c.errors.is_empty() {
            format!("`{}` declares none", self.c.name)
        } else {
            format!(
                "the codes of `{}` are {}",
                self.c.name,
                self.c
                    .errors
                    .iter()
                    .map(|e| e.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        }
    }
}

/// What `Error(NAME)` names.
pub(in crate::lower) enum ErrorRef {
    Declared(ErrorId),
    /// A var of type `error`.
    Held(VarId),
}
