//! `rcsc check --witnesses DIR`: after the checks, each finding that
//! carries a run (a way to make it happen, from a fresh controller) is
//! written as a `*.scenario.yaml` that `rcsc test` runs and passes, so a
//! reader can watch the finding happen. Pure up to the write, which goes
//! through the one file writer of the generated outputs.

use rcs_dsl::analysis::run::scenario_text;
use std::collections::BTreeMap;
use std::path::Path;

/// The scenarios gathered from the findings, by file name.
#[derive(Default)]
pub struct Witnesses {
    files: BTreeMap<String, String>,
}

impl Witnesses {
    /// Gather the runs of one plan set's findings.
    pub fn collect(&mut self, checked: &rcs_dsl::Checked) {
        for d in &checked.diagnostics {
            let Some(w) = &d.witness else { continue };
            let Some(run) = &w.run else { continue };
            let stem = self.free_stem(&format!(
                "{}_{}_{}_{}",
                d.code.name(),
                run.controller,
                run.command,
                w.state
            ));
            let about = format!(
                "{} (`rcsc check --witnesses`): reproduces the {} finding\n{}\n\
                 Run it with `rcsc test PLANS THIS_FILE`.",
                rcs_codegen::GENERATED,
                d.code.name(),
                d.message
            );
            // A run that cannot be written is left out: the check's own
            // output still reports the finding.
            if let Ok(text) = scenario_text(run, &stem, &about) {
                self.files.insert(format!("{stem}.scenario.yaml"), text);
            }
            // A handshake finding, reproduced with the subordinate running
            // its own plan: the same finding as a system scenario.
            let ir = checked.ir.as_ref().or(checked.rejected_by_checks.as_ref());
            if let (Some(script), Some(ir)) = (&w.system, ir) {
                let stem = self.free_stem(&format!("{stem}_system"));
                let script = rcs_dsl::scenario::SystemScript {
                    name: stem.clone(),
                    ..script.clone()
                };
                let mut text = String::new();
                for line in about.lines() {
                    text.push_str("# ");
                    text.push_str(line);
                    text.push('\n');
                }
                text.push_str(&script.to_yaml(ir));
                self.files.insert(format!("{stem}.scenario.yaml"), text);
            }
        }
    }

    /// `name` made a safe file name, numbered when already taken.
    fn free_stem(&self, name: &str) -> String {
        let safe: String = name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let mut stem = safe.clone();
        let mut n = 2;
        while self.files.contains_key(&format!("{stem}.scenario.yaml")) {
            stem = format!("{safe}_{n}");
            n += 1;
        }
        stem
    }

    pub fn len(&self) -> usize {
        self.files.len()
    }

    /// Write every scenario under `dir` (made if missing).
    pub fn write(&self, dir: &Path) -> Result<(), String> {
        let files: Vec<rcs_codegen::OutputFile> = self
            .files
            .iter()
            .map(|(path, contents)| rcs_codegen::OutputFile {
                path: path.clone(),
                contents: contents.clone(),
            })
            .collect();
        rcs_codegen::writer::write_files(dir, &files, &mut |_| {})
            .map(|_| ())
            .map_err(|e| format!("cannot write witnesses: {e}"))
    }
}
