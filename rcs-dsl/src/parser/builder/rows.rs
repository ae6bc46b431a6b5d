//! Stage 1, the builder: plan rows (labels, state patterns, conditions,
//! targets) and their jobs.

use super::*;

impl Builder {
    pub(in crate::parser) fn row(&mut self, p: Pair<Rule>) -> Row {
        let span = self.span(&p);
        let mut docs = Vec::new();
        let mut label = None;
        let mut from = None;
        let mut otherwise = None;
        let mut when = None;
        let mut cond = None;
        let mut cond_span = span;
        let mut target = None;
        let mut jobs = Vec::new();
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::doc_comment => docs.push(Self::doc(&c)),
                Rule::row_label => {
                    let s = self.span(&c);
                    let n = c.as_str()[1..].parse::<u64>().unwrap_or(u64::MAX);
                    label = Some((n, s));
                }
                Rule::from_state => from = Some(self.state_pattern(c)),
                Rule::kw_otherwise => {
                    cond_span = self.span(&c);
                    otherwise = Some(cond_span);
                }
                Rule::kw_when => when = Some(self.span(&c)),
                Rule::expr => {
                    cond_span = self.span(&c);
                    cond = Some(self.expr(c));
                }
                Rule::target => target = Some(self.target(c)),
                Rule::jobs => {
                    // Sized exactly: collecting from pest's pairs starts at
                    // four jobs (640 bytes) for the usual one or two.
                    let inner = c.into_inner();
                    jobs = Vec::with_capacity(inner.len());
                    jobs.extend(inner.map(|j| self.job(j)));
                }
                _ => {}
            }
        }
        let from = match (from, otherwise) {
            (Some(f @ (From::State(_) | From::States(..) | From::Except(..))), Some(_)) => {
                let (span, what) = match &f {
                    From::State(n) => (n.span, format!("in state `{}`", n.text)),
                    From::States(_, s) => (*s, "in a set of states".to_string()),
                    From::Except(_, _, s) => (*s, "with `except`".to_string()),
                    _ => unreachable!("matched above"),
                };
                self.error(
                    span,
                    format!("an `otherwise` row cannot start {what}"),
                    "`otherwise` applies in every state",
                );
                self.diags.last_mut().expect("just pushed").help =
                    Some("write `otherwise -> …` or `*N otherwise -> …`".to_string());
                From::Implicit
            }
            (Some(f), _) => f,
            (None, Some(_)) => From::Implicit,
            (None, None) => {
                self.error(
                    when.unwrap_or(cond_span),
                    "expected a state or `*` before `when`",
                    "this row names no state",
                );
                self.diags.last_mut().expect("just pushed").help =
                    Some("start the row with the state it applies in (`S1 when …`) or `*` for every state".to_string());
                From::Implicit
            }
        };
        debug_assert!(otherwise.is_some() == cond.is_none());
        Row {
            docs,
            label,
            from,
            cond,
            cond_span,
            target: target.expect("row has a target"),
            jobs,
            span,
            shared: None,
        }
    }

    /// `*N`, `*N except A | B`, `A`, or `A | B | C`.
    fn state_pattern(&mut self, p: Pair<Rule>) -> From {
        let whole = self.span(&p);
        let mut inner = p.into_inner();
        let first = inner.next().expect("from has a first part");
        if first.as_rule() == Rule::dont_care {
            let From::DontCare(n, span) = self.dont_care(first) else {
                unreachable!("dont_care builds a DontCare")
            };
            return match inner.next() {
                Some(except) => {
                    let names = except
                        .into_inner()
                        .filter(|c| c.as_rule() == Rule::ident)
                        .map(|c| self.name(c))
                        .collect();
                    From::Except(n, names, whole)
                }
                None => From::DontCare(n, span),
            };
        }
        let mut names = vec![self.name(first)];
        names.extend(inner.map(|c| self.name(c)));
        if names.len() == 1 {
            From::State(names.pop().expect("one name"))
        } else {
            From::States(names, whole)
        }
    }

    pub(in crate::parser) fn dont_care(&mut self, p: Pair<Rule>) -> From {
        let span = self.span(&p);
        let digits = &p.as_str()[1..];
        let n = if digits.is_empty() {
            None
        } else {
            Some(digits.parse::<u64>().unwrap_or(u64::MAX))
        };
        From::DontCare(n, span)
    }

    pub(in crate::parser) fn target(&mut self, p: Pair<Rule>) -> Target {
        let c = p.into_inner().next().expect("target has one child");
        let span = self.span(&c);
        match c.as_rule() {
            Rule::kw_same => Target::Same(span),
            Rule::error_target => {
                let code = c.into_inner().nth(1).map(|n| self.name(n));
                Target::Error(code, span)
            }
            _ => Target::State(self.name(c)),
        }
    }

    pub(in crate::parser) fn job(&mut self, p: Pair<Rule>) -> Job {
        let c = p.into_inner().next().expect("job has one child");
        let span = self.span(&c);
        match c.as_rule() {
            Rule::report_job => {
                let mut inner = c.into_inner().skip(1);
                let n = self.name(inner.next().expect("status"));
                match inner.next() {
                    Some(code) => Job::ReportCode(n, self.name(code), span),
                    None => Job::Report(n, span),
                }
            }
            _ => {
                let c_text = c.as_str();
                let mut inner = c.into_inner();
                let first = inner.next().expect("place");
                match inner.next() {
                    Some(arrow) if arrow.as_rule() == Rule::send_arrow => {
                        // `X <- VERB(args)`: the name before `<-` is the subordinate.
                        let sub_span = self.span(&first);
                        let place = self.postfix(first, 0).0;
                        let sub = match place.kind {
                            ExprKind::Path(None, n) => n,
                            _ => {
                                self.error(
                                    sub_span,
                                    "expected a subordinate's name before `<-`",
                                    "not a controller name",
                                );
                                Name {
                                    text: Default::default(),
                                    span: sub_span,
                                }
                            }
                        };
                        let verb_pair = inner.next().expect("verb");
                        if verb_pair.as_str() == "cmd" {
                            // `X <- cmd`: forward the current command as it is.
                            if inner.next().is_some() || c_text.trim_end().ends_with(')') {
                                self.error(
                                    span,
                                    "`X <- cmd` forwards the current command as it is and takes no arguments",
                                    "arguments to a forwarded command",
                                );
                            }
                            return Job::Forward { sub, span };
                        }
                        let verb = self.name(verb_pair);
                        let args = inner
                            .map(|a| {
                                let mut ai = a.into_inner();
                                let n = self.name(ai.next().expect("arg name"));
                                let e = self.expr(ai.next().expect("arg value"));
                                (n, e)
                            })
                            .collect();
                        Job::Send {
                            sub,
                            verb,
                            args,
                            span,
                        }
                    }
                    Some(op) => {
                        let place = self.postfix(first, 0).0;
                        let op = match op.as_str() {
                            "+=" => AssignOp::Add,
                            "-=" => AssignOp::Sub,
                            _ => AssignOp::Set,
                        };
                        let value = self.expr(inner.next().expect("assigned value"));
                        Job::Assign {
                            place,
                            op,
                            value,
                            span,
                        }
                    }
                    None => {
                        let place = self.postfix(first, 0).0;
                        if !matches!(place.kind, ExprKind::Call(..)) {
                            self.error(
                                span,
                                "expected a job: an assignment, `X <- VERB`, `report S` or a hook call",
                                "this expression does nothing",
                            );
                        }
                        Job::Call(place)
                    }
                }
            }
        }
    }
}
