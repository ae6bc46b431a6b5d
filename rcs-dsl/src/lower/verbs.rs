//! Stage 2, inside the controllers' second pass: the verbs of a plan
//! header (`plan A | B | C`) and the forwarding job `X <- cmd`.
//!
//! A plan shared by several verbs is lowered once. Its verbs must declare
//! the same parameters — names, types and order — so that `cmd.P` means
//! one parameter whichever verb is running (`plan_verbs_differ`
//! otherwise). `X <- cmd` sends the running command on, so every verb of the
//! plan must exist, alike, among X's commands (`forward_mismatch`).

use super::duplicate;
use super::expr::Cx;
use crate::ast;
use crate::diagnostic::{Code, Diagnostic};
use crate::ir::*;
use crate::source::Span;

/// How two parameter lists differ, in words, or `None` when they agree.
fn params_differ(cx: &Cx, a: &[Param], b: &[Param]) -> Option<String> {
    for (i, (pa, pb)) in a.iter().zip(b).enumerate() {
        if pa.name != pb.name {
            return Some(format!(
                "parameter {} is `{}` in one and `{}` in the other",
                i + 1,
                pa.name,
                pb.name
            ));
        }
        if pa.ty != pb.ty {
            return Some(format!(
                "parameter `{}` is `{}` in one and `{}` in the other",
                pa.name,
                cx.type_name(&pa.ty),
                cx.type_name(&pb.ty)
            ));
        }
    }
    match a.len().cmp(&b.len()) {
        std::cmp::Ordering::Equal => None,
        std::cmp::Ordering::Less => Some(format!("only one has `{}`", b[a.len()].name)),
        std::cmp::Ordering::Greater => Some(format!("only one has `{}`", a[b.len()].name)),
    }
}

fn signature(cx: &Cx, c: &Command) -> String {
    let ps: Vec<String> = c
        .params
        .iter()
        .map(|p| format!("{}: {}", p.name, cx.type_name(&p.ty)))
        .collect();
    format!("{}({})", c.name, ps.join(", "))
}

impl Cx<'_, '_> {
    /// The verbs of a plan header, each declared, in no other plan, and
    /// with the first verb's parameters; `None` (reported) otherwise.
    /// `plan_of` says which of the `plans` lowered so far took each command.
    pub(in crate::lower) fn plan_verbs(
        &mut self,
        p: &ast::PlanDef,
        plan_of: &[Option<PlanId>],
        plans: &[Plan],
    ) -> Option<Vec<CommandId>> {
        let mut verbs: Vec<(CommandId, Span)> = Vec::new();
        let mut ok = true;
        for v in std::iter::once(&p.verb).chain(&p.more_verbs) {
            let Some(cmd) = self.ix.controllers[self.ctrl.index()].commands.get(&v.text) else {
                self.diags.push(
                    Diagnostic::error(
                        Code::UnknownCommand,
                        format!("`{}` has no command `{}`", self.c.name, v.text),
                        v.span,
                        "no such command",
                    )
                    .with_help(format!("declare it: `command {}`", v.text))
                    .suggest(&v.text, self.c.commands.iter().map(|c| c.name.as_str())),
                );
                ok = false;
                continue;
            };
            if let Some(prev) = plan_of[cmd] {
                self.diags.push(duplicate(
                    "plan",
                    &v.text,
                    v.span,
                    plans[prev.index()].header,
                ));
                ok = false;
                continue;
            }
            if let Some((_, first)) = verbs.iter().find(|(c, _)| c.index() == cmd) {
                self.diags.push(duplicate("plan", &v.text, v.span, *first));
                ok = false;
                continue;
            }
            verbs.push((CommandId(cmd as u32), v.span));
        }
        if let Some(&(first, first_span)) = verbs.first() {
            let a = &self.c.commands[first.index()];
            for &(other, span) in &verbs[1..] {
                let b = &self.c.commands[other.index()];
                if let Some(why) = params_differ(self, &a.params, &b.params) {
                    self.diags.push(
                        Diagnostic::error(
                            Code::PlanVerbsDiffer,
                            format!(
                                "`{}` and `{}` share a plan but not their parameters: {why}",
                                a.name, b.name
                            ),
                            span,
                            format!("`{}` is `{}`", b.name, signature(self, b)),
                        )
                        .with_secondary(first_span, format!("`{}` is `{}`", a.name, signature(self, a)))
                        .with_secondary(a.span, format!("`{}` declared here", a.name))
                        .with_secondary(b.span, format!("`{}` declared here", b.name))
                        .with_help(
                            "the verbs of one plan need the same parameter names and types, in the same order; \
                             give the verb its own plan",
                        ),
                    );
                    ok = false;
                }
            }
        }
        ok.then(|| verbs.into_iter().map(|(c, _)| c).collect())
    }

    /// `X <- cmd` in a plan: X must be a subordinate and declare every verb
    /// of the plan with the same parameters. Outside a plan (no verbs) the
    /// job forwards nothing; the checks of where jobs may stand reject it.
    pub(in crate::lower) fn forward(&mut self, sub: &ast::Name, span: Span) -> Option<Job> {
        let sid = self.subordinate_named(sub)?;
        let target = &self.ir.controllers[sid.index()];
        let mut commands = Vec::new();
        let mut ok = true;
        for &v in &self.plan_verbs {
            let ours = &self.c.commands[v.index()];
            let Some(ci) = self.ix.controllers[sid.index()].commands.get(&ours.name) else {
                self.diags.push(
                    Diagnostic::error(
                        Code::ForwardMismatch,
                        format!(
                            "`{}` has no command `{}` to forward `{}` to",
                            target.name, ours.name, ours.name
                        ),
                        span,
                        format!("forwards `{}`", ours.name),
                    )
                    .with_secondary(ours.span, format!("`{}` declared here", ours.name))
                    .with_help(format!(
                        "declare `command {}` in `{}`, or send it a command of its own: `{} <- VERB(…)`",
                        signature(self, ours),
                        target.name,
                        target.name
                    )),
                );
                ok = false;
                continue;
            };
            let theirs = &target.commands[ci];
            if let Some(why) = params_differ(self, &ours.params, &theirs.params) {
                self.diags.push(
                    Diagnostic::error(
                        Code::ForwardMismatch,
                        format!(
                            "`{}` of `{}` and `{}` of `{}` differ: {why}",
                            ours.name, self.c.name, theirs.name, target.name
                        ),
                        span,
                        format!("forwards `{}`", signature(self, ours)),
                    )
                    .with_secondary(ours.span, format!("`{}` here", signature(self, ours)))
                    .with_secondary(theirs.span, format!("`{}` of `{}` here", signature(self, theirs), target.name))
                    .with_help(
                        "a forwarded command keeps its parameters; declare them alike (names, types, order) \
                         or send it with `X <- VERB(name: value, …)`",
                    ),
                );
                ok = false;
                continue;
            }
            commands.push((v, CommandId(ci as u32)));
        }
        ok.then_some(Job::Forward {
            sub: sid,
            commands,
            span,
        })
    }
}
