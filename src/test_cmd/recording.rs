//! The trace `rcsc test --trace FILE` writes, in memory until the run
//! ends (then through the one writer): JSON lines, or an MCAP recording
//! when FILE ends in `.mcap` (docs/trace-format.md). The scenario runners
//! hand each cycle's driver record to [`Recording::cycle`]; this module
//! adds what the plans know — verb, state, status and row names, the
//! simulated time (cycle × the controller's CPU period, scenarios one after
//! another), and in MCAP the values of the Global Memory buffers each
//! controller writes — so the same run gives byte-identical files.

use rcs_dsl::ir::{CtrlId, Ir, Type};
use rcs_runtime::driver::{Record, Value};
use rcs_runtime::{TraceDetail, TraceRecord, TraceSink};
use serde_json::{json, Value as Json};
use std::path::Path;
use std::sync::{Arc, Mutex};

/// The bytes of a trace being written, shared with the sink (which owns
/// its writer); seekable, as MCAP needs.
#[derive(Clone, Default)]
struct TraceBuffer(Arc<Mutex<std::io::Cursor<Vec<u8>>>>);

impl TraceBuffer {
    fn with<T>(&self, f: impl FnOnce(&mut std::io::Cursor<Vec<u8>>) -> T) -> T {
        match self.0.lock() {
            Ok(mut b) => f(&mut b),
            Err(poisoned) => f(&mut poisoned.into_inner()),
        }
    }
}

impl std::io::Write for TraceBuffer {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.with(|c| c.write(buf))
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl std::io::Seek for TraceBuffer {
    fn seek(&mut self, to: std::io::SeekFrom) -> std::io::Result<u64> {
        self.with(|c| c.seek(to))
    }
}

/// Whether `path` asks for an MCAP recording (it ends in `.mcap`).
pub fn wants_mcap(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
}

/// A trace being recorded, with the simulated clock of the run.
pub struct Recording {
    sink: TraceSink,
    bytes: TraceBuffer,
    /// Where the current scenario's time starts, in nanoseconds.
    base_ns: u64,
    /// Where the next scenario's starts: after every cycle so far.
    next_base_ns: u64,
}

impl Recording {
    /// A recording in memory, as MCAP when `mcap`, headed with `header`.
    /// `Err`: MCAP asked of an rcsc built without its feature `mcap`.
    pub fn new(header: &rcs_runtime::TraceHeader, mcap: bool) -> Result<Recording, String> {
        let bytes = TraceBuffer::default();
        let sink = match mcap {
            #[cfg(feature = "mcap")]
            true => TraceSink::mcap_with_header(bytes.clone(), header),
            #[cfg(not(feature = "mcap"))]
            true => {
                return Err(
                    "this rcsc writes no MCAP (built without its default feature `mcap`); name a .jsonl trace or rebuild rcsc with default features"
                        .to_string(),
                )
            }
            false => TraceSink::with_header(bytes.clone(), header),
        };
        Ok(Recording {
            sink,
            bytes,
            base_ns: 0,
            next_base_ns: 0,
        })
    }

    /// A scenario starts: its cycle 0 comes after every cycle recorded.
    pub fn start_scenario(&mut self) {
        self.base_ns = self.next_base_ns;
    }

    /// Record controller `c`'s cycle `rec` of the scenario run as
    /// `executive`.
    pub fn cycle(&mut self, ir: &Ir, c: CtrlId, executive: &str, rec: &Record, new_command: bool) {
        let ctrl = ir.controller(c);
        let period = period_of(ir, c);
        let time_ns = self
            .base_ns
            .saturating_add(rec.cycle.saturating_mul(period));
        self.next_base_ns = self.next_base_ns.max(time_ns.saturating_add(period));
        let plan = rec
            .verb
            .and_then(|v| ctrl.commands.get(usize::from(v)))
            .and_then(|cmd| cmd.plan)
            .map(|p| &ctrl.plans[p.index()]);
        let row = plan.and_then(|p| {
            let at = rec.fired?;
            p.rows.iter().find(|r| r.position == u32::from(at))
        });
        let row_name = row.map(|r| r.display_name());
        let detail = TraceDetail {
            time_ns: Some(time_ns),
            verb_name: rec
                .verb
                .and_then(|v| ctrl.commands.get(usize::from(v)))
                .map(|cmd| cmd.name.as_str()),
            state_name: plan
                .and_then(|p| p.states.get(usize::from(rec.state)))
                .map(|s| s.name.as_str()),
            fired_name: row_name.as_deref(),
            status_name: ctrl
                .statuses
                .get(usize::from(rec.status.0))
                .map(|s| s.name.as_str()),
            serial: Some(rec.echo_serial),
            cycle_ns: None,
        };
        self.sink.write_with(
            &TraceRecord {
                executive,
                cycle: rec.cycle,
                controller: ctrl.name.as_str(),
                verb: rec.verb,
                state: rec.verb.map(|_| rec.state),
                status: Some(rec.status.0),
                error: Some(rec.error.0),
                fired: rec.fired,
                new_command,
            },
            &detail,
        );
        if self.sink.is_mcap() {
            self.buffers(ir, c, executive, rec, time_ns);
        }
    }

    /// The buffers controller `c` writes, after its cycle, one message each.
    #[cfg(feature = "mcap")]
    fn buffers(&mut self, ir: &Ir, c: CtrlId, executive: &str, rec: &Record, time_ns: u64) {
        let ctrl = ir.controller(c);
        for (id, value) in ctrl.writes.iter().zip(&rec.writes) {
            let buffer = &ir.buffers[id.index()];
            let ty = Type::Buffer(buffer.ty);
            let type_name = &ir.buffer_types[buffer.ty.index()].name;
            let schema = json!({
                "title": type_name,
                "type": "object",
                "properties": {
                    "executive": { "type": "string" },
                    "buffer": { "type": "string" },
                    "writer": { "type": "string" },
                    "cycle": { "type": "integer" },
                    "time_ns": { "type": "integer" },
                    "value": type_schema(ir, &ty),
                },
                "required": ["executive", "buffer", "writer", "cycle", "time_ns", "value"],
            });
            self.sink
                .write_buffer(&rcs_runtime::trace::mcap::BufferSample {
                    executive,
                    buffer: &buffer.name,
                    writer: &ctrl.name,
                    cycle: rec.cycle,
                    time_ns,
                    schema_name: &format!("rcs.buffer.{type_name}"),
                    schema: &schema.to_string(),
                    value: &value_json(ir, &ty, value),
                });
        }
    }

    #[cfg(not(feature = "mcap"))]
    fn buffers(&mut self, _: &Ir, _: CtrlId, _: &str, _: &Record, _: u64) {}

    /// The whole trace, finished; `Err` when a write to it failed.
    pub fn finish(mut self) -> Result<Vec<u8>, String> {
        let finished = self.sink.finish();
        if self.sink.errors() > 0 || finished.is_err() {
            return Err("the trace could not be written whole (a write failed)".to_string());
        }
        drop(self.sink);
        Ok(self.bytes.with(|c| std::mem::take(c.get_mut())))
    }
}

/// The period of the CPU controller `c` runs on.
fn period_of(ir: &Ir, c: CtrlId) -> u64 {
    ir.schedule
        .iter()
        .find(|cpu| cpu.order.contains(&c))
        .map_or(rcs_dsl::manifest::DEFAULT_PERIOD_NS, |cpu| cpu.period_ns)
}

/// The JSON Schema of a value of type `ty`.
#[cfg_attr(not(feature = "mcap"), allow(dead_code))]
fn type_schema(ir: &Ir, ty: &Type) -> Json {
    match ty {
        Type::Bool => json!({ "type": "boolean" }),
        Type::Int(_) | Type::ErrorCode(_) => json!({ "type": "integer" }),
        Type::Float(_) => json!({ "type": ["number", "null"] }),
        Type::Enum(e) => {
            let names: Vec<&str> = ir.enums[e.index()]
                .variants
                .iter()
                .map(|v| v.name.as_str())
                .collect();
            json!({ "type": "string", "enum": names })
        }
        Type::Status(_) => json!({ "type": "string" }),
        Type::Buffer(b) => {
            let fields = &ir.buffer_types[b.index()].fields;
            let properties: serde_json::Map<String, Json> = fields
                .iter()
                .map(|f| (f.name.clone(), type_schema(ir, &f.ty)))
                .collect();
            let names: Vec<&str> = fields.iter().map(|f| f.name.as_str()).collect();
            json!({ "type": "object", "properties": properties, "required": names })
        }
        Type::Array(t, n) => json!({
            "type": "array", "items": type_schema(ir, t), "minItems": n, "maxItems": n
        }),
        Type::Unit => json!({ "type": "null" }),
    }
}

/// A driver value of type `ty` as JSON: fields and variants by name, a
/// status by name, an integer beyond JSON's safe range as a string.
#[cfg_attr(not(feature = "mcap"), allow(dead_code))]
fn value_json(ir: &Ir, ty: &Type, v: &Value) -> Json {
    match (ty, v) {
        (Type::Enum(e), Value::Enum(i)) => ir.enums[e.index()]
            .variants
            .get(*i as usize)
            .map_or_else(|| json!(i), |var| json!(var.name)),
        (Type::Status(c), Value::Status(s)) => ir
            .controller(*c)
            .statuses
            .get(usize::from(*s))
            .map_or_else(|| json!(s), |st| json!(st.name)),
        (Type::Buffer(b), Value::Buffer(vs)) => {
            let fields = &ir.buffer_types[b.index()].fields;
            let object: serde_json::Map<String, Json> = fields
                .iter()
                .zip(vs)
                .map(|(f, v)| (f.name.clone(), value_json(ir, &f.ty, v)))
                .collect();
            Json::Object(object)
        }
        (Type::Array(t, _), Value::Array(vs)) => {
            Json::Array(vs.iter().map(|v| value_json(ir, t, v)).collect())
        }
        (_, Value::Bool(b)) => json!(b),
        (_, Value::Int(i)) => i64::try_from(*i).map_or_else(|_| json!(i.to_string()), |i| json!(i)),
        (_, Value::Float(f)) => json!(f),
        (_, Value::Enum(i)) => json!(i),
        (_, Value::Status(s)) => json!(s),
        (_, Value::Buffer(vs) | Value::Array(vs)) => {
            Json::Array(vs.iter().map(|v| value_json(ir, &Type::Unit, v)).collect())
        }
        (_, Value::Unit) => Json::Null,
    }
}
