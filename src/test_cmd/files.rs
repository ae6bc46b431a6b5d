//! Which scenario files `rcsc test` runs for which plan set — those named
//! on the command line, else each set's `scenarios/` folder — and reading
//! each into a scenario of the IR (or the error that stops it).

use rcs_dsl::ir::Ir;
use rcs_dsl::scenario::{self, AnyScenario};
use rcs_dsl::source::SourceFile;
use rcs_dsl::PlanSet;
use std::path::{Path, PathBuf};

/// What to run: plan-set paths, and scenario files named explicitly.
#[derive(Debug, Default, PartialEq)]
pub struct Targets {
    pub plan_paths: Vec<PathBuf>,
    pub scenarios: Vec<PathBuf>,
}

/// Whether a path names a scenario file.
fn is_scenario(path: &Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy())
        .unwrap_or_default();
    name.ends_with(".scenario.yaml") || name.ends_with(".scenario.yml")
}

/// The `*.scenario.yaml` files of a folder, sorted.
fn scenarios_in(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(format!("cannot read {}: {e}", rcs_dsl::load::display(dir))),
    };
    let mut out = Vec::new();
    for entry in entries {
        let path = entry
            .map_err(|e| format!("cannot read {}: {e}", rcs_dsl::load::display(dir)))?
            .path();
        if path.is_file() && is_scenario(&path) {
            out.push(path);
        }
    }
    out.sort();
    Ok(out)
}

/// Split the command line into plan sets and scenarios. A `scenarios/`
/// folder stands for its scenario files; a scenario named without any
/// plan set tests the set it lives in (the folder above `scenarios/`, or
/// the nearest folder with an `rcs.yaml`).
pub fn targets(paths: Vec<PathBuf>) -> Result<Targets, String> {
    let mut t = Targets::default();
    for p in paths {
        if is_scenario(&p) {
            t.scenarios.push(p);
        } else if p.is_dir() && p.file_name().is_some_and(|n| n == "scenarios") {
            t.scenarios.extend(scenarios_in(&p)?);
        } else {
            t.plan_paths.push(p);
        }
    }
    if t.plan_paths.is_empty() {
        let mut homes = Vec::new();
        for s in &t.scenarios {
            let home = home_of(s).ok_or_else(|| {
                format!(
                    "cannot tell which plan set {} tests; name the plan set too (`rcsc test PLANS {}`)",
                    rcs_dsl::load::display(s),
                    rcs_dsl::load::display(s)
                )
            })?;
            if !homes.contains(&home) {
                homes.push(home);
            }
        }
        t.plan_paths = homes;
    }
    if t.plan_paths.is_empty() {
        t.plan_paths.push(PathBuf::from("."));
    }
    Ok(t)
}

/// The plan-set folder a scenario file belongs to.
fn home_of(scenario: &Path) -> Option<PathBuf> {
    let dir = scenario.parent()?;
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    if dir.file_name().is_some_and(|n| n == "scenarios") {
        let up = dir.parent()?;
        return Some(if up.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            up.to_path_buf()
        });
    }
    dir.ancestors()
        .find(|a| a.join("rcs.yaml").is_file())
        .map(Path::to_path_buf)
}

/// The scenario files of a plan set's own `scenarios/` folder, sorted
/// (what `rcsc test` runs for it when none are named).
fn own_scenarios(set: &PlanSet) -> Result<Vec<PathBuf>, String> {
    scenarios_in(&set_folder(set).join("scenarios"))
}

/// [`own_scenarios`] with their texts; `Err`, saying which, when one
/// cannot be read (a renumbering must see every scenario or none).
pub fn own_scenario_texts(set: &PlanSet) -> Result<Vec<(PathBuf, String)>, String> {
    own_scenarios(set)?
        .into_iter()
        .map(|path| match std::fs::read_to_string(&path) {
            Ok(text) => Ok((path, text)),
            Err(e) => Err(format!(
                "cannot read {}: {e}",
                rcs_dsl::load::display(&path)
            )),
        })
        .collect()
}

/// The folder a plan set's `scenarios/` sits in.
pub(super) fn set_folder(set: &PlanSet) -> PathBuf {
    if !set.root.is_empty() {
        return PathBuf::from(&set.root);
    }
    // Loose files: the folder of the first one.
    set.rcs_files
        .first()
        .and_then(|f| Path::new(&set.sources.get(*f).path).parent())
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn same_place(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// Scenario files per plan set: those named for it, else its `scenarios/`.
pub fn assign(sets: &[PlanSet], named: &[PathBuf]) -> Result<Vec<Vec<PathBuf>>, String> {
    let folders: Vec<PathBuf> = sets.iter().map(set_folder).collect();
    let mut per_set = vec![Vec::new(); sets.len()];
    for s in named {
        let home = home_of(s);
        let i = match home
            .as_ref()
            .and_then(|h| folders.iter().position(|f| same_place(f, h)))
        {
            Some(i) => i,
            None if sets.len() == 1 => 0,
            None => {
                return Err(format!(
                    "{} is not under any of the plan sets named; run it with its own plan set",
                    rcs_dsl::load::display(s)
                ))
            }
        };
        per_set[i].push(s.clone());
    }
    for (i, list) in per_set.iter_mut().enumerate() {
        if list.is_empty() && named.is_empty() {
            *list = own_scenarios(&sets[i])?;
        }
    }
    Ok(per_set)
}

/// One scenario to run, or a file that could not be read as one.
pub struct Loaded {
    pub path: String,
    /// One controller's scenario or a system scenario.
    pub scenario: Result<AnyScenario, (usize, String)>,
}

pub fn load(ir: &Ir, path: &Path) -> Loaded {
    let shown = rcs_dsl::load::display(path);
    let text = std::fs::read(path).map(String::from_utf8);
    let scenario = match text {
        Err(e) => Err((0, format!("cannot read: {e}"))),
        Ok(Err(e)) => {
            // Where the first bad byte is, as for a plan file.
            let mut offset = e.utf8_error().valid_up_to();
            let lossy = String::from_utf8_lossy(e.as_bytes());
            if lossy.starts_with(rcs_dsl::source::BOM) {
                offset -= rcs_dsl::source::BOM.len_utf8();
            }
            let file = SourceFile::new(shown.clone(), lossy.into_owned());
            let (line, column) = file.line_col(offset);
            Err((
                line,
                format!("not valid UTF-8 (first bad byte at line {line}, column {column}); save the file as UTF-8"),
            ))
        }
        Ok(Ok(text)) => {
            let stem = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let stem = stem
                .trim_end_matches(".yaml")
                .trim_end_matches(".yml")
                .trim_end_matches(".scenario")
                .to_string();
            scenario::parse_any(ir, &SourceFile::new(shown.clone(), text), &stem)
                .map_err(|e| (e.line, e.message))
        }
    };
    Loaded {
        path: shown,
        scenario,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenario_files_are_told_from_plan_paths() {
        let t = targets(vec![
            "plans/submarine".into(),
            "x/scenarios/a.scenario.yaml".into(),
        ])
        .unwrap();
        assert_eq!(t.plan_paths, [PathBuf::from("plans/submarine")]);
        assert_eq!(t.scenarios, [PathBuf::from("x/scenarios/a.scenario.yaml")]);
        // A scenario alone tests the set above its `scenarios/` folder.
        let t = targets(vec!["x/scenarios/a.scenario.yaml".into()]).unwrap();
        assert_eq!(t.plan_paths, [PathBuf::from("x")]);
        assert!(targets(vec!["/nowhere/a.scenario.yaml".into()]).is_err());
    }
}
