//! Stage 1, the builder: items (enums, buffers, controllers), their fields,
//! types and parameters, and the entries of a controller.

use super::*;

impl Builder {
    pub(in crate::parser) fn item(&mut self, p: Pair<Rule>) -> Option<Item> {
        let (outer, mut rest) = self.split_outer(p);
        let def = rest.pop()?;
        let span = self.span(&def);
        match def.as_rule() {
            Rule::enum_def => self.no_attributes(&outer, "an enum"),
            Rule::buffer_def => self.no_attributes(&outer, "a buffer"),
            Rule::const_def => self.no_attributes(&outer, "a constant"),
            _ => {}
        }
        let mut inner = def.clone().into_inner();
        Some(match def.as_rule() {
            Rule::enum_def => {
                inner.next(); // kw
                let name = self.name(inner.next()?);
                let variants = inner
                    .map(|v| {
                        let mut docs = Vec::new();
                        let mut name = None;
                        for c in v.into_inner() {
                            match c.as_rule() {
                                Rule::doc_comment => docs.push(Self::doc(&c)),
                                _ => name = Some(self.name(c)),
                            }
                        }
                        (docs, name.expect("variant has a name"))
                    })
                    .collect();
                Item::Enum(EnumDef {
                    outer,
                    name,
                    variants,
                    span,
                })
            }
            Rule::buffer_def => {
                inner.next();
                let name = self.name(inner.next()?);
                let fields = inner.map(|f| self.field(f)).collect();
                Item::Buffer(BufferDef {
                    outer,
                    name,
                    fields,
                    span,
                })
            }
            Rule::controller_def => {
                inner.next(); // controller
                let (def, _) = self.controller_body(inner, outer, span)?;
                Item::Controller(def)
            }
            Rule::const_def => Item::Const(self.const_def(def)?),
            Rule::controller_type_def => {
                inner.next(); // controller
                inner.next(); // type
                let (def, params) = self.controller_body(inner, outer, span)?;
                Item::ControllerType(ControllerTypeDef { def, params })
            }
            Rule::instance_def => {
                inner.next(); // controller
                let name = self.name(inner.next()?);
                let ty = self.name(inner.next()?);
                let mut title = None;
                let mut args = Vec::new();
                let mut bindings = Vec::new();
                for c in inner {
                    match c.as_rule() {
                        Rule::string_lit => title = Some(Self::title(&c)),
                        Rule::named_arg => {
                            let mut ai = c.into_inner();
                            let n = self.name(ai.next()?);
                            let e = self.expr(ai.next()?);
                            args.push((n, e));
                        }
                        Rule::binding => {
                            let mut bi = c.into_inner();
                            let local = self.name(bi.next()?);
                            let global = self.name(bi.next()?);
                            bindings.push((local, global));
                        }
                        _ => {}
                    }
                }
                Item::Instance(InstanceDef {
                    outer,
                    name,
                    ty,
                    args,
                    title,
                    bindings,
                    span,
                })
            }
            _ => return None,
        })
    }

    /// `use NAME`, placed before row `at`.
    fn use_line(&mut self, p: Pair<Rule>, at: usize) -> Option<Use> {
        let span = self.span(&p);
        let name = self.name(p.into_inner().nth(1)?);
        Some(Use { at, name, span })
    }

    /// A controller's or a type's name, title, parameters (a type's) and
    /// entries, from the name on.
    fn controller_body<'i>(
        &mut self,
        mut inner: impl Iterator<Item = Pair<'i, Rule>>,
        outer: Outer,
        span: Span,
    ) -> Option<(ControllerDef, Vec<Param>)> {
        let name = self.name(inner.next()?);
        let mut title = None;
        let mut params = Vec::new();
        // Sized once, as the entries are most of a controller.
        let mut entries = Vec::with_capacity(inner.size_hint().0);
        for c in inner {
            match c.as_rule() {
                Rule::string_lit => title = Some(Self::title(&c)),
                Rule::param => params.extend(self.params(std::iter::once(c))),
                Rule::entry => entries.extend(self.entry(c)),
                _ => {}
            }
        }
        let def = ControllerDef {
            outer,
            name,
            title,
            entries,
            span,
            instance: None,
        };
        Some((def, params))
    }

    /// A title string's text.
    fn title(p: &Pair<Rule>) -> String {
        let s = p.as_str();
        unescape(&s[1..s.len() - 1])
    }

    /// `const NAME: TYPE = EXPR` (constants).
    pub(in crate::parser) fn const_def(&mut self, p: Pair<Rule>) -> Option<ConstDef> {
        let span = self.span(&p);
        let mut inner = p.into_inner();
        inner.next(); // the keyword
        let name = self.name(inner.next()?);
        let ty = self.type_expr(inner.next()?);
        let value = self.expr(inner.next()?);
        Some(ConstDef {
            name,
            ty,
            value,
            span,
        })
    }

    pub(in crate::parser) fn field(&mut self, p: Pair<Rule>) -> Field {
        let mut docs = Vec::new();
        let mut name = None;
        let mut ty = None;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::doc_comment => docs.push(Self::doc(&c)),
                Rule::ident => name = Some(self.name(c)),
                Rule::type_expr => ty = Some(self.type_expr(c)),
                _ => {}
            }
        }
        Field {
            docs,
            name: name.expect("field has a name"),
            ty: ty.expect("field has a type"),
        }
    }

    pub(in crate::parser) fn type_expr(&mut self, p: Pair<Rule>) -> TypeExpr {
        let c = p.into_inner().next().expect("type_expr has one child");
        match c.as_rule() {
            Rule::array_type => {
                let span = self.span(&c);
                let mut inner = c.into_inner();
                let elem = self.type_expr(inner.next().expect("element type"));
                let len = inner.next().expect("array length");
                let (len, len_expr) = if len.as_rule() == Rule::int_lit {
                    (self.int(len), None)
                } else {
                    (0, Some(Box::new(self.expr(len))))
                };
                TypeExpr::Array {
                    elem: Box::new(elem),
                    len,
                    span,
                    len_expr,
                }
            }
            // `error` is a reserved word, and a type (§8): a controller's
            // error codes.
            _ if c.as_str() == "error" => TypeExpr::Named(crate::ast::Name {
                text: c.as_str().into(),
                span: self.token_span(&c),
            }),
            _ => TypeExpr::Named(self.name(c)),
        }
    }

    pub(in crate::parser) fn params<'i>(
        &mut self,
        pairs: impl Iterator<Item = Pair<'i, Rule>>,
    ) -> Vec<Param> {
        pairs
            .filter(|p| p.as_rule() == Rule::param)
            .map(|p| {
                // A parameter is written like a buffer field: docs, name, type.
                let Field { docs, name, ty } = self.field(p);
                Param { docs, name, ty }
            })
            .collect()
    }

    pub(in crate::parser) fn entry(&mut self, p: Pair<Rule>) -> Option<Entry> {
        let span = self.span(&p);
        let (outer, mut rest) = self.split_outer(p);
        let decl = rest.pop()?;
        let rule = decl.as_rule();
        if rule != Rule::plan_def {
            self.no_attributes(&outer, "this entry");
        }
        let mut inner = decl.clone().into_inner();
        inner.next(); // the keyword
        let kind = match rule {
            Rule::level_decl => {
                let n = inner.next()?;
                let s = self.span(&n);
                EntryKind::Level(self.int(n), s)
            }
            Rule::subordinates_decl => {
                EntryKind::Subordinates(inner.map(|n| self.name(n)).collect())
            }
            Rule::reads_decl | Rule::writes_decl => {
                let name = self.name(inner.next()?);
                let ty = self.name(inner.next()?);
                if rule == Rule::reads_decl {
                    EntryKind::Reads(name, ty)
                } else {
                    EntryKind::Writes(name, ty)
                }
            }
            Rule::command_decl => {
                let name = self.name(inner.next()?);
                let rest: Vec<_> = inner.collect();
                let accept = rest
                    .iter()
                    .find(|p| p.as_rule() == Rule::accept_clause)
                    .and_then(|a| {
                        let mut parts = a.clone().into_inner();
                        let kw = self.span(&parts.next()?);
                        let when = self.span(&parts.next()?);
                        let cond = self.expr(parts.next()?);
                        Some(crate::ast::Accept {
                            keyword: kw.to(when),
                            cond,
                        })
                    });
                EntryKind::Command {
                    name,
                    params: self.params(rest.into_iter()),
                    accept,
                }
            }
            Rule::status_field_decl => {
                let name = self.name(inner.next()?);
                let ty = self.type_expr(inner.next()?);
                let init = inner.next().map(|e| self.expr(e));
                EntryKind::StatusField { name, ty, init }
            }
            Rule::every_cycle_decl => {
                let kw = decl.clone().into_inner().next()?;
                let phase = if kw.as_rule() == Rule::kw_pre {
                    Phase::Pre
                } else {
                    Phase::Post
                };
                let jobs = inner.next()?.into_inner().map(|j| self.job(j)).collect();
                let target = inner.nth(1).map(|t| self.target(t));
                EntryKind::EveryCycle(EveryCycleDef {
                    phase,
                    keyword: self.span(&kw),
                    jobs,
                    target,
                })
            }
            Rule::status_decl => EntryKind::Status(inner.map(|n| self.name(n)).collect()),
            Rule::error_decl => EntryKind::Error(inner.map(|n| self.name(n)).collect()),
            Rule::var_decl => {
                let name = self.name(inner.next()?);
                let ty = self.type_expr(inner.next()?);
                let init = inner.next().map(|e| self.expr(e));
                EntryKind::Var { name, ty, init }
            }
            Rule::hook_decl => {
                let name = self.name(inner.next()?);
                let mut params = Vec::new();
                let mut ret = None;
                for c in inner {
                    match c.as_rule() {
                        Rule::param => params.extend(self.params(std::iter::once(c))),
                        Rule::type_expr => ret = Some(self.type_expr(c)),
                        _ => {}
                    }
                }
                EntryKind::Hook { name, params, ret }
            }
            Rule::plan_def => {
                let kw = decl.clone().into_inner().next()?;
                let verb_pair = inner.next()?;
                let mut header = self.span(&kw).to(self.span(&verb_pair));
                let verb = self.name(verb_pair);
                // `plan A | B | C`: the header runs to the last verb.
                let mut more_verbs = Vec::new();
                // Sized once (the rows are most of the AST, and growing by
                // doubling left a quarter of it unused).
                let mut rows = Vec::with_capacity(inner.len());
                let mut uses = Vec::new();
                for c in inner {
                    match c.as_rule() {
                        Rule::ident => {
                            header = header.to(self.span(&c));
                            more_verbs.push(self.name(c));
                        }
                        Rule::use_rows => uses.push(self.use_line(c, rows.len())?),
                        _ => rows.push(self.row(c)),
                    }
                }
                EntryKind::Plan(PlanDef {
                    verb,
                    header,
                    rows,
                    more_verbs,
                    uses,
                })
            }
            Rule::const_def => EntryKind::Const(self.const_def(decl)?),
            Rule::rows_def => {
                let name = self.name(inner.next()?);
                let mut rows = Vec::with_capacity(inner.len());
                let mut uses = Vec::new();
                for c in inner {
                    if c.as_rule() == Rule::use_rows {
                        uses.push(self.use_line(c, rows.len())?);
                    } else {
                        rows.push(self.row(c));
                    }
                }
                EntryKind::Rows(RowsDef { name, rows, uses })
            }
            Rule::jobs_def => {
                let name = self.name(inner.next()?);
                let mut params = Vec::new();
                let mut jobs = Vec::new();
                for c in inner {
                    match c.as_rule() {
                        Rule::param => params.extend(self.params(std::iter::once(c))),
                        Rule::jobs => jobs = c.into_inner().map(|j| self.job(j)).collect(),
                        _ => {}
                    }
                }
                EntryKind::Jobs(JobsDef { name, params, jobs })
            }
            _ => return None,
        };
        Some(Entry { outer, kind, span })
    }
}
