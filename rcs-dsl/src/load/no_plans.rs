//! `no_plans`: a plan set that found no `.rcs` file is an error where it
//! is loaded, so that `rcsc check`, `rcsc build` and a build script's
//! `Config::compile` all refuse it instead of compiling an empty system.

use super::{display, PlanSet};
use crate::diagnostic::{Code, Diagnostic};
use crate::source::Span;
use std::path::Path;

impl PlanSet {
    /// `no_plans` for a set that found no `.rcs` file: it would compile
    /// into an empty system, which is never what was meant (a mistyped
    /// folder, plans not written yet, a `plans:` that names nothing). At
    /// the manifest when there is one, else at the folder itself. Not when
    /// loading already went wrong (a broken manifest explains it).
    pub(super) fn report_no_plans(&mut self, dir: &Path, has_nested: bool) {
        if !self.rcs_files.is_empty() || !self.diagnostics.is_empty() {
            return;
        }
        let here = display(dir);
        let (span, label) = match (self.manifest_file, &self.manifest.plans) {
            (Some(id), Some(_)) => {
                let text = &self.sources.get(id).text;
                let at = text
                    .match_indices("plans")
                    .map(|(i, _)| i)
                    .find(|&i| i == 0 || text[..i].ends_with('\n'))
                    .unwrap_or(0);
                let end = if at == 0 && !text.starts_with("plans") {
                    0
                } else {
                    at + "plans".len()
                };
                (Span::new(id, at, end), "`plans:` names no `.rcs` file")
            }
            (Some(id), None) => (
                Span::new(id, 0, 0),
                "this manifest's folder holds no `.rcs` file",
            ),
            (None, _) => {
                // No file to point into: the folder stands as an empty one.
                let id = self
                    .sources
                    .add(format!("{}/", here.trim_end_matches('/')), String::new());
                (Span::new(id, 0, 0), "no `.rcs` file in this folder")
            }
        };
        let mut d = Diagnostic::error(
            Code::NoPlans,
            format!("plan set `{here}` holds no `.rcs` file"),
            span,
            label,
        )
        .with_help(format!(
            "write the plans as `.rcs` files in `{here}` (or below it), or name the folder that holds them"
        ));
        if has_nested {
            d = d.with_note(
                "the folders below it with an `rcs.yaml` of their own are plan sets of their own",
            );
        }
        self.diagnostics.push(d);
    }
}
