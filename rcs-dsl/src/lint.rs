//! Lint levels: which findings of the checks are errors, warnings or
//! silent. Levels come, later overriding earlier, from the defaults, the
//! manifest's `lints:`, the command line (`-A/-W/-D`), then `#[allow]`-style
//! attributes on an item and on a plan.

use serde::Serialize;

/// A lint-controlled check. The order here is the catalogue order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Lint {
    RuleOfTen,
    ShadowedRow,
    UnreachableState,
    DeadEndState,
    NoDone,
    StateTypo,
    SpanOfControl,
    LevelOrder,
    FloatEquality,
    Unused,
    UnhandledError,
    IncompleteState,
    Livelock,
    CommandEveryCycle,
    StatusNeverReported,
    StaleSubordinateStatus,
    CommandOverwritten,
    AlwaysRejected,
    IndexRange,
    TimerResolution,
    IntWrap,
    DivByZero,
    NanPath,
    ReadBeforeAssign,
}

impl Lint {
    pub const ALL: [Lint; 24] = [
        Lint::RuleOfTen,
        Lint::ShadowedRow,
        Lint::UnreachableState,
        Lint::DeadEndState,
        Lint::NoDone,
        Lint::StateTypo,
        Lint::SpanOfControl,
        Lint::LevelOrder,
        Lint::FloatEquality,
        Lint::Unused,
        Lint::UnhandledError,
        Lint::IncompleteState,
        Lint::Livelock,
        Lint::CommandEveryCycle,
        Lint::StatusNeverReported,
        Lint::StaleSubordinateStatus,
        Lint::CommandOverwritten,
        Lint::AlwaysRejected,
        Lint::IndexRange,
        Lint::TimerResolution,
        Lint::IntWrap,
        Lint::DivByZero,
        Lint::NanPath,
        Lint::ReadBeforeAssign,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Lint::RuleOfTen => "rule_of_ten",
            Lint::ShadowedRow => "shadowed_row",
            Lint::UnreachableState => "unreachable_state",
            Lint::DeadEndState => "dead_end_state",
            Lint::NoDone => "no_done",
            Lint::StateTypo => "state_typo",
            Lint::SpanOfControl => "span_of_control",
            Lint::LevelOrder => "level_order",
            Lint::FloatEquality => "float_equality",
            Lint::Unused => "unused",
            Lint::UnhandledError => "unhandled_error",
            Lint::IncompleteState => "incomplete_state",
            Lint::Livelock => "livelock",
            Lint::CommandEveryCycle => "command_every_cycle",
            Lint::StatusNeverReported => "status_never_reported",
            Lint::StaleSubordinateStatus => "stale_subordinate_status",
            Lint::CommandOverwritten => "command_overwritten",
            Lint::AlwaysRejected => "always_rejected",
            Lint::IndexRange => "index_range",
            Lint::TimerResolution => "timer_resolution",
            Lint::IntWrap => "int_wrap",
            Lint::DivByZero => "div_by_zero",
            Lint::NanPath => "nan_path",
            Lint::ReadBeforeAssign => "read_before_assign",
        }
    }

    pub fn from_name(name: &str) -> Option<Lint> {
        Lint::ALL.into_iter().find(|l| l.name() == name)
    }

    pub fn default_level(self) -> Level {
        match self {
            Lint::RuleOfTen | Lint::ShadowedRow | Lint::StateTypo => Level::Deny,
            _ => Level::Warn,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Level {
    Allow,
    Warn,
    Deny,
}

impl Level {
    pub fn name(self) -> &'static str {
        match self {
            Level::Allow => "allow",
            Level::Warn => "warn",
            Level::Deny => "deny",
        }
    }

    pub fn from_name(name: &str) -> Option<Level> {
        match name {
            "allow" => Some(Level::Allow),
            "warn" => Some(Level::Warn),
            "deny" => Some(Level::Deny),
            _ => None,
        }
    }
}

/// One override: a lint set to a level (from a manifest, a flag or an attribute).
pub type LintOverride = (Lint, Level);

/// The lint levels in force for a whole plan set before attributes apply.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LintLevels {
    levels: [Level; Lint::ALL.len()],
}

impl Default for LintLevels {
    fn default() -> Self {
        LintLevels {
            levels: Lint::ALL.map(Lint::default_level),
        }
    }
}

impl LintLevels {
    pub fn set(&mut self, lint: Lint, level: Level) {
        self.levels[lint as usize] = level;
    }

    pub fn get(&self, lint: Lint) -> Level {
        self.levels[lint as usize]
    }

    /// The level at a place, given the attribute overrides of the enclosing
    /// scopes from outermost (item) to innermost (plan).
    pub fn at(&self, lint: Lint, scopes: &[&[LintOverride]]) -> Level {
        let mut level = self.get(lint);
        for scope in scopes {
            for &(l, lv) in scope.iter() {
                if l == lint {
                    level = lv;
                }
            }
        }
        level
    }
}
