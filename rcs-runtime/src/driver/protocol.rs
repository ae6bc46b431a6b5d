//! The driver protocol: [`Request`]s and [`Response`]s as JSON lines, and
//! its server ([`serve`], [`serve_systems`]), which answers them on a
//! generated controller or system run. `rcsc test --backend compiled`
//! speaks it to a small crate built around the generated code; the client
//! side is `remote` (and `system` for runs).

use super::system::{self, DrivenSystem, SystemFactory};
use super::{DriveError, Driven, Record, Value};
use crate::handshake::StatusBuffer;
use serde::{Deserialize, Serialize};

/// One request of the driver protocol: [`serve`] reads them as JSON lines
/// and answers each with one [`Response`] line; [`Remote`](super::Remote) writes them.
/// This is how `rcsc test --backend compiled` drives generated code that
/// lives in a separate process (a small crate rcsc builds around it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Request {
    /// Replace the driven controller by a fresh `controller` of plan set
    /// number `set` (an index into the server's factories).
    New {
        /// The plan set.
        set: usize,
        /// The controller's name.
        controller: String,
    },
    /// [`Driven::command`].
    Command {
        /// The verb.
        verb: String,
        /// Its arguments.
        args: Vec<Value>,
    },
    /// [`Driven::set_read`].
    SetRead {
        /// The buffer.
        buffer: String,
        /// Its value.
        value: Value,
    },
    /// [`Driven::set_hook`].
    SetHook {
        /// The hook.
        hook: String,
        /// What it returns.
        value: Value,
    },
    /// [`Driven::set_var`].
    SetVar {
        /// The var.
        var: String,
        /// Its value.
        value: Value,
    },
    /// [`Driven::set_write`].
    SetWrite {
        /// The buffer.
        buffer: String,
        /// Its value.
        value: Value,
    },
    /// [`Driven::write_sub_status`].
    WriteSubStatus {
        /// The subordinate.
        sub: String,
        /// The status buffer it writes.
        status: StatusBuffer,
    },
    /// [`Driven::last_sent`].
    LastSent {
        /// The subordinate.
        sub: String,
    },
    /// [`Driven::cycle`].
    Cycle,
    /// [`Driven::write_sub_field`].
    WriteSubField {
        /// The subordinate.
        sub: String,
        /// Its status field.
        field: String,
        /// The value it publishes.
        value: Value,
    },
    /// Replace what is driven by a fresh run of the named controllers of
    /// plan set number `set` (its [`SystemFactory`]).
    NewSystem {
        /// The plan set.
        set: usize,
        /// The controllers of the run (whole subtrees).
        controllers: Vec<String>,
    },
    /// [`DrivenSystem::command`].
    SystemCommand {
        /// The root of the run commanded.
        root: String,
        /// The verb.
        verb: String,
        /// Its arguments.
        args: Vec<Value>,
    },
    /// [`DrivenSystem::set_read`].
    SystemSetRead {
        /// The external buffer.
        buffer: String,
        /// Its value.
        value: Value,
    },
    /// [`DrivenSystem::set_hook`].
    SystemSetHook {
        /// The controller.
        controller: String,
        /// Its hook.
        hook: String,
        /// What it returns.
        value: Value,
    },
    /// [`DrivenSystem::set_var`].
    SystemSetVar {
        /// The controller.
        controller: String,
        /// Its var.
        var: String,
        /// Its value.
        value: Value,
    },
    /// [`DrivenSystem::run_cpu`].
    RunCpu {
        /// The CPU's name in the schedule.
        cpu: String,
    },
}

/// The answer to one [`Request`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Response {
    /// Done, nothing to return.
    Done,
    /// A serial number (`Command`, `LastSent`).
    Serial(u32),
    /// What the cycle did.
    Record(Record),
    /// What one CPU's cycle did, per controller (`RunCpu`).
    Records(Vec<(String, Record)>),
    /// The driven controller refused a name or value.
    Refused(DriveError),
    /// The request could not be served at all (no such plan set or
    /// controller, no controller yet, a malformed line).
    Failed(String),
}

/// Makes a fresh generated controller by name; `None`: no such controller.
/// The generated `new_driver` of each plan set has this type.
pub type Factory = fn(&str) -> Option<Result<Box<dyn Driven>, crate::SetupError>>;

/// Serve the driver protocol: one [`Response`] line for each [`Request`]
/// line of `input`, until `input` ends. `sets[i]` makes the controllers of
/// plan set `i`.
pub fn serve(
    sets: &[Factory],
    input: impl std::io::BufRead,
    output: impl std::io::Write,
) -> std::io::Result<()> {
    serve_systems(sets, &[], input, output)
}

/// [`serve`], with system runs too: `systems[i]` makes the runs of plan
/// set `i` (`NewSystem` and the `System…`/`RunCpu` requests).
pub fn serve_systems(
    sets: &[Factory],
    systems: &[SystemFactory],
    input: impl std::io::BufRead,
    mut output: impl std::io::Write,
) -> std::io::Result<()> {
    let mut driven: Option<Box<dyn Driven>> = None;
    let mut run: Option<Box<dyn DrivenSystem>> = None;
    for line in input.lines() {
        let line = line?;
        let response = match serde_json::from_str::<Request>(&line) {
            Err(e) => Response::Failed(format!("malformed request: {e}")),
            Ok(Request::NewSystem { set, controllers }) => {
                let names: Vec<&str> = controllers.iter().map(String::as_str).collect();
                match systems.get(set).map(|make| make(&names)) {
                    None => Response::Failed(format!("no system runs for plan set number {set}")),
                    Some(Err(e)) => Response::Failed(format!("setting up the run: {e}")),
                    Some(Ok(d)) => {
                        run = Some(d);
                        Response::Done
                    }
                }
            }
            Ok(
                request @ (Request::SystemCommand { .. }
                | Request::SystemSetRead { .. }
                | Request::SystemSetHook { .. }
                | Request::SystemSetVar { .. }
                | Request::RunCpu { .. }),
            ) => match run.as_deref_mut() {
                None => Response::Failed("no system run yet: send `NewSystem` first".to_string()),
                Some(d) => system::answer(d, request),
            },
            Ok(Request::New { set, controller }) => {
                match sets.get(set).map(|make| make(&controller)) {
                    None => Response::Failed(format!("no plan set number {set}")),
                    Some(None) => Response::Failed(format!("no controller `{controller}`")),
                    Some(Some(Err(e))) => {
                        Response::Failed(format!("setting up `{controller}`: {e}"))
                    }
                    Some(Some(Ok(d))) => {
                        driven = Some(d);
                        Response::Done
                    }
                }
            }
            Ok(request) => match driven.as_deref_mut() {
                None => Response::Failed("no controller yet: send `New` first".to_string()),
                Some(d) => answer(d, request),
            },
        };
        let text = serde_json::to_string(&response).map_err(std::io::Error::other)?;
        writeln!(output, "{text}")?;
        output.flush()?;
    }
    Ok(())
}

fn answer(d: &mut dyn Driven, request: Request) -> Response {
    let done = |r: Result<(), DriveError>| r.map_or_else(Response::Refused, |()| Response::Done);
    let serial = |r: Result<u32, DriveError>| r.map_or_else(Response::Refused, Response::Serial);
    match request {
        Request::New { .. } => Response::Failed("unexpected `New`".to_string()),
        Request::Command { verb, args } => serial(d.command(&verb, &args)),
        Request::SetRead { buffer, value } => done(d.set_read(&buffer, &value)),
        Request::SetHook { hook, value } => done(d.set_hook(&hook, &value)),
        Request::SetVar { var, value } => done(d.set_var(&var, &value)),
        Request::SetWrite { buffer, value } => done(d.set_write(&buffer, &value)),
        Request::WriteSubStatus { sub, status } => done(d.write_sub_status(&sub, status)),
        Request::LastSent { sub } => serial(d.last_sent(&sub)),
        Request::Cycle => Response::Record(d.cycle()),
        Request::WriteSubField { sub, field, value } => {
            done(d.write_sub_field(&sub, &field, &value))
        }
        _ => Response::Failed("a system request to one controller".to_string()),
    }
}
