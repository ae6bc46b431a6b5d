//! `rcs.yaml`, the optional manifest at a plan set's root. This is the one
//! module that touches YAML (through serde-saphyr); it yields a plain
//! [`Manifest`] with spans into the YAML file, and `manifest` diagnostics.
//!
//! Names of controllers are checked later, in `lower`, where they are known.

use crate::diagnostic::{Code, Diagnostic};
use crate::ir::Limits;
use crate::lint::{Level, Lint, LintOverride};
use crate::source::{FileId, SourceFile, Span};
use crate::yaml::{self, Spanned};
use serde::Deserialize;
use std::collections::BTreeMap;

/// The longest executive period, as the runtime accepts it.
const MAX_PERIOD_NS: u64 = rcs_runtime::exec::MAX_PERIOD.as_nanos() as u64;

/// The default executive period when the manifest gives no schedule.
pub const DEFAULT_PERIOD_NS: u64 = 10_000_000;

#[derive(Clone, Debug, Default)]
pub struct Manifest {
    pub system: Option<(String, Span)>,
    /// `plans:` entries (files or folders relative to the manifest).
    pub plans: Option<Vec<(String, Span)>>,
    /// `workspace:` entries: this manifest holds no plans of its own but
    /// names the folders (relative to it) that hold plan sets, as a Cargo
    /// virtual manifest lists its members.
    pub workspace: Option<Vec<(String, Span)>>,
    pub limits: Limits,
    pub lints: Vec<LintOverride>,
    pub schedule: Option<Vec<CpuSpec>>,
    /// The `schedule:` key, for diagnostics about the schedule as a whole.
    pub schedule_span: Option<Span>,
}

#[derive(Clone, Debug)]
pub struct CpuSpec {
    pub name: String,
    pub span: Span,
    pub period_ns: u64,
    /// Whether `period:` is given (always, once the manifest parses: a
    /// CPU without one is a `manifest` error).
    pub period_given: bool,
    pub order: Vec<(String, Span)>,
    /// `process:`: the program this CPU runs in (`None`: the default
    /// process, named after the system). See `docs/distribution.md`.
    pub process: Option<(String, Span)>,
    /// `inputs:`: external buffers (no controller writes them) that
    /// hand-written code in this CPU's process writes.
    pub inputs: Vec<(String, Span)>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    system: Option<Spanned<String>>,
    plans: Option<Vec<Spanned<String>>>,
    workspace: Option<Spanned<Vec<Spanned<String>>>>,
    limits: Option<RawLimits>,
    lints: Option<BTreeMap<String, Spanned<String>>>,
    schedule: Option<Spanned<Vec<RawCpu>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLimits {
    max_rules_per_plan: Option<Spanned<u32>>,
    max_subordinates: Option<Spanned<u32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCpu {
    cpu: Spanned<String>,
    period: Option<Spanned<String>>,
    order: Vec<Spanned<String>>,
    process: Option<Spanned<String>>,
    inputs: Option<Vec<Spanned<String>>>,
}

/// Parse a manifest. Every problem is a `manifest` diagnostic in `file`.
pub fn parse(id: FileId, file: &SourceFile) -> Result<Manifest, Vec<Diagnostic>> {
    let spanned = |loc: &yaml::Location| -> Span { yaml::span(id, file, loc) };
    if yaml::is_empty(&file.text) {
        return Ok(Manifest::default());
    }
    let raw: Raw = match yaml::from_str(&file.text) {
        Ok(raw) => raw,
        Err(e) => {
            let span = match &e.location {
                Some(loc) => spanned(loc),
                None => Span::new(id, 0, 0),
            };
            if let Some(d) = e
                .location
                .as_ref()
                .and_then(|loc| misindented(id, file, &e.message, loc))
            {
                return Err(vec![d]);
            }
            let (message, label) = describe_yaml_error(&e.message);
            let d = Diagnostic::error(
                Code::Manifest,
                format!("invalid `rcs.yaml`: {message}"),
                span,
                label,
            );
            // The list of keys helps with a misplaced key, not with broken YAML.
            let d = if label == "unknown key" || label == "here" && message.contains("field") {
                d.with_help(
                    "known keys: system, plans, workspace, limits {max_rules_per_plan, max_subordinates}, \
                     lints {LINT: allow|warn|deny}, schedule [{cpu, period, order, process, inputs}]",
                )
            } else {
                d.with_help(
                    "fix the YAML here: `key: value` pairs, lists as `[a, b]` or `- ` lines, \
                     the keys of one mapping indented alike",
                )
            };
            return Err(vec![d]);
        }
    };

    let mut diags = Vec::new();
    let mut m = Manifest {
        system: raw
            .system
            .map(|s| (s.value.clone(), spanned(&s.referenced))),
        plans: raw.plans.map(|ps| {
            ps.iter()
                .map(|p| (p.value.clone(), spanned(&p.referenced)))
                .collect()
        }),
        workspace: raw.workspace.as_ref().map(|ws| {
            ws.value
                .iter()
                .map(|w| (w.value.clone(), spanned(&w.referenced)))
                .collect()
        }),
        ..Manifest::default()
    };
    if let Some(ws) = &raw.workspace {
        let others = [
            ("system", m.system.is_some()),
            ("plans", m.plans.is_some()),
            ("limits", raw.limits.is_some()),
            ("lints", raw.lints.is_some()),
            ("schedule", raw.schedule.is_some()),
        ];
        let others: Vec<&str> = others.iter().filter(|o| o.1).map(|o| o.0).collect();
        if !others.is_empty() {
            diags.push(
                Diagnostic::error(
                    Code::Manifest,
                    format!(
                        "a workspace manifest holds only `workspace:`, but this one also has {}",
                        others
                            .iter()
                            .map(|k| format!("`{k}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                    key_span(file, id, spanned(&ws.referenced), "workspace"),
                    "this makes the folder a workspace",
                )
                .with_help(
                    "put the plan set's keys into the `rcs.yaml` of each member folder, \
                     or drop `workspace:` to make this folder one plan set",
                ),
            );
        }
        if ws.value.is_empty() {
            diags.push(Diagnostic::error(
                Code::Manifest,
                "`workspace:` lists no folders",
                key_span(file, id, spanned(&ws.referenced), "workspace"),
                "empty list",
            ));
        }
    }
    if let Some((name, span)) = &m.system {
        if !is_identifier(name) {
            diags.push(
                Diagnostic::error(
                    Code::Manifest,
                    format!("system name `{name}` is not an identifier"),
                    *span,
                    "used as a Rust module name",
                )
                .with_help("use letters, digits and `_`, not starting with a digit"),
            );
        }
    }
    if let Some(limits) = raw.limits {
        if let Some(v) = limits.max_rules_per_plan {
            m.limits.max_rules_per_plan = v.value;
        }
        if let Some(v) = limits.max_subordinates {
            m.limits.max_subordinates = v.value;
        }
    }
    for (name, level) in raw.lints.into_iter().flatten() {
        let span = spanned(&level.referenced);
        match (Lint::from_name(&name), Level::from_name(&level.value)) {
            (Some(lint), Some(lv)) => m.lints.push((lint, lv)),
            (None, _) => diags.push(
                Diagnostic::error(
                    Code::Manifest,
                    format!("unknown lint `{name}` in `lints`"),
                    key_span(file, id, span, &name),
                    "not a lint",
                )
                .with_help(format!(
                    "the lints are: {}",
                    Lint::ALL.map(Lint::name).join(", ")
                )),
            ),
            (Some(_), None) => diags.push(Diagnostic::error(
                Code::Manifest,
                format!("unknown lint level `{}`", level.value),
                span,
                "expected `allow`, `warn` or `deny`",
            )),
        }
    }
    if let Some(schedule) = raw.schedule {
        m.schedule_span = Some(spanned(&schedule.referenced));
        let mut cpus = Vec::new();
        for cpu in schedule.value {
            let span = spanned(&cpu.cpu.referenced);
            let period_ns = match &cpu.period {
                None => {
                    // A CPU of a schedule is an executive someone placed:
                    // its period is theirs to choose, and one left out
                    // would count every time in a period nobody chose.
                    diags.push(
                        Diagnostic::error(
                            Code::Manifest,
                            format!("CPU `{}` has no `period:`", cpu.cpu.value),
                            key_span(file, id, span, "cpu"),
                            "this schedule entry gives no period",
                        )
                        .with_help(format!(
                            "give its period, with a unit: `{{ cpu: {}, period: 10ms, order: [...] }}` \
                             (10ms is the default only of a plan set without `schedule:`)",
                            cpu.cpu.value
                        )),
                    );
                    DEFAULT_PERIOD_NS
                }
                Some(p) => match parse_duration(&p.value) {
                    Some(ns) if ns > MAX_PERIOD_NS => {
                        diags.push(
                            Diagnostic::error(
                                Code::Manifest,
                                format!("period `{}` is too long", p.value),
                                spanned(&p.referenced),
                                "longer than an hour",
                            )
                            .with_help("an executive's period is at most `3600s` (one hour)"),
                        );
                        DEFAULT_PERIOD_NS
                    }
                    Some(ns) if ns > 0 => ns,
                    _ => {
                        diags.push(
                            Diagnostic::error(
                                Code::Manifest,
                                format!("bad period `{}`", p.value),
                                spanned(&p.referenced),
                                "not a duration",
                            )
                            .with_help("write a positive number with a unit: `30ms`, `500us`, `1s`, `250000ns`"),
                        );
                        DEFAULT_PERIOD_NS
                    }
                },
            };
            if cpus.iter().any(|c: &CpuSpec| c.name == cpu.cpu.value) {
                diags.push(Diagnostic::error(
                    Code::Manifest,
                    format!("CPU `{}` is scheduled twice", cpu.cpu.value),
                    span,
                    "second entry for this CPU",
                ));
            }
            let process = cpu
                .process
                .as_ref()
                .map(|p| (p.value.clone(), spanned(&p.referenced)));
            if let Some((name, span)) = &process {
                diags.extend(crate::placement::check_process_name(name, *span));
            }
            cpus.push(CpuSpec {
                process,
                inputs: cpu
                    .inputs
                    .iter()
                    .flatten()
                    .map(|i| (i.value.clone(), spanned(&i.referenced)))
                    .collect(),
                name: cpu.cpu.value.clone(),
                span,
                period_ns,
                period_given: cpu.period.is_some(),
                order: cpu
                    .order
                    .iter()
                    .map(|o| (o.value.clone(), spanned(&o.referenced)))
                    .collect(),
            });
        }
        m.schedule = Some(cpus);
    }
    if diags.is_empty() {
        Ok(m)
    } else {
        Err(diags)
    }
}

/// Any serialisable value as YAML (`rcsc ir`), through the same library
/// that reads manifests, so the project has one YAML dependency.
pub fn to_yaml<T: serde::Serialize>(value: &T) -> Result<String, serde_saphyr::SerializeError> {
    yaml::to_string(value)
}

/// `30ms`, `1.5s`, `500us`/`500µs`, `100ns`, in nanoseconds.
pub fn parse_duration(text: &str) -> Option<u64> {
    let text = text.trim();
    let split = text.find(|c: char| !(c.is_ascii_digit() || c == '.'))?;
    let (num, unit) = text.split_at(split);
    let scale: f64 = match unit.trim() {
        "ns" => 1.0,
        "us" | "µs" => 1e3,
        "ms" => 1e6,
        "s" => 1e9,
        _ => return None,
    };
    let v: f64 = num.parse().ok()?;
    let ns = v * scale;
    (1.0..1e18).contains(&ns).then_some(ns.round() as u64)
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The key of a `key: value` pair, found on the value's line before it
/// (the YAML library gives spans for values only); the value's span if not found.
fn key_span(file: &SourceFile, id: FileId, value: Span, key: &str) -> Span {
    let start = value.start as usize;
    let line_start = file.text[..start].rfind('\n').map_or(0, |i| i + 1);
    match file.text[line_start..start].rfind(key) {
        Some(i) => Span::new(id, line_start + i, line_start + i + key.len()),
        None => value,
    }
}

/// A YAML error that a mis-indented key caused, said at that key: what
/// the library reported is kept as a note, with what YAML made of the key.
fn misindented(
    id: FileId,
    file: &SourceFile,
    message: &str,
    loc: &yaml::Location,
) -> Option<Diagnostic> {
    let (line, column) = (loc.line() as usize, loc.column() as usize);
    let (m, saw) = if let Some(key) = message
        .strip_prefix("missing field `")
        .and_then(|r| r.strip_suffix('`'))
    {
        let m = crate::yaml_layout::missing_key_elsewhere(&file.text, key, line, column)?;
        let saw = if m.indent < m.expected {
            format!(
                "YAML ended the mapping that holds `{}:` before this line, so that mapping has no `{key}`",
                m.sibling
            )
        } else {
            format!("YAML read `{key}:` as part of the value before it, then found `{key}` missing in the mapping of `{}:`", m.sibling)
        };
        (m, saw)
    } else if message.starts_with("mapping values are not allowed") {
        let m = crate::yaml_layout::key_under_a_value(&file.text, line)?;
        let saw = format!(
            "YAML read this line as more of the value of `{}:` on the line above, where a key cannot start",
            m.sibling
        );
        (m, saw)
    } else {
        return None;
    };
    let key = &file.text[m.start..m.end];
    Some(
        Diagnostic::error(
            Code::Manifest,
            format!(
                "invalid `rcs.yaml`: `{key}:` is indented {} spaces, but `{}:` {}",
                m.indent, m.sibling, m.expected
            ),
            Span::new(id, m.start, m.end),
            "mis-indented key",
        )
        .with_note(saw)
        .with_note(format!("the YAML library said: {message} (line {line})"))
        .with_help(format!(
            "indent `{key}:` by {} spaces, as `{}:`",
            m.expected, m.sibling
        )),
    )
}

/// The YAML library's message in the manifest's words, and a label for it.
fn describe_yaml_error(message: &str) -> (String, &'static str) {
    // The location is shown by the snippet; drop the library's copy of it.
    let message = match message.rfind(" at line ") {
        Some(i) if message[i..].contains(", column ") => &message[..i],
        _ => message,
    };
    if let Some(rest) = message.strip_prefix("unknown field ") {
        return (
            format!(
                "unknown key {}",
                rest.replace(", expected one of ", "; expected one of: ")
            ),
            "unknown key",
        );
    }
    if message.starts_with("invalid u32") || message.starts_with("invalid u64") {
        return ("expected a whole number".to_string(), "not a whole number");
    }
    (message.to_string(), "here")
}
