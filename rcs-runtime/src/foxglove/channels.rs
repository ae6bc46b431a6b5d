//! What the live server serves: the [`LiveSystem`] a program describes
//! (its executives' handles and monitors, Global Memory buffers, names from
//! the plans), the channels made of it — the topics and JSON Schemas of an
//! MCAP recording (docs/trace-format.md, "MCAP") — and their messages,
//! sampled on a client's thread.
//!
//! Sampling reads what the executives already publish for another thread:
//! the monitor's atomics ([`ExecutiveMonitor`]), the handle's cycle count
//! and Global Memory's seqlocked buffers. None of it takes a lock the
//! executive takes or makes it wait, so a client costs the control cycle
//! nothing, however many there are or however slowly they read.

use std::collections::BTreeMap;
use std::sync::Arc;

use serde::Serialize;
use serde_json::json;

use super::protocol::ChannelAd;
use crate::exec::{ControllerMonitor, ExecutiveHandle, ExecutiveMonitor};
use crate::gm::{status_buffer_name, BufferData, GlobalMemory, Reader};
use crate::handshake::{RowId, Status, StatusBuffer};
use crate::trace::{
    buffer_topic, controller_topic, TraceDetail, TraceRecord, CONTROLLER_SCHEMA,
    CONTROLLER_SCHEMA_NAME,
};

/// The names of a controller's ids, from its plans, so that messages say
/// `TRANSIT` and `S2` beside the numbers. Every part is optional: an id
/// without a name is sent as a number only.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ControllerNames {
    /// Verb names by verb id.
    pub verbs: Vec<String>,
    /// Per verb id, its plan's state names by state id.
    pub states: Vec<Vec<String>>,
    /// Per verb id, its plan's row labels by row id (`E3`).
    pub rows: Vec<Vec<String>>,
    /// Status names by status code; the built-in ones (`DONE`…) need not
    /// be given.
    pub statuses: Vec<String>,
}

impl ControllerNames {
    fn verb(&self, verb: u16) -> Option<&str> {
        self.verbs.get(usize::from(verb)).map(String::as_str)
    }
    fn state(&self, verb: u16, state: u16) -> Option<&str> {
        let states = self.states.get(usize::from(verb))?;
        states.get(usize::from(state)).map(String::as_str)
    }
    fn row(&self, verb: u16, row: RowId) -> Option<&str> {
        let rows = self.rows.get(usize::from(verb))?;
        rows.get(usize::from(row)).map(String::as_str)
    }
    fn status(&self, status: Status) -> Option<&str> {
        match self.statuses.get(usize::from(status.0)) {
            Some(name) => Some(name),
            None => status.builtin_name(),
        }
    }
}

/// A buffer whose values a channel carries, its type erased.
trait BufferSource: Send + Sync {
    /// Its generation now (0: never written), without copying.
    fn generation(&self) -> u64;
    /// Its value as JSON, with the generation and writer cycle of the write.
    fn sample(&self) -> (u64, u64, serde_json::Value);
}

impl<T: BufferData + Serialize + Sync> BufferSource for Reader<T> {
    fn generation(&self) -> u64 {
        Reader::generation(self)
    }
    fn sample(&self) -> (u64, u64, serde_json::Value) {
        let s = self.read();
        let value = serde_json::to_value(s.value).unwrap_or_else(|e| json!(e.to_string()));
        (s.generation, s.writer_cycle, value)
    }
}

/// One executive as the server sees it.
struct LiveExecutive {
    handle: ExecutiveHandle,
    monitor: Arc<ExecutiveMonitor>,
    /// Status readers of its controllers, in monitor order.
    status: Vec<Option<Reader<StatusBuffer>>>,
}

/// One Global Memory buffer channel.
struct LiveBuffer {
    executive: String,
    buffer: String,
    writer: String,
    source: Box<dyn BufferSource>,
}

/// A running system as the live server serves it; see the module docs.
/// Build it before starting the server: its channels are fixed then.
pub struct LiveSystem {
    name: String,
    executives: Vec<LiveExecutive>,
    names: BTreeMap<String, ControllerNames>,
    buffers: Vec<(LiveBuffer, String, String)>,
}

impl std::fmt::Debug for LiveSystem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveSystem")
            .field("name", &self.name)
            .field("executives", &self.executives.len())
            .field("buffers", &self.buffers.len())
            .finish()
    }
}

/// The schema of a buffer channel whose `value` has the JSON Schema
/// `value`, as `rcsc test --trace` writes it.
fn buffer_schema(type_name: &str, value: serde_json::Value) -> String {
    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": type_name,
        "type": "object",
        "properties": {
            "executive": { "type": "string" },
            "buffer": { "type": "string" },
            "writer": { "type": "string" },
            "cycle": { "type": "integer", "description": "the writer's cycle at the write" },
            "time_ns": { "type": "integer" },
            "value": value,
        },
        "required": ["executive", "buffer", "writer", "cycle", "time_ns", "value"],
    })
    .to_string()
}

/// The JSON Schema of a [`StatusBuffer`]'s value.
fn status_value_schema() -> serde_json::Value {
    let int = |d: &str| json!({ "type": "integer", "description": d });
    json!({
        "type": "object",
        "properties": {
            "echo_serial": int("the serial of the command the status is about"),
            "echo_epoch": int("the epoch of that command"),
            "status": int("the status code"),
            "error": int("the error code (0: none)"),
            "verb": int("the verb of the echoed command"),
            "state": int("the current state of its plan"),
            "refused_serial": int("the serial of the command refused last (0: none)"),
            "refused_epoch": int("the epoch of that command"),
        },
        "required": ["echo_serial", "echo_epoch", "status", "error", "verb", "state", "refused_serial", "refused_epoch"],
    })
}

impl LiveSystem {
    /// A system called `name` (shown by the client), with nothing in it yet.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            executives: Vec::new(),
            names: BTreeMap::new(),
            buffers: Vec::new(),
        }
    }

    /// Serve executive `handle`'s controllers from its `monitor`
    /// ([`Executive::attach_monitor`](crate::Executive::attach_monitor)),
    /// and each controller's status buffer from `gm`: channel
    /// `/rcs/<executive>/<controller>` for each, and
    /// `/rcs/<executive>/gm/<controller>.status` for each that has one.
    pub fn executive(
        mut self,
        handle: ExecutiveHandle,
        monitor: Arc<ExecutiveMonitor>,
        gm: &GlobalMemory,
    ) -> Self {
        let status = monitor
            .controllers()
            .iter()
            .map(|c| gm.status_reader(c.name()).ok())
            .collect();
        self.executives.push(LiveExecutive {
            handle,
            monitor,
            status,
        });
        self
    }

    /// Name controller `controller`'s verbs, states, rows and statuses.
    pub fn names(mut self, controller: impl Into<String>, names: ControllerNames) -> Self {
        self.names.insert(controller.into(), names);
        self
    }

    /// Serve Global Memory buffer `reader` (of type `type_name`, whose
    /// values have the JSON Schema `value_schema`), written by controller
    /// `writer` on executive `executive`, on `/rcs/<executive>/gm/<buffer>`.
    /// A message is sent each time a write is seen.
    pub fn buffer<T: BufferData + Serialize + Sync>(
        mut self,
        executive: &str,
        writer: &str,
        reader: Reader<T>,
        type_name: &str,
        value_schema: serde_json::Value,
    ) -> Self {
        let buffer = LiveBuffer {
            executive: executive.to_string(),
            buffer: reader.name().to_string(),
            writer: writer.to_string(),
            source: Box::new(reader),
        };
        self.buffers.push((
            buffer,
            format!("rcs.buffer.{type_name}"),
            buffer_schema(type_name, value_schema),
        ));
        self
    }

    pub(super) fn name(&self) -> &str {
        &self.name
    }

    /// The channels, ids from 1: every controller of every executive, then
    /// the status buffers, then the buffers added with [`Self::buffer`].
    pub(super) fn into_channels(self) -> Channels {
        let mut ads = Vec::new();
        let mut sources = Vec::new();
        let mut statuses = Vec::new();
        let names = Arc::new(self.names);
        for (e, exec) in self.executives.iter().enumerate() {
            let exec_name = exec.monitor.name();
            for (c, ctrl) in exec.monitor.controllers().iter().enumerate() {
                ads.push((
                    controller_topic(exec_name, ctrl.name()),
                    CONTROLLER_SCHEMA_NAME.to_string(),
                    CONTROLLER_SCHEMA.to_string(),
                ));
                sources.push(Source::Controller { exec: e, index: c });
                if let Some(reader) = &exec.status[c] {
                    statuses.push((
                        LiveBuffer {
                            executive: exec_name.to_string(),
                            buffer: status_buffer_name(ctrl.name()),
                            writer: ctrl.name().to_string(),
                            source: Box::new(reader.clone()),
                        },
                        "rcs.buffer.StatusBuffer".to_string(),
                        buffer_schema("StatusBuffer", status_value_schema()),
                    ));
                }
            }
        }
        for (buffer, schema_name, schema) in statuses.into_iter().chain(self.buffers) {
            ads.push((
                buffer_topic(&buffer.executive, &buffer.buffer),
                schema_name,
                schema,
            ));
            sources.push(Source::Buffer(buffer));
        }
        let ads = ads
            .into_iter()
            .zip(1..)
            .map(|((topic, schema_name, schema), id)| ChannelAd {
                id,
                topic,
                encoding: "json",
                schema_name,
                schema,
                schema_encoding: "jsonschema",
            })
            .collect();
        Channels {
            executives: self.executives,
            names,
            ads,
            sources,
        }
    }
}

/// Where a channel's messages come from.
enum Source {
    /// Controller `index` of executive `exec`.
    Controller { exec: usize, index: usize },
    /// A Global Memory buffer.
    Buffer(LiveBuffer),
}

/// What a client was last sent on a channel, so that it is sent only what
/// is new: the executive's cycle count (a controller) or the buffer's
/// generation, and the serial then.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(super) struct Sent {
    mark: u64,
    serial: Option<u32>,
}

/// The server's channels, shared by its clients' threads.
pub(super) struct Channels {
    executives: Vec<LiveExecutive>,
    names: Arc<BTreeMap<String, ControllerNames>>,
    /// Advertisements, index = id - 1.
    pub(super) ads: Vec<ChannelAd>,
    sources: Vec<Source>,
}

/// A controller channel's message: the trace's record and details, plus
/// what only a live monitor knows.
#[derive(Serialize)]
struct LiveControllerMessage<'a> {
    #[serde(flatten)]
    record: TraceRecord<&'a str>,
    #[serde(flatten)]
    detail: TraceDetail<'a>,
    #[serde(skip_serializing_if = "Option::is_none")]
    last_fired: Option<RowId>,
    #[serde(skip_serializing_if = "Option::is_none")]
    last_fired_name: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    last_fired_cycle: Option<u64>,
    exec_max_ns: u64,
    overruns: u64,
    panics: u64,
}

#[derive(Serialize)]
struct BufferMessage<'a> {
    executive: &'a str,
    buffer: &'a str,
    writer: &'a str,
    cycle: u64,
    time_ns: u64,
    value: serde_json::Value,
}

impl Channels {
    /// The channel with advertised id `id`.
    pub(super) fn has(&self, id: u32) -> bool {
        id.checked_sub(1)
            .and_then(|i| usize::try_from(i).ok())
            .is_some_and(|i| i < self.sources.len())
    }

    /// Channel `id`'s message at `time_ns` if there is something new since
    /// `sent` (and then `sent` is updated), else `None`.
    pub(super) fn sample(&self, id: u32, time_ns: u64, sent: &mut Sent) -> Option<Vec<u8>> {
        let i = usize::try_from(id.checked_sub(1)?).ok()?;
        match self.sources.get(i)? {
            Source::Controller { exec, index } => {
                let exec = &self.executives[*exec];
                let ctrl = exec.monitor.controllers().get(*index)?;
                self.controller_message(exec, ctrl, exec.status[*index].as_ref(), time_ns, sent)
            }
            Source::Buffer(b) => {
                let generation = b.source.generation();
                if generation == 0 || generation == sent.mark {
                    return None;
                }
                let (generation, cycle, value) = b.source.sample();
                sent.mark = generation;
                serde_json::to_vec(&BufferMessage {
                    executive: &b.executive,
                    buffer: &b.buffer,
                    writer: &b.writer,
                    cycle,
                    time_ns,
                    value,
                })
                .ok()
            }
        }
    }

    fn controller_message(
        &self,
        exec: &LiveExecutive,
        ctrl: &ControllerMonitor,
        status: Option<&Reader<StatusBuffer>>,
        time_ns: u64,
        sent: &mut Sent,
    ) -> Option<Vec<u8>> {
        // Cycles run so far: nothing new while paused or before the first.
        let cycles = exec.handle.cycle();
        if cycles == 0 || cycles == sent.mark {
            return None;
        }
        let cycle = cycles - 1;
        let f = ctrl.figures();
        let serial = status
            .map(|r| r.read())
            .filter(|s| s.generation > 0)
            .map(|s| s.value.echo_serial);
        // A new command arrived between two samples if the serial changed;
        // the first message to a client has nothing to compare with.
        let new_command = f.has_plans && sent.serial.is_some() && serial != sent.serial;
        sent.mark = cycles;
        sent.serial = serial;
        let names = self.names.get(ctrl.name());
        let plans = f.has_plans;
        let last = f.last_fired;
        let fired = last.filter(|(_, _, c)| *c == cycle).map(|(_, row, _)| row);
        let row_name = |(verb, row, _): (u16, RowId, u64)| names.and_then(|n| n.row(verb, row));
        let message = LiveControllerMessage {
            record: TraceRecord {
                executive: exec.monitor.name(),
                cycle,
                controller: ctrl.name(),
                verb: plans.then_some(f.verb),
                state: plans.then_some(f.state),
                status: plans.then_some(f.status.0),
                error: plans.then_some(f.error.0),
                fired: plans.then_some(fired).flatten(),
                new_command,
            },
            detail: TraceDetail {
                time_ns: Some(time_ns),
                verb_name: names.filter(|_| plans).and_then(|n| n.verb(f.verb)),
                state_name: names
                    .filter(|_| plans)
                    .and_then(|n| n.state(f.verb, f.state)),
                fired_name: last.filter(|(_, _, c)| *c == cycle).and_then(row_name),
                status_name: plans
                    .then(|| match names {
                        Some(n) => n.status(f.status),
                        None => f.status.builtin_name(),
                    })
                    .flatten(),
                serial,
                cycle_ns: (f.exec_max_ns > 0).then_some(f.exec_last_ns),
            },
            last_fired: last.map(|(_, row, _)| row),
            last_fired_name: last.and_then(row_name),
            last_fired_cycle: last.map(|(_, _, c)| c),
            exec_max_ns: f.exec_max_ns,
            overruns: f.overruns,
            panics: f.panics,
        };
        serde_json::to_vec(&message).ok()
    }
}
