//! Diagnostics: what every stage of the pipeline returns instead of
//! failing. The library only collects them; the CLI (or build.rs `Config`)
//! renders them with [`crate::render`].
//!
//! Every diagnostic has a stable [`Code`] from one catalogue, a severity, a
//! primary span with a label, optional secondary spans, notes and a help line.

use crate::lint::{Level, Lint};
use crate::source::{SourceMap, Span};
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    Error,
    Warning,
    /// Information, neither an error nor a warning (the default period a
    /// controller's times are counted in).
    Note,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "note",
        }
    }
}

/// The catalogue of diagnostic codes. Codes are stable: tests, CI and
/// editors key on [`Code::name`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Code {
    Syntax,
    DuplicateDefinition,
    UnknownName,
    UnknownCommand,
    UnknownSubordinate,
    TypeMismatch,
    WrongArguments,
    AssignToInput,
    RowNumber,
    OtherwiseNotLast,
    EntryMissing,
    EntryNotFirst,
    UnreachableRow,
    DoubleCommand,
    MissingPlan,
    MultipleSupervisors,
    HierarchyCycle,
    MultipleWriters,
    BufferTypeConflict,
    Manifest,
    LooseFile,
    TooLarge,
    CaseCollision,
    NotConstant,
    ConstCycle,
    ReservedName,
    PlanVerbsDiffer,
    ForwardMismatch,
    Lint(Lint),
    EveryCycleDecision,
    EveryCycleTwice,
    Placement,
    SharedRows,
    JobList,
    Instance,
    AcceptCondition,
    NoPlans,
}

impl Code {
    /// Every hard-error code, in catalogue order (lints follow in [`Lint::ALL`]).
    pub const ERRORS: [Code; 36] = [
        Code::Syntax,
        Code::DuplicateDefinition,
        Code::UnknownName,
        Code::UnknownCommand,
        Code::UnknownSubordinate,
        Code::TypeMismatch,
        Code::WrongArguments,
        Code::AssignToInput,
        Code::RowNumber,
        Code::OtherwiseNotLast,
        Code::EntryMissing,
        Code::EntryNotFirst,
        Code::UnreachableRow,
        Code::DoubleCommand,
        Code::MissingPlan,
        Code::MultipleSupervisors,
        Code::HierarchyCycle,
        Code::MultipleWriters,
        Code::BufferTypeConflict,
        Code::Manifest,
        Code::LooseFile,
        Code::TooLarge,
        Code::CaseCollision,
        Code::NotConstant,
        Code::ConstCycle,
        Code::ReservedName,
        Code::PlanVerbsDiffer,
        Code::ForwardMismatch,
        Code::EveryCycleDecision,
        Code::EveryCycleTwice,
        Code::Placement,
        Code::SharedRows,
        Code::JobList,
        Code::Instance,
        Code::AcceptCondition,
        Code::NoPlans,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Code::Syntax => "syntax",
            Code::DuplicateDefinition => "duplicate_definition",
            Code::UnknownName => "unknown_name",
            Code::UnknownCommand => "unknown_command",
            Code::UnknownSubordinate => "unknown_subordinate",
            Code::TypeMismatch => "type_mismatch",
            Code::WrongArguments => "wrong_arguments",
            Code::AssignToInput => "assign_to_input",
            Code::RowNumber => "row_number",
            Code::OtherwiseNotLast => "otherwise_not_last",
            Code::EntryMissing => "entry_missing",
            Code::EntryNotFirst => "entry_not_first",
            Code::UnreachableRow => "unreachable_row",
            Code::DoubleCommand => "double_command",
            Code::MissingPlan => "missing_plan",
            Code::MultipleSupervisors => "multiple_supervisors",
            Code::HierarchyCycle => "hierarchy_cycle",
            Code::MultipleWriters => "multiple_writers",
            Code::BufferTypeConflict => "buffer_type_conflict",
            Code::Manifest => "manifest",
            Code::LooseFile => "loose_file",
            Code::TooLarge => "too_large",
            Code::CaseCollision => "case_collision",
            Code::NotConstant => "not_constant",
            Code::ConstCycle => "const_cycle",
            Code::ReservedName => "reserved_name",
            Code::PlanVerbsDiffer => "plan_verbs_differ",
            Code::ForwardMismatch => "forward_mismatch",
            Code::Lint(l) => l.name(),
            Code::EveryCycleDecision => "every_cycle_decision",
            Code::EveryCycleTwice => "every_cycle_twice",
            Code::Placement => "placement",
            Code::SharedRows => "shared_rows",
            Code::JobList => "job_list",
            Code::Instance => "instance",
            Code::AcceptCondition => "accept_condition",
            Code::NoPlans => "no_plans",
        }
    }

    /// One line saying what the code means, for `docs/` and `--explain`.
    pub fn summary(self) -> &'static str {
        match self {
            Code::Syntax => "the text does not parse",
            Code::DuplicateDefinition => "two definitions share one name",
            Code::UnknownName => "a name is not declared",
            Code::UnknownCommand => "a verb the controller does not declare",
            Code::UnknownSubordinate => "a controller that is not a subordinate here",
            Code::TypeMismatch => "the types of an expression disagree",
            Code::WrongArguments => "missing, extra or repeated arguments",
            Code::AssignToInput => "a job assigns to an input",
            Code::RowNumber => "a row's number is not its precedence position",
            Code::OtherwiseNotLast => "`otherwise` is not the single last row",
            Code::EntryMissing => "no row handles a new command",
            Code::EntryNotFirst => "a new-command row stands after an ordinary row",
            Code::UnreachableRow => "a row can never match",
            Code::DoubleCommand => "one row commands a subordinate twice",
            Code::MissingPlan => "a command has no plan",
            Code::MultipleSupervisors => "a controller has two supervisors",
            Code::HierarchyCycle => "a controller is above itself",
            Code::MultipleWriters => "a buffer has two writers",
            Code::BufferTypeConflict => "one buffer name has two types",
            Code::Manifest => "`rcs.yaml` is malformed",
            Code::LooseFile => "a `.rcs` file stands beside plan-set folders",
            Code::TooLarge => {
                "a plan or controller has more of something than the runtime can number"
            }
            Code::CaseCollision => {
                "two names differ only in case where they become one output file name"
            }
            Code::NotConstant => "a `const` or an array length is not a constant expression",
            Code::ConstCycle => "constants are defined in terms of each other",
            Code::ReservedName => "a declaration takes the name of a built-in function",
            Code::PlanVerbsDiffer => "the verbs of one plan do not have the same parameters",
            Code::ForwardMismatch => "a forwarded command is not declared alike by the subordinate",
            Code::Lint(Lint::RuleOfTen) => "a plan has more rows than the rule of ten allows",
            Code::Lint(Lint::ShadowedRow) => "earlier rows always match before this row",
            Code::Lint(Lint::UnreachableState) => "no path from the entry reaches a state",
            Code::Lint(Lint::DeadEndState) => "a state has no way out",
            Code::Lint(Lint::NoDone) => "a plan never reaches `Done` or `Error`",
            Code::Lint(Lint::StateTypo) => {
                "a state named once is one edit from another state, `Done`, `Error` or `same`: a typo"
            }
            Code::Lint(Lint::SpanOfControl) => "a supervisor has too many subordinates",
            Code::Lint(Lint::LevelOrder) => "a subordinate's level is not below its supervisor's",
            Code::Lint(Lint::FloatEquality) => "floats compared with `==` or `!=`",
            Code::Lint(Lint::Unused) => "a declaration is never used",
            Code::Lint(Lint::UnhandledError) => {
                "a state waits for a subordinate that can fail, and nothing handles the failure"
            }
            Code::Lint(Lint::IncompleteState) => {
                "with some command values no row of a reachable state can ever fire: the plan hangs"
            }
            Code::Lint(Lint::Livelock) => {
                "rows move between states every cycle, so no other row can ever fire"
            }
            Code::Lint(Lint::CommandEveryCycle) => {
                "a command is sent again every cycle while the subordinate executes it"
            }
            Code::Lint(Lint::StatusNeverReported) => {
                "a supervisor waits for a status the subordinate never reports"
            }
            Code::Lint(Lint::StaleSubordinateStatus) => {
                "a row can read a subordinate's answer to an earlier command"
            }
            Code::Lint(Lint::CommandOverwritten) => {
                "a subordinate is commanded again before its answer to the last command is read"
            }
            Code::Lint(Lint::AlwaysRejected) => {
                "a command is sent that the subordinate always answers with ERROR at once"
            }
            Code::Lint(Lint::IndexRange) => "an index by a run-time value can fall outside its array",
            Code::Lint(Lint::TimerResolution) => {
                "a duration is not a whole number of the CPU's periods: the comparison fires later than written"
            }
            Code::Lint(Lint::IntWrap) => {
                "an integer job wraps, and the wrapped value reaches a condition, a send or an output"
            }
            Code::Lint(Lint::DivByZero) => {
                "a divisor can be 0 (the quotient is then 0) where the result reaches a condition, a send or an output"
            }
            Code::Lint(Lint::NanPath) => {
                "a float becomes NaN and then latches the plan in its state, or is sent or published"
            }
            Code::Lint(Lint::ReadBeforeAssign) => {
                "a row reads a var the command's jobs set later, while it still holds an earlier command's value"
            }
            Code::EveryCycleDecision => {
                "a `pre` or `post` block sends, reports or changes state: decisions belong in the rows"
            }
            Code::EveryCycleTwice => "a controller has two `pre` or two `post` blocks",
            Code::Placement => {
                "a CPU's `process:` or `inputs:` in `rcs.yaml` does not place it"
            }
            Code::SharedRows => {
                "a `rows` block or a `use` is written wrongly: a label or `use` inside a block, an unknown block"
            }
            Code::JobList => {
                "a job list is called where it cannot be, calls itself, or is given an argument it would change"
            }
            Code::Instance => {
                "an instance names no controller type, or binds its buffers and subordinates wrongly"
            }
            Code::AcceptCondition => {
                "an `accept when` condition calls a hook or reads a plan quantity of the plan it may replace"
            }
            Code::NoPlans => "a plan set holds no `.rcs` file",
        }
    }

    pub fn from_name(name: &str) -> Option<Code> {
        Code::ERRORS
            .into_iter()
            .find(|c| c.name() == name)
            .or_else(|| Lint::from_name(name).map(Code::Lint))
    }
}

/// A labelled span. The primary label says what is wrong; secondary labels
/// point at related places ("first defined here").
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Label {
    pub span: Span,
    pub message: String,
    pub primary: bool,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnostic {
    pub code: Code,
    pub severity: Severity,
    pub message: String,
    /// The primary label comes first; there is always exactly one.
    pub labels: Vec<Label>,
    pub notes: Vec<String>,
    pub help: Option<String>,
    /// For a finding that something can happen: the concrete inputs of one
    /// cycle that make it happen (also shown as a note).
    pub witness: Option<Witness>,
    /// A machine-applicable edit that makes the diagnostic go away ("did
    /// you mean", a row number): what an editor offers as a quick fix.
    /// Not part of the rendered or JSON output, which say it in the help.
    #[serde(skip)]
    pub fix: Option<Fix>,
}

/// Replace `was` inside `span` by `with`. `was` is kept so that a client
/// applying the fix to a text that moved on can tell it no longer applies.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Fix {
    pub span: Span,
    pub was: String,
    pub with: String,
}

/// The inputs of one cycle that make a finding happen, as the language
/// writes them, in the state it happens in.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Witness {
    pub state: String,
    pub inputs: Vec<WitnessInput>,
    /// The same finding reproduced from a fresh controller, step by step,
    /// when one was found and replayed (what `rcsc check --witnesses`
    /// writes as a scenario).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run: Option<crate::analysis::run::Run>,
    /// For a finding between a supervisor and a subordinate: what a run of
    /// the supervisor's whole subtree needs of the subordinate. Set by the
    /// check, read once to compose `system`.
    #[serde(skip)]
    pub across: Option<Across>,
    /// The same finding reproduced with the supervisor's whole subtree
    /// running, the subordinate playing its own plan: a system scenario,
    /// replayed on the interpreter before it is kept (what `rcsc check
    /// --witnesses` writes for such a finding).
    #[serde(skip)]
    pub system: Option<crate::scenario::SystemScript>,
}

/// The `for example, in state S: a = 1, b = 2` note of a witness.
fn example_note<'a>(state: &str, inputs: impl Iterator<Item = (&'a str, &'a str)>) -> String {
    let shown: Vec<String> = inputs.map(|(n, v)| format!("{n} = {v}")).collect();
    format!("for example, in state {state}: {}", shown.join(", "))
}

impl Witness {
    /// The note [`Diagnostic::with_witness`] adds for this witness: a
    /// renderer that shows the witness itself leaves that note out.
    pub fn example_note(&self) -> String {
        example_note(
            &self.state,
            self.inputs
                .iter()
                .map(|i| (i.name.as_str(), i.value.as_str())),
        )
    }
}

/// What a cross-controller finding's system run needs of the subordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct Across {
    pub sub: crate::ir::CtrlId,
    /// The status it must show at the end of the run, by name (`ERROR`,
    /// `DONE`, a declared status); `None`: not compared.
    pub shows: Option<String>,
    /// A run of the supervisor, before the finding's own, that commands
    /// the subordinate: it answers that command as the finding's run then
    /// reads (`stale_subordinate_status`: an earlier command's answer).
    pub earlier: Option<crate::analysis::run::Run>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WitnessInput {
    pub name: String,
    pub value: String,
}

impl Diagnostic {
    /// An error with its primary label.
    pub fn error(
        code: Code,
        message: impl Into<String>,
        span: Span,
        label: impl Into<String>,
    ) -> Self {
        Diagnostic {
            code,
            severity: Severity::Error,
            message: message.into(),
            labels: vec![Label {
                span,
                message: label.into(),
                primary: true,
            }],
            notes: Vec::new(),
            help: None,
            witness: None,
            fix: None,
        }
    }

    /// A lint finding; its severity is settled by [`Diagnostic::at_level`].
    pub fn lint(
        lint: Lint,
        message: impl Into<String>,
        span: Span,
        label: impl Into<String>,
    ) -> Self {
        let mut d = Diagnostic::error(Code::Lint(lint), message, span, label);
        d.severity = Severity::Warning;
        d
    }

    /// A note: information the user should have, counted as neither error
    /// nor warning.
    pub fn note(
        code: Code,
        message: impl Into<String>,
        span: Span,
        label: impl Into<String>,
    ) -> Self {
        let mut d = Diagnostic::error(code, message, span, label);
        d.severity = Severity::Note;
        d
    }

    pub fn with_secondary(mut self, span: Span, label: impl Into<String>) -> Self {
        self.labels.push(Label {
            span,
            message: label.into(),
            primary: false,
        });
        self
    }

    /// The quick fix: `was` (a whole word inside the primary span) becomes
    /// `with`.
    pub fn with_fix(mut self, was: impl Into<String>, with: impl Into<String>) -> Self {
        let span = self.labels.first().map(|l| l.span);
        if let Some(span) = span {
            self.fix = Some(Fix {
                span,
                was: was.into(),
                with: with.into(),
            });
        }
        self
    }

    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    /// The witness of a "can happen" finding, also as a `for example:` note.
    pub fn with_witness(mut self, state: &str, inputs: &[(String, String)]) -> Self {
        self.notes.push(example_note(
            state,
            inputs.iter().map(|(n, v)| (n.as_str(), v.as_str())),
        ));
        self.witness = Some(Witness {
            state: state.to_string(),
            inputs: inputs
                .iter()
                .map(|(name, value)| WitnessInput {
                    name: name.clone(),
                    value: value.clone(),
                })
                .collect(),
            run: None,
            across: None,
            system: None,
        });
        self
    }

    /// What a run of the whole subtree needs of the subordinate (after
    /// [`Diagnostic::with_run`]).
    pub fn with_across(mut self, across: Across) -> Self {
        if let Some(w) = &mut self.witness {
            w.across = Some(across);
        }
        self
    }

    /// The run that reproduces the finding, on its witness (set by
    /// [`Diagnostic::with_witness`] first).
    pub fn with_run(mut self, run: Option<crate::analysis::run::Run>) -> Self {
        if let Some(w) = &mut self.witness {
            w.run = run;
        }
        self
    }

    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    pub fn primary_span(&self) -> Span {
        self.labels[0].span
    }

    /// Apply a lint level: `None` when the lint is allowed here.
    /// `is_default` says whether the level is the lint's default (rustc's
    /// "on by default" note) or was set by the manifest, a flag or an attribute.
    pub fn at_level(mut self, level: Level, is_default: bool) -> Option<Diagnostic> {
        let name = self.code.name();
        let how = if is_default {
            "on by default"
        } else {
            "set for this scope"
        };
        let (severity, note) = match level {
            Level::Allow => return None,
            Level::Warn => (Severity::Warning, format!("`#[warn({name})]` {how}")),
            Level::Deny => (Severity::Error, format!("`#[deny({name})]` {how}")),
        };
        self.severity = severity;
        self.notes.push(note);
        Some(self)
    }
}

/// The one list every check pushes into.
#[derive(Clone, Debug, Default)]
pub struct Diagnostics {
    list: Vec<Diagnostic>,
}

impl Diagnostics {
    pub fn new() -> Self {
        Diagnostics::default()
    }

    pub fn push(&mut self, d: Diagnostic) {
        self.list.push(d);
    }

    /// The diagnostic pushed last, to add a help line or label to it.
    pub fn last_mut(&mut self) -> Option<&mut Diagnostic> {
        self.list.last_mut()
    }

    pub fn has_errors(&self) -> bool {
        self.list.iter().any(|d| d.severity == Severity::Error)
    }

    pub fn error_count(&self) -> usize {
        self.list
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .count()
    }

    pub fn warning_count(&self) -> usize {
        self.list
            .iter()
            .filter(|d| d.severity == Severity::Warning)
            .count()
    }

    pub fn iter(&self) -> impl Iterator<Item = &Diagnostic> {
        self.list.iter()
    }

    /// Of the diagnostics from position `start` on, keep those `keep` says
    /// (one flag each, in order; missing flags keep).
    pub fn keep_from(&mut self, start: usize, keep: &[bool]) {
        let mut i = 0;
        self.list.retain(|_| {
            let kept = i < start || keep.get(i - start).copied().unwrap_or(true);
            i += 1;
            kept
        });
    }

    /// The diagnostics from position `start` on, to amend.
    pub fn since_mut(&mut self, start: usize) -> &mut [Diagnostic] {
        let start = start.min(self.list.len());
        &mut self.list[start..]
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    pub fn len(&self) -> usize {
        self.list.len()
    }

    pub fn extend(&mut self, other: Diagnostics) {
        self.list.extend(other.list);
    }

    /// Order a stage's findings by where they point (file path, offset),
    /// then by code, so output never depends on traversal details.
    pub fn sort_from(&mut self, start: usize, sources: &SourceMap) {
        self.list[start..].sort_by(|a, b| {
            let ka = sources.order_key(a.primary_span());
            let kb = sources.order_key(b.primary_span());
            ka.cmp(&kb)
                .then(a.primary_span().end.cmp(&b.primary_span().end))
                .then(a.code.cmp(&b.code))
        });
    }

    pub fn into_vec(self) -> Vec<Diagnostic> {
        self.list
    }
}
