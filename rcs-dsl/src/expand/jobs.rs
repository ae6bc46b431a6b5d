//! Stage 1b, expansion: job lists (`jobs NAME(p: T) { … }`, LANGUAGE.md §8).
//!
//! A call `NAME(args)` in a row's jobs, in `pre`/`post`, in a shared row or
//! in another job list is replaced by the list's jobs with each parameter
//! replaced by its argument. Nothing after this stage knows job lists
//! existed: `double_command` and every lint see the expanded jobs.
//!
//! Replacing a parameter by its argument text is the same as passing the
//! argument's value (as a hook call does) only when nothing in the list
//! changes what the argument reads before the parameter is used; where it
//! could, or where the argument calls a hook (which would then run at each
//! use), the call is refused with a diagnostic rather than given another
//! meaning.

use crate::ast::{ControllerDef, EntryKind, Expr, ExprKind, Job, JobsDef, Name, Phase};
use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use crate::source::Span;

/// Inline every call of a job list of `def` and remove the lists.
pub(super) fn inline(def: &mut ControllerDef, diags: &mut Diagnostics) {
    let lists = take_lists(def, diags);
    if lists.is_empty() {
        return;
    }
    let expanded = expand_lists(&lists, diags);
    let ctx = Lists {
        lists: &lists,
        expanded: &expanded,
    };
    for entry in &mut def.entries {
        match &mut entry.kind {
            EntryKind::Plan(plan) => {
                for row in &mut plan.rows {
                    ctx.in_condition(row.cond.as_ref(), diags);
                    row.jobs = ctx.inline_jobs(std::mem::take(&mut row.jobs), None, diags);
                }
            }
            EntryKind::Rows(block) => {
                for row in &mut block.rows {
                    ctx.in_condition(row.cond.as_ref(), diags);
                    row.jobs = ctx.inline_jobs(std::mem::take(&mut row.jobs), None, diags);
                }
            }
            EntryKind::EveryCycle(block) => {
                let phase = Some(block.phase);
                block.jobs = ctx.inline_jobs(std::mem::take(&mut block.jobs), phase, diags);
            }
            EntryKind::Var { init: Some(e), .. } | EntryKind::StatusField { init: Some(e), .. } => {
                ctx.in_condition(Some(e), diags)
            }
            EntryKind::Command {
                accept: Some(a), ..
            } => ctx.in_condition(Some(&a.cond), diags),
            _ => {}
        }
    }
}

/// The controller's job lists, removed from its entries; a second list of
/// one name, or a list named like a hook, is an error.
fn take_lists(def: &mut ControllerDef, diags: &mut Diagnostics) -> Vec<JobsDef> {
    let hooks: Vec<Name> = def
        .entries
        .iter()
        .filter_map(|e| match &e.kind {
            EntryKind::Hook { name, .. } => Some(name.clone()),
            _ => None,
        })
        .collect();
    let mut lists: Vec<JobsDef> = Vec::new();
    def.entries.retain_mut(|e| {
        let EntryKind::Jobs(list) = &mut e.kind else {
            return true;
        };
        let list = std::mem::replace(
            list,
            JobsDef {
                name: list.name.clone(),
                params: Vec::new(),
                jobs: Vec::new(),
            },
        );
        let clash = lists
            .iter()
            .map(|l| &l.name)
            .chain(&hooks)
            .find(|n| n.text == list.name.text)
            .map(|n| n.span);
        match clash {
            Some(first) => diags.push(
                Diagnostic::error(
                    Code::DuplicateDefinition,
                    format!("`{}` is defined more than once", list.name.text),
                    list.name.span,
                    "a job list of this name",
                )
                .with_secondary(first, "first definition")
                .with_help("a job list, a hook and another job list are called alike: give each its own name"),
            ),
            None => lists.push(list),
        }
        false
    });
    lists
}

/// Each list's jobs with the calls to other lists inlined, in list order;
/// `None` for a list in a cycle of calls (reported once per cycle).
fn expand_lists(lists: &[JobsDef], diags: &mut Diagnostics) -> Vec<Option<Vec<Job>>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    struct Walk<'a> {
        lists: &'a [JobsDef],
        marks: Vec<Mark>,
        out: Vec<Option<Vec<Job>>>,
        stack: Vec<usize>,
    }
    impl Walk<'_> {
        fn visit(&mut self, i: usize, diags: &mut Diagnostics) {
            match self.marks[i] {
                Mark::Done => return,
                Mark::Open => {
                    let from = self.stack.iter().position(|&k| k == i).unwrap_or(0);
                    let ring: Vec<&str> = self.stack[from..]
                        .iter()
                        .chain(std::iter::once(&i))
                        .map(|&k| self.lists[k].name.text.as_str())
                        .collect();
                    let name = &self.lists[i].name;
                    diags.push(
                        Diagnostic::error(
                            Code::JobList,
                            format!("job list `{}` calls itself: {}", name.text, ring.join(" → ")),
                            name.span,
                            "recursive job list",
                        )
                        .with_help("a job list expands into the row that calls it, so it cannot call itself, directly or through another list"),
                    );
                    return;
                }
                Mark::New => {}
            }
            self.marks[i] = Mark::Open;
            self.stack.push(i);
            for callee in callees(&self.lists[i].jobs, self.lists) {
                self.visit(callee, diags);
            }
            self.stack.pop();
            // Inline with the callees' expansions (those in a cycle are left out).
            let done: Vec<Option<Vec<Job>>> = self.out.clone();
            let ctx = Lists {
                lists: self.lists,
                expanded: &done,
            };
            let body = self.lists[i].jobs.clone();
            let ok = callees(&body, self.lists).all(|k| done[k].is_some());
            self.out[i] = ok.then(|| ctx.inline_jobs(body, None, diags));
            self.marks[i] = Mark::Done;
        }
    }
    let mut walk = Walk {
        lists,
        marks: vec![Mark::New; lists.len()],
        out: vec![None; lists.len()],
        stack: Vec::new(),
    };
    for i in 0..lists.len() {
        walk.visit(i, diags);
    }
    walk.out
}

/// The lists that `jobs` call, by index.
fn callees<'a>(jobs: &'a [Job], lists: &'a [JobsDef]) -> impl Iterator<Item = usize> + 'a {
    jobs.iter().filter_map(|j| match j {
        Job::Call(Expr {
            kind: ExprKind::Call(name, _),
            ..
        }) => lists.iter().position(|l| l.name.text == name.text),
        _ => None,
    })
}

struct Lists<'a> {
    lists: &'a [JobsDef],
    expanded: &'a [Option<Vec<Job>>],
}

impl Lists<'_> {
    fn find(&self, name: &str) -> Option<usize> {
        self.lists.iter().position(|l| l.name.text == name)
    }

    /// A job list called inside an expression (a condition, an argument).
    fn in_condition(&self, e: Option<&Expr>, diags: &mut Diagnostics) {
        let Some(e) = e else { return };
        e.walk(&mut |x| {
            if let ExprKind::Call(name, _) = &x.kind {
                if self.find(&name.text).is_some() {
                    diags.push(
                        Diagnostic::error(
                            Code::JobList,
                            format!("job list `{}` is called inside an expression", name.text),
                            name.span,
                            "a job list gives no value",
                        )
                        .with_help(format!(
                            "call it as a job of a row, `pre` or `post`: `{{ {}(…) }}`",
                            name.text
                        )),
                    );
                }
            }
        });
    }

    /// `jobs` with every call of a list replaced by its jobs. `phase`: the
    /// jobs are a `pre`/`post` block's, where a list may not decide.
    fn inline_jobs(
        &self,
        jobs: Vec<Job>,
        phase: Option<Phase>,
        diags: &mut Diagnostics,
    ) -> Vec<Job> {
        let mut out = Vec::with_capacity(jobs.len());
        for job in jobs {
            for e in job_exprs_outside_call(&job) {
                self.in_condition(Some(e), diags);
            }
            let Job::Call(Expr {
                kind: ExprKind::Call(name, args),
                span,
            }) = &job
            else {
                out.push(job);
                continue;
            };
            let Some(i) = self.find(&name.text) else {
                args.iter().for_each(|a| self.in_condition(Some(a), diags));
                out.push(job);
                continue;
            };
            args.iter().for_each(|a| self.in_condition(Some(a), diags));
            let Some(body) = &self.expanded[i] else {
                continue; // in a cycle: reported on the list
            };
            let list = &self.lists[i];
            if args.len() != list.params.len() {
                diags.push(
                    Diagnostic::error(
                        Code::WrongArguments,
                        format!(
                            "job list `{}` takes {} argument{}, {} given",
                            list.name.text,
                            list.params.len(),
                            if list.params.len() == 1 { "" } else { "s" },
                            args.len()
                        ),
                        *span,
                        "wrong number of arguments",
                    )
                    .with_secondary(list.name.span, "the job list"),
                );
                continue;
            }
            let mut jobs = body.clone();
            let mut sound = true;
            for (param, arg) in list.params.iter().zip(args) {
                sound &= check_argument(&list.name, &param.name, arg, &jobs, diags);
            }
            if !sound {
                continue;
            }
            // All parameters at once: replaced one after another, an
            // argument naming a later parameter (`inner(y, x)` inside a
            // list with parameters `x, y`, or a var `y` passed for `x`)
            // would be replaced again.
            let bound: Vec<(&Name, &Expr)> =
                list.params.iter().map(|p| &p.name).zip(args).collect();
            for j in &mut jobs {
                substitute_job(j, &bound, diags);
            }
            if let Some(phase) = phase {
                jobs.retain(|j| {
                    let what = match j {
                        Job::Send { .. } | Job::Forward { .. } => "a command to a subordinate",
                        Job::Report(..) | Job::ReportCode(..) => "a `report`",
                        _ => return true,
                    };
                    diags.push(
                        Diagnostic::error(
                            Code::EveryCycleDecision,
                            format!(
                                "a `{}` block cannot call job list `{}`: it holds {what}, and `{}` runs every cycle, whatever the plan decides",
                                phase.keyword(),
                                list.name.text,
                                phase.keyword()
                            ),
                            *span,
                            format!("called in `{}`", phase.keyword()),
                        )
                        .with_secondary(job_span(j), format!("{what} in `{}`", list.name.text))
                        .with_help("call the list from the rows that decide, or move the command or report out of it"),
                    );
                    false
                });
            }
            out.extend(jobs);
        }
        out
    }
}

/// Whether replacing `param` by `arg` in `body` keeps the meaning of
/// passing `arg`'s value; a diagnostic when it does not.
fn check_argument(
    list: &Name,
    param: &Name,
    arg: &Expr,
    body: &[Job],
    diags: &mut Diagnostics,
) -> bool {
    let mut reads = Vec::new();
    let mut calls_hook = None;
    arg.walk(&mut |x| match &x.kind {
        ExprKind::Path(None, n) => reads.push(n.text.clone()),
        ExprKind::Call(n, _) if crate::builtin::Builtin::from_name(&n.text).is_none() => {
            calls_hook.get_or_insert(n.span);
        }
        _ => {}
    });
    if let Some(hook) = calls_hook {
        diags.push(
            Diagnostic::error(
                Code::JobList,
                format!("the argument for `{}` of job list `{}` calls a hook", param.text, list.text),
                arg.span,
                "a hook call as an argument",
            )
            .with_secondary(hook, "this call")
            .with_help("the list's jobs are written in place of the call, so the hook would run once per use of the parameter: assign its result to a var first and pass the var"),
        );
        return false;
    }
    let mut assigned: Vec<(&str, Span)> = Vec::new();
    for job in body {
        if uses(job, &param.text) {
            if let Some((root, at)) = assigned
                .iter()
                .find(|(root, _)| reads.iter().any(|r| r == root))
            {
                diags.push(
                    Diagnostic::error(
                        Code::JobList,
                        format!(
                            "job list `{}` changes `{root}` before it uses `{}`, and the argument reads `{root}`",
                            list.text, param.text
                        ),
                        arg.span,
                        format!("reads `{root}`"),
                    )
                    .with_secondary(*at, format!("`{root}` changed here"))
                    .with_help("the list's jobs are written in place of the call, so this use would see the new value: pass a var that the list does not change, or use the parameter before the assignment"),
                );
                return false;
            }
        }
        if let Job::Assign { place, .. } = job {
            if let Some(root) = place_root(place) {
                assigned.push((root, job_span(job)));
            }
        }
    }
    true
}

fn place_root(e: &Expr) -> Option<&str> {
    match &e.kind {
        ExprKind::Path(None, n) => Some(&n.text),
        ExprKind::Field(b, _) | ExprKind::Index(b, _) | ExprKind::Paren(b) => place_root(b),
        _ => None,
    }
}

fn uses(job: &Job, param: &str) -> bool {
    let mut found = false;
    for e in job_all_exprs(job) {
        e.walk(&mut |x| found |= matches!(&x.kind, ExprKind::Path(None, n) if n.text == param));
    }
    found || matches!(job, Job::ReportCode(_, code, _) if code.text == param)
}

fn job_span(j: &Job) -> Span {
    match j {
        Job::Send { span, .. }
        | Job::Report(_, span)
        | Job::Assign { span, .. }
        | Job::Forward { span, .. }
        | Job::ReportCode(_, _, span) => *span,
        Job::Call(e) => e.span,
    }
}

/// Every expression of a job, the assigned place included.
fn job_all_exprs(job: &Job) -> Vec<&Expr> {
    match job {
        Job::Send { args, .. } => args.iter().map(|(_, e)| e).collect(),
        Job::Assign { place, value, .. } => vec![place, value],
        Job::Call(e) => vec![e],
        Job::Report(..) | Job::Forward { .. } | Job::ReportCode(..) => Vec::new(),
    }
}

/// A job's expressions other than a call job's own call (its arguments
/// are looked at by the caller).
fn job_exprs_outside_call(job: &Job) -> Vec<&Expr> {
    match job {
        Job::Call(_) => Vec::new(),
        _ => job_all_exprs(job),
    }
}

/// Replace each parameter by its argument in a job, all at once.
fn substitute_job(job: &mut Job, bound: &[(&Name, &Expr)], diags: &mut Diagnostics) {
    match job {
        Job::Send { args, .. } => args.iter_mut().for_each(|(_, e)| substitute(e, bound)),
        Job::Assign { place, value, .. } => {
            let root = place_root(place);
            if let Some((param, _)) = bound.iter().find(|(p, _)| root == Some(p.text.as_str())) {
                diags.push(
                    Diagnostic::error(
                        Code::JobList,
                        format!("job list parameter `{}` is assigned to", param.text),
                        place.span,
                        "a parameter is a value, not a place",
                    )
                    .with_help("assign to a var or a `writes` buffer field instead"),
                );
            }
            substitute(place, bound);
            substitute(value, bound);
        }
        Job::Call(e) => substitute(e, bound),
        Job::ReportCode(_, code, _) => {
            if let Some((_, arg)) = bound.iter().find(|(p, _)| p.text == code.text) {
                if let ExprKind::Path(None, n) = &arg.kind {
                    *code = n.clone();
                }
            }
        }
        Job::Report(..) | Job::Forward { .. } => {}
    }
}

/// Replace each parameter named in `e` by its argument; an argument put in
/// is not looked into again.
fn substitute(e: &mut Expr, bound: &[(&Name, &Expr)]) {
    e.walk_mut(&mut |x| match &x.kind {
        ExprKind::Path(None, n) => match bound.iter().find(|(p, _)| p.text == n.text) {
            Some((_, arg)) => {
                *x = (*arg).clone();
                false
            }
            None => true,
        },
        _ => true,
    });
}
