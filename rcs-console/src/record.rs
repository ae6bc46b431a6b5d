//! Recording a console session (`rcsc console … --trace FILE`):
//! [`Recording`] wraps any [`Source`] and writes what the console sees to
//! the runtime's [`TraceSink`] — MCAP (`FILE.mcap`, one channel per
//! controller, the same layout as `rcsc test --trace`, with the names of
//! verbs, states, rows and statuses from the catalog) or JSON lines.
//!
//! What is recorded is what the console samples, about ten times a second:
//! one message per controller whose figures changed since the last sample
//! (its CPU's cycle count, verb, state, status, error, the row fired last
//! when it fired since), logged at the time of sampling. It is a record of
//! the session, not of every cycle: a program that needs every cycle
//! attaches a trace sink to its executive (`Executive::set_trace`).

use rcs_runtime::{TraceDetail, TraceRecord, TraceSink};

use crate::catalog::{ArgValue, Catalog};
use crate::model::{ControllerSnapshot, Snapshot};
use crate::source::Source;

/// What was last recorded of one controller.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Seen {
    name: String,
    figures: (u16, u16, u16, u16),
    /// The cycle of the last row fired that was recorded.
    fired_cycle: Option<u64>,
}

/// A [`Source`] that records every snapshot it passes on. See the module
/// docs.
pub struct Recording<'a> {
    inner: &'a mut dyn Source,
    sink: TraceSink,
    catalog: Catalog,
    seen: Vec<Seen>,
}

impl std::fmt::Debug for Recording<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recording")
            .field("records", &self.sink.records())
            .finish()
    }
}

impl<'a> Recording<'a> {
    /// Record what `inner` shows to `sink`, naming ids from `catalog`.
    pub fn new(inner: &'a mut dyn Source, sink: TraceSink, catalog: Catalog) -> Self {
        Self {
            inner,
            sink,
            catalog,
            seen: Vec::new(),
        }
    }

    /// End the recording (MCAP writes its summary): the records written
    /// and lost.
    pub fn finish(mut self) -> std::io::Result<(u64, u64)> {
        self.sink.finish()?;
        Ok((self.sink.records(), self.sink.errors()))
    }

    fn record(&mut self, snap: &Snapshot) {
        for c in &snap.controllers {
            let figures = (c.verb, c.state, c.status.0, c.error.0);
            let fired_cycle = c.last_fired.map(|(_, _, cycle)| cycle);
            let cycle = snap
                .cpus
                .iter()
                .find(|cpu| cpu.name == c.cpu)
                .map_or(0, |cpu| cpu.cycle);
            let index = self.seen.iter().position(|s| s.name == c.name);
            let (changed, fired) = match index.map(|i| &self.seen[i]) {
                Some(s) => (
                    s.figures != figures || s.fired_cycle != fired_cycle,
                    fired_cycle.is_some() && s.fired_cycle != fired_cycle,
                ),
                None => (true, fired_cycle.is_some()),
            };
            if !changed {
                continue;
            }
            self.write(c, cycle, fired);
            let seen = Seen {
                name: c.name.clone(),
                figures,
                fired_cycle,
            };
            match index {
                Some(i) => self.seen[i] = seen,
                None => self.seen.push(seen),
            }
        }
    }

    fn write(&mut self, c: &ControllerSnapshot, cycle: u64, fired: bool) {
        let info = self.catalog.controller(&c.name);
        let plans = c.has_plans;
        let verb = info.and_then(|i| i.verbs.get(usize::from(c.verb)));
        let row = c
            .last_fired
            .filter(|_| fired)
            .map(|(verb, row, _)| (verb, row));
        let plan = verb.and_then(|v| v.plan.as_ref());
        let state_name = plan.and_then(|p| p.states.get(usize::from(c.state)));
        let fired_name = row
            .filter(|(v, _)| *v == c.verb)
            .and_then(|(_, r)| plan.and_then(|p| p.rows.get(usize::from(r))))
            .map(|r| r.label.as_str());
        let status_name = info.map(|i| i.status_name(c.status));
        self.sink.write_with(
            &TraceRecord {
                executive: c.cpu.as_str(),
                cycle,
                controller: c.name.as_str(),
                verb: plans.then_some(c.verb),
                state: plans.then_some(c.state),
                status: plans.then_some(c.status.0),
                error: plans.then_some(c.error.0),
                fired: row.map(|(_, r)| r),
                new_command: false,
            },
            &TraceDetail {
                verb_name: verb.filter(|_| plans).map(|v| v.name.as_str()),
                state_name: state_name.filter(|_| plans).map(String::as_str),
                fired_name,
                status_name: status_name.as_deref().filter(|_| plans),
                ..TraceDetail::default()
            },
        );
    }
}

impl Source for Recording<'_> {
    fn snapshot(&mut self) -> Snapshot {
        let snap = self.inner.snapshot();
        self.record(&snap);
        snap
    }

    fn pause(&mut self, cpu: &str) -> Result<(), String> {
        self.inner.pause(cpu)
    }

    fn step(&mut self, cpu: &str, n: u64) -> Result<(), String> {
        self.inner.step(cpu, n)
    }

    fn resume(&mut self, cpu: &str) -> Result<(), String> {
        self.inner.resume(cpu)
    }

    fn command(&mut self, root: &str, verb: &str, args: &[ArgValue]) -> Result<u32, String> {
        self.inner.command(root, verb, args)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::CpuSnapshot;
    use rcs_runtime::{ErrorCode, Status};

    /// Gives the snapshots it holds, one a call, then the last again.
    struct Replay(Vec<Snapshot>);

    impl Source for Replay {
        fn snapshot(&mut self) -> Snapshot {
            if self.0.len() > 1 {
                self.0.remove(0)
            } else {
                self.0[0].clone()
            }
        }
        fn pause(&mut self, _: &str) -> Result<(), String> {
            Ok(())
        }
        fn step(&mut self, _: &str, _: u64) -> Result<(), String> {
            Ok(())
        }
        fn resume(&mut self, _: &str) -> Result<(), String> {
            Ok(())
        }
        fn command(&mut self, _: &str, _: &str, _: &[ArgValue]) -> Result<u32, String> {
            Ok(1)
        }
    }

    fn snap(cycle: u64, state: u16, fired: Option<(u16, u16, u64)>) -> Snapshot {
        Snapshot {
            cpus: vec![CpuSnapshot {
                name: "main".into(),
                cycle,
                ..CpuSnapshot::default()
            }],
            controllers: vec![ControllerSnapshot {
                name: "SM".into(),
                cpu: "main".into(),
                has_plans: true,
                verb: 1,
                state,
                status: Status::EXECUTING,
                error: ErrorCode::NONE,
                last_fired: fired,
                ..ControllerSnapshot::default()
            }],
        }
    }

    fn record(path: &std::path::Path) -> Vec<rcs_runtime::TraceRecord> {
        let catalog = Catalog::load(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../plans/submarine"),
        )
        .expect("catalog");
        let mut source = Replay(vec![
            snap(10, 0, None),
            snap(11, 0, None), // unchanged figures: not recorded
            snap(12, 1, Some((1, 0, 12))),
            snap(13, 1, Some((1, 0, 12))), // the same firing: not again
            snap(20, 2, Some((1, 2, 20))),
        ]);
        let sink = TraceSink::create(path).expect("sink");
        let mut rec = Recording::new(&mut source, sink, catalog);
        for _ in 0..6 {
            rec.snapshot();
        }
        assert_eq!(rec.finish().expect("finish"), (3, 0));
        let bytes = std::fs::read(path).expect("read back");
        let _ = std::fs::remove_file(path);
        rcs_runtime::read_trace_bytes(&bytes).expect("a trace")
    }

    #[test]
    fn a_session_records_each_change_once() {
        let path = std::env::temp_dir().join(format!("rcs-console-{}.jsonl", std::process::id()));
        let records = record(&path);
        let got: Vec<(u64, Option<u16>, Option<u16>)> = records
            .iter()
            .map(|r| (r.cycle, r.state, r.fired))
            .collect();
        assert_eq!(
            got,
            [
                (10, Some(0), None),
                (12, Some(1), Some(0)),
                (20, Some(2), Some(2))
            ]
        );
        assert!(records
            .iter()
            .all(|r| r.controller == "SM" && r.executive == "main"));
    }

    #[cfg(feature = "mcap")]
    #[test]
    fn a_session_records_to_mcap() {
        let path = std::env::temp_dir().join(format!("rcs-console-{}.mcap", std::process::id()));
        let records = record(&path);
        assert_eq!(records.len(), 3);
        assert_eq!(records[2].fired, Some(2));
    }
}
