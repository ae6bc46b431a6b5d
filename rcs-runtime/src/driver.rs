//! Driving one controller alone, by name, from outside: the interface a
//! scenario runner or a differential test needs.
//!
//! A [`Driven`] controller plays against a world the caller scripts: the
//! caller writes its supervisor's command, its `reads` buffers, the results
//! its hooks return and its subordinates' status buffers, runs one cycle,
//! and gets back a [`Record`] of what the cycle did. rcsc has two backends
//! behind this one trait — the reference interpreter (`rcs-dsl`) and the
//! generated code (`rcs-codegen` emits a `Driver` per controller when asked
//! to, e.g. `Config::driver(true)`) — so a scenario means the same on both
//! and their traces can be compared cycle by cycle.
//!
//! Values cross this interface as dynamic [`Value`]s, which allocate: this
//! is test tooling, never the cycle path of a running system.

use crate::handshake::{ErrorCode, RowId, StateId, Status, StatusBuffer, VerbId};

pub mod system;
use serde::{Deserialize, Serialize};
pub use system::{DrivenSystem, RemoteSystem, SystemFactory};

/// A value of any plan type, as the interpreter computes it and as the
/// generated types convert to and from it ([`ToValue`], [`FromValue`]).
///
/// Integers hold every width (range is the type's business); `f32` values
/// are held as the `f64` of the same number.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Value {
    /// `bool`.
    Bool(bool),
    /// Any integer type.
    Int(i128),
    /// `f32` or `f64`.
    Float(f64),
    /// An enum variant by its declaration index.
    Enum(u32),
    /// A status code ([`Status`]).
    Status(u16),
    /// A buffer's fields in declaration order.
    Buffer(Vec<Value>),
    /// An array's elements.
    Array(Vec<Value>),
    /// No value (hooks returning nothing).
    Unit,
}

/// A typed value as a [`Value`].
pub trait ToValue {
    /// The dynamic value.
    fn to_value(&self) -> Value;
}

/// A typed value from a [`Value`]: `None` when the value has another shape
/// or is out of the type's range.
pub trait FromValue: Sized {
    /// The typed value.
    fn from_value(v: &Value) -> Option<Self>;
}

impl ToValue for bool {
    fn to_value(&self) -> Value {
        Value::Bool(*self)
    }
}

impl FromValue for bool {
    fn from_value(v: &Value) -> Option<Self> {
        match v {
            Value::Bool(b) => Some(*b),
            _ => None,
        }
    }
}

macro_rules! int_values {
    ($($t:ty),*) => {$(
        impl ToValue for $t {
            fn to_value(&self) -> Value {
                Value::Int(i128::from(*self))
            }
        }
        impl FromValue for $t {
            fn from_value(v: &Value) -> Option<Self> {
                match v {
                    Value::Int(i) => <$t>::try_from(*i).ok(),
                    _ => None,
                }
            }
        }
    )*};
}

int_values!(i8, i16, i32, i64, u8, u16, u32, u64);

impl ToValue for f64 {
    fn to_value(&self) -> Value {
        Value::Float(*self)
    }
}

impl FromValue for f64 {
    fn from_value(v: &Value) -> Option<Self> {
        match v {
            Value::Float(f) => Some(*f),
            _ => None,
        }
    }
}

impl ToValue for f32 {
    fn to_value(&self) -> Value {
        Value::Float(f64::from(*self))
    }
}

impl FromValue for f32 {
    /// Rounds to the nearest `f32`, as the generated arithmetic does.
    fn from_value(v: &Value) -> Option<Self> {
        match v {
            Value::Float(f) => Some(*f as f32),
            _ => None,
        }
    }
}

impl ToValue for Status {
    fn to_value(&self) -> Value {
        Value::Status(self.0)
    }
}

impl FromValue for Status {
    fn from_value(v: &Value) -> Option<Self> {
        match v {
            Value::Status(s) => Some(Status(*s)),
            _ => None,
        }
    }
}

/// An error code travels as its number (`rcs_dsl` gives it the name).
impl ToValue for ErrorCode {
    fn to_value(&self) -> Value {
        Value::Int(i128::from(self.0))
    }
}

impl FromValue for ErrorCode {
    fn from_value(v: &Value) -> Option<Self> {
        match v {
            Value::Int(n) => u16::try_from(*n).ok().map(ErrorCode),
            _ => None,
        }
    }
}

impl ToValue for () {
    fn to_value(&self) -> Value {
        Value::Unit
    }
}

impl FromValue for () {
    fn from_value(v: &Value) -> Option<Self> {
        matches!(v, Value::Unit).then_some(())
    }
}

impl<T: ToValue, const N: usize> ToValue for [T; N] {
    fn to_value(&self) -> Value {
        Value::Array(self.iter().map(ToValue::to_value).collect())
    }
}

impl<T: FromValue, const N: usize> FromValue for [T; N] {
    fn from_value(v: &Value) -> Option<Self> {
        let Value::Array(items) = v else {
            return None;
        };
        let items: Vec<T> = items.iter().map(T::from_value).collect::<Option<_>>()?;
        items.try_into().ok()
    }
}

/// A controller's command enum seen by name: built from a verb name and
/// arguments, taken apart into a verb id and arguments.
pub trait DrivenCommand: Sized {
    /// The command `verb(args…)`; an error names what does not fit.
    fn from_parts(verb: &str, args: &[Value]) -> Result<Self, DriveError>;
    /// The verb id and the arguments in declaration order.
    fn parts(&self) -> (VerbId, Vec<Value>);
}

/// A name or value the driven controller does not accept.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum DriveError {
    /// The controller has nothing of this kind with this name.
    #[error("`{controller}` has no {kind} `{name}`")]
    Unknown {
        /// The controller.
        controller: String,
        /// `verb`, `read buffer`, `hook` or `subordinate`.
        kind: String,
        /// The name asked for.
        name: String,
    },
    /// A value of the wrong shape or range.
    #[error("`{controller}`: {what}: a value of another type")]
    Type {
        /// The controller.
        controller: String,
        /// What the value was for (`AHEAD.speed`, `ship`, …).
        what: String,
    },
    /// A verb given the wrong number of arguments.
    #[error("`{controller}`: {verb} takes {expected} argument(s), got {got}")]
    Arity {
        /// The controller.
        controller: String,
        /// The verb.
        verb: String,
        /// Its parameter count.
        expected: usize,
        /// The count given.
        got: usize,
    },
}

impl DriveError {
    /// The same error, for controller `name`: a command type shared by the
    /// instances of a controller type names the type; the instance's
    /// driver names the instance.
    pub fn for_controller(mut self, name: &str) -> DriveError {
        match &mut self {
            DriveError::Unknown { controller, .. }
            | DriveError::Type { controller, .. }
            | DriveError::Arity { controller, .. } => *controller = name.to_string(),
        }
        self
    }
}

/// The `index`-th argument of `verb`, typed. For generated `from_parts`.
pub fn arg<T: FromValue>(
    controller: &str,
    verb: &str,
    param: &str,
    args: &[Value],
    index: usize,
) -> Result<T, DriveError> {
    args.get(index)
        .and_then(T::from_value)
        .ok_or_else(|| DriveError::Type {
            controller: controller.to_string(),
            what: format!("{verb}.{param}"),
        })
}

/// `verb` must have exactly `expected` arguments. For generated `from_parts`.
pub fn arity(
    controller: &str,
    verb: &str,
    args: &[Value],
    expected: usize,
) -> Result<(), DriveError> {
    if args.len() == expected {
        Ok(())
    } else {
        Err(DriveError::Arity {
            controller: controller.to_string(),
            verb: verb.to_string(),
            expected,
            got: args.len(),
        })
    }
}

/// `name` is not one of `controller`'s `kind`s.
pub fn unknown(controller: &str, kind: &str, name: &str) -> DriveError {
    DriveError::Unknown {
        controller: controller.to_string(),
        kind: kind.to_string(),
        name: name.to_string(),
    }
}

/// `value` typed for `what`, or a [`DriveError::Type`].
pub fn typed<T: FromValue>(controller: &str, what: &str, value: &Value) -> Result<T, DriveError> {
    T::from_value(value).ok_or_else(|| DriveError::Type {
        controller: controller.to_string(),
        what: what.to_string(),
    })
}

/// A command a cycle sent to a subordinate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sent {
    /// The subordinate, by its position in the controller's `subordinates`.
    pub sub: u16,
    /// The verb, by its position in the subordinate's commands.
    pub verb: VerbId,
    /// The arguments in declaration order.
    pub args: Vec<Value>,
    /// The serial it was sent with.
    pub serial: u32,
}

/// What one cycle did and left behind.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// The cycle (0 first).
    pub cycle: u64,
    /// The verb of the command being (or last) executed; `None` before the first.
    pub verb: Option<VerbId>,
    /// The row that fired, if one did.
    pub fired: Option<RowId>,
    /// The plan's state after the cycle.
    pub state: StateId,
    /// The status after the cycle.
    pub status: Status,
    /// The error code after the cycle.
    pub error: ErrorCode,
    /// The serial of the command the status is about (0: none yet).
    #[serde(default)]
    pub echo_serial: u32,
    /// The serial of the command refused last (0: none), docs/semantics.md
    /// step 3a: its sender sees `ERROR`/`REFUSED` for it.
    #[serde(default)]
    pub refused_serial: u32,
    /// Commands sent to subordinates this cycle, in subordinate order.
    pub sent: Vec<Sent>,
    /// The controller's vars after the cycle, in declaration order.
    pub vars: Vec<Value>,
    /// Its `writes` buffers after the cycle, in declaration order.
    pub writes: Vec<Value>,
    /// How many times each hook was called this cycle, in declaration
    /// order (a condition's call counts once however many rows ask).
    #[serde(default)]
    pub hook_calls: Vec<u32>,
    /// Each hook call this cycle that ran (not one answered from the
    /// cycle's condition cache): the hook's index and its arguments, in
    /// call order.
    #[serde(default)]
    pub hook_args: Vec<(u16, Vec<Value>)>,
}

/// One controller driven alone. Names are as written in the plans.
pub trait Driven {
    /// The controller's name.
    fn name(&self) -> &str;
    /// The supervisor writes a new command (the next serial), read at the
    /// next cycle. Returns the serial.
    fn command(&mut self, verb: &str, args: &[Value]) -> Result<u32, DriveError>;
    /// The world writes `reads` buffer `buffer`; the next cycle reads it.
    fn set_read(&mut self, buffer: &str, value: &Value) -> Result<(), DriveError>;
    /// From now on hook `hook` returns `value` (until set again). Before it
    /// is set a hook returns its type's zero.
    fn set_hook(&mut self, hook: &str, value: &Value) -> Result<(), DriveError>;
    /// Var `var` holds `value` from now on (until the plan assigns it):
    /// how a scenario's `initial:` sets the world model.
    fn set_var(&mut self, var: &str, value: &Value) -> Result<(), DriveError>;
    /// The controller's own `writes` buffer `buffer` holds `value` from now
    /// on (until a job writes it).
    fn set_write(&mut self, buffer: &str, value: &Value) -> Result<(), DriveError>;
    /// Subordinate `sub` writes its status buffer (a new generation) before
    /// the next cycle. A subordinate not written is silent: its status
    /// goes stale. An `echo_epoch` of 0 stands for the epoch of this
    /// controller's commands to `sub`, which the driver fills in: scenarios
    /// name serials only (the epoch is a detail of the handshake); a
    /// nonzero epoch is written as given.
    fn write_sub_status(&mut self, sub: &str, status: StatusBuffer) -> Result<(), DriveError>;
    /// The serial of the last command this controller sent `sub` (0: none).
    fn last_sent(&mut self, sub: &str) -> Result<u32, DriveError>;
    /// One control cycle.
    fn cycle(&mut self) -> Record;
    /// Subordinate `sub` publishes `value` for its status field `field`
    /// (`status NAME: TYPE`), read from the next cycle on as `sub.field`
    /// whatever serial its status buffer echoes. A controller whose
    /// subordinates have no status fields refuses every name. An unknown
    /// subordinate or field is `unknown(self, "status field", "sub.field")`.
    fn write_sub_field(&mut self, sub: &str, field: &str, value: &Value) -> Result<(), DriveError> {
        let _ = value;
        Err(unknown(
            self.name(),
            "status field",
            &format!("{sub}.{field}"),
        ))
    }
}

/// One request of the driver protocol: [`serve`] reads them as JSON lines
/// and answers each with one [`Response`] line; [`Remote`] writes them.
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

/// A controller driven through the protocol, in another process (the
/// client side of [`serve`]). A broken connection or a refused request is
/// kept in [`Remote::failure`]; the calls then return empty answers.
#[derive(Debug)]
pub struct Remote<R, W> {
    input: R,
    output: W,
    name: String,
    failure: Option<String>,
}

impl<R: std::io::BufRead, W: std::io::Write> Remote<R, W> {
    /// Ask the server for a fresh `controller` of plan set `set`.
    pub fn open(input: R, output: W, set: usize, controller: &str) -> Result<Self, String> {
        let mut me = Remote {
            input,
            output,
            name: controller.to_string(),
            failure: None,
        };
        match me.call(&Request::New {
            set,
            controller: controller.to_string(),
        }) {
            Some(Response::Done) => Ok(me),
            _ => Err(me
                .failure
                .unwrap_or_else(|| "unexpected answer".to_string())),
        }
    }

    /// Give the connection back (to open the next controller on it).
    pub fn into_parts(self) -> (R, W) {
        (self.input, self.output)
    }

    /// Why the connection failed, if it did.
    pub fn failure(&self) -> Option<&str> {
        self.failure.as_deref()
    }

    fn call(&mut self, request: &Request) -> Option<Response> {
        if self.failure.is_some() {
            return None;
        }
        let result = (|| -> Result<Response, String> {
            let text = serde_json::to_string(request).map_err(|e| e.to_string())?;
            writeln!(self.output, "{text}").map_err(|e| e.to_string())?;
            self.output.flush().map_err(|e| e.to_string())?;
            let mut line = String::new();
            if self.input.read_line(&mut line).map_err(|e| e.to_string())? == 0 {
                return Err("the driver process ended".to_string());
            }
            serde_json::from_str(&line).map_err(|e| format!("malformed answer: {e}"))
        })();
        match result {
            Ok(Response::Failed(reason)) => {
                self.failure = Some(reason);
                None
            }
            Ok(r) => Some(r),
            Err(reason) => {
                self.failure = Some(reason);
                None
            }
        }
    }

    fn unit(&mut self, request: &Request) -> Result<(), DriveError> {
        match self.call(request) {
            Some(Response::Refused(e)) => Err(e),
            _ => Ok(()),
        }
    }

    fn serial(&mut self, request: &Request) -> Result<u32, DriveError> {
        match self.call(request) {
            Some(Response::Serial(n)) => Ok(n),
            Some(Response::Refused(e)) => Err(e),
            _ => Ok(0),
        }
    }
}

impl<R: std::io::BufRead, W: std::io::Write> Driven for Remote<R, W> {
    fn name(&self) -> &str {
        &self.name
    }

    fn command(&mut self, verb: &str, args: &[Value]) -> Result<u32, DriveError> {
        self.serial(&Request::Command {
            verb: verb.to_string(),
            args: args.to_vec(),
        })
    }

    fn set_read(&mut self, buffer: &str, value: &Value) -> Result<(), DriveError> {
        self.unit(&Request::SetRead {
            buffer: buffer.to_string(),
            value: value.clone(),
        })
    }

    fn set_hook(&mut self, hook: &str, value: &Value) -> Result<(), DriveError> {
        self.unit(&Request::SetHook {
            hook: hook.to_string(),
            value: value.clone(),
        })
    }

    fn set_var(&mut self, var: &str, value: &Value) -> Result<(), DriveError> {
        self.unit(&Request::SetVar {
            var: var.to_string(),
            value: value.clone(),
        })
    }

    fn set_write(&mut self, buffer: &str, value: &Value) -> Result<(), DriveError> {
        self.unit(&Request::SetWrite {
            buffer: buffer.to_string(),
            value: value.clone(),
        })
    }

    fn write_sub_status(&mut self, sub: &str, status: StatusBuffer) -> Result<(), DriveError> {
        self.unit(&Request::WriteSubStatus {
            sub: sub.to_string(),
            status,
        })
    }

    fn last_sent(&mut self, sub: &str) -> Result<u32, DriveError> {
        self.serial(&Request::LastSent {
            sub: sub.to_string(),
        })
    }

    fn cycle(&mut self) -> Record {
        match self.call(&Request::Cycle) {
            Some(Response::Record(r)) => r,
            _ => Record::default(),
        }
    }

    fn write_sub_field(&mut self, sub: &str, field: &str, value: &Value) -> Result<(), DriveError> {
        self.unit(&Request::WriteSubField {
            sub: sub.to_string(),
            field: field.to_string(),
            value: value.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_refuse_values_out_of_their_range() {
        assert_eq!(u8::from_value(&Value::Int(255)), Some(255));
        assert_eq!(u8::from_value(&Value::Int(256)), None);
        assert_eq!(i8::from_value(&Value::Int(-129)), None);
        assert_eq!(i64::from_value(&Value::Float(1.0)), None);
    }

    #[test]
    fn arrays_round_trip_and_check_their_length() {
        let a = [1.5f32, -2.0, 0.25];
        let v = a.to_value();
        assert_eq!(<[f32; 3]>::from_value(&v), Some(a));
        assert_eq!(<[f32; 2]>::from_value(&v), None);
    }

    #[test]
    fn f32_values_round_to_f32() {
        assert_eq!(f32::from_value(&Value::Float(0.1)), Some(0.1f32));
        assert_eq!(0.1f32.to_value(), Value::Float(f64::from(0.1f32)));
    }

    #[test]
    fn errors_name_the_controller_and_the_name() {
        assert_eq!(
            unknown("PR", "hook", "nope").to_string(),
            "`PR` has no hook `nope`"
        );
        let e = arity("PR", "AHEAD", &[], 1).unwrap_err();
        assert_eq!(e.to_string(), "`PR`: AHEAD takes 1 argument(s), got 0");
        let e = arg::<f64>("PR", "AHEAD", "speed", &[Value::Bool(true)], 0).unwrap_err();
        assert_eq!(e.to_string(), "`PR`: AHEAD.speed: a value of another type");
    }
}
