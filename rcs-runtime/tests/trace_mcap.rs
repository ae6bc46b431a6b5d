//! An executive's trace sink writing MCAP (feature `mcap`): a sink made by
//! `TraceSink::create` for a `.mcap` path records every controller's cycle,
//! and the recording reads back as the same records a JSON-lines sink
//! writes for the same run.
#![cfg(feature = "mcap")]

use rcs_runtime::{
    read_trace_bytes, Controller, CycleContext, Executive, ExecutiveConfig, TraceSink,
};
use std::time::Duration;

/// A controller without plans (a simulator): traced with empty fields.
struct Idle(&'static str);

impl Controller for Idle {
    fn name(&self) -> &str {
        self.0
    }
    fn cycle(&mut self, _: &CycleContext) {}
}

/// Run two controllers for 5 cycles, tracing to `path`; the trace's bytes.
fn run(path: &std::path::Path) -> Vec<u8> {
    run_measured(path, false)
}

fn run_measured(path: &std::path::Path, measure: bool) -> Vec<u8> {
    let config = ExecutiveConfig::new("main", Duration::from_millis(10)).with_measure(measure);
    let mut e = Executive::new(config).unwrap();
    e.add(Box::new(Idle("SIM"))).unwrap();
    e.add(Box::new(Idle("DRV"))).unwrap();
    e.set_trace(TraceSink::create(path).unwrap());
    e.run_cycles(5).unwrap();
    let mut sink = e.take_trace().unwrap();
    sink.finish().unwrap();
    assert_eq!((sink.records(), sink.errors()), (10, 0));
    drop(sink);
    std::fs::read(path).unwrap()
}

#[test]
fn an_executive_records_mcap_for_a_dot_mcap_path() {
    let dir = std::env::temp_dir().join(format!("rcs-runtime-trace-mcap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mcap = run(&dir.join("run.mcap"));
    let lines = run(&dir.join("run.jsonl"));
    assert!(mcap.starts_with(b"\x89MCAP0\r\n"));
    assert!(lines.starts_with(b"{\"format\":\"rcs-trace\""));
    let from_mcap = read_trace_bytes(&mcap).unwrap();
    assert_eq!(from_mcap, read_trace_bytes(&lines).unwrap());
    assert_eq!(from_mcap.len(), 10);
    assert_eq!(from_mcap[9].cycle, 4);
    assert_eq!(from_mcap[9].controller, "DRV");
    assert_eq!(from_mcap[9].verb, None);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// With timing on, each controller message carries the cycle's time
/// (`cycle_ns`), and without it none does.
#[test]
fn a_measured_executive_records_each_cycle_time() {
    let dir = std::env::temp_dir().join(format!("rcs-runtime-trace-ns-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for measure in [true, false] {
        let bytes = run_measured(&dir.join("run.mcap"), measure);
        let mut messages = 0;
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            let json: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
            assert_eq!(json["cycle_ns"].is_u64(), measure, "{json}");
            messages += 1;
        }
        assert_eq!(messages, 10);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
