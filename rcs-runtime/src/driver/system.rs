//! Driving a whole plan set, or a subtree of it, from outside: the
//! interface a *system* scenario runs on (docs/scenarios.md, "System
//! scenarios"). Where [`Driven`](super::Driven) plays everything around one
//! controller, a [`DrivenSystem`] runs several controllers that command and
//! answer each other for real through Global Memory, and the caller plays
//! only the environment: the external `reads` buffers (those no controller
//! of the run writes), the hooks, and the supervisor of each root of the run.
//!
//! The caller also owns the schedule: it asks for one cycle of one CPU at a
//! time ([`DrivenSystem::run_cpu`]), so that the interpreter and the
//! generated code run a multi-rate set in exactly the same interleaving
//! (`rcs_dsl::scenario` computes it from the schedule's periods).
//!
//! Like the rest of [`super`], this allocates: test tooling, never the
//! cycle path of a running system.

use super::{DriveError, Record, Remote, Request, Response, Value};

/// Several controllers of one plan set, on their real schedule. Names are
/// as written in the plans.
pub trait DrivenSystem {
    /// The supervisor of `root` (a controller of the run whose supervisor
    /// is not in the run) writes a new command, read at `root`'s next
    /// cycle. Returns the serial.
    fn command(&mut self, root: &str, verb: &str, args: &[Value]) -> Result<u32, DriveError>;
    /// The world writes external buffer `buffer` (one no controller of the
    /// run writes): a new generation, read at each reader's next cycle.
    fn set_read(&mut self, buffer: &str, value: &Value) -> Result<(), DriveError>;
    /// From now on hook `hook` of `controller` returns `value`.
    fn set_hook(&mut self, controller: &str, hook: &str, value: &Value) -> Result<(), DriveError>;
    /// Var `var` of `controller` holds `value` from now on (until a plan
    /// assigns it): a scenario's `initial: vars`.
    fn set_var(&mut self, controller: &str, var: &str, value: &Value) -> Result<(), DriveError>;
    /// One cycle of CPU `cpu` (its name in the schedule): each controller
    /// of the run on it runs once, in the CPU's order, each reading what
    /// the others last wrote. Returns each one's name and record, in that
    /// order (`sent` indexes the controller's own `subordinates`).
    fn run_cpu(&mut self, cpu: &str) -> Result<Vec<(String, Record)>, DriveError>;
}

/// Makes a fresh generated run of the named controllers (whole subtrees);
/// `Err` names what is wrong with the list. The generated
/// `new_system_driver` of each plan set has this type.
pub type SystemFactory = fn(&[&str]) -> Result<Box<dyn DrivenSystem>, String>;

/// One system request of the protocol, answered by `d` (the server side,
/// [`super::serve_systems`]).
pub(super) fn answer(d: &mut dyn DrivenSystem, request: Request) -> Response {
    let done = |r: Result<(), DriveError>| r.map_or_else(Response::Refused, |()| Response::Done);
    match request {
        Request::SystemCommand { root, verb, args } => d
            .command(&root, &verb, &args)
            .map_or_else(Response::Refused, Response::Serial),
        Request::SystemSetRead { buffer, value } => done(d.set_read(&buffer, &value)),
        Request::SystemSetHook {
            controller,
            hook,
            value,
        } => done(d.set_hook(&controller, &hook, &value)),
        Request::SystemSetVar {
            controller,
            var,
            value,
        } => done(d.set_var(&controller, &var, &value)),
        Request::RunCpu { cpu } => d
            .run_cpu(&cpu)
            .map_or_else(Response::Refused, Response::Records),
        _ => Response::Failed("not a system request".to_string()),
    }
}

/// A system run driven through the protocol, in another process (the
/// client side of [`super::serve_systems`]): how `rcsc test --backend
/// compiled` runs system scenarios. A broken connection is kept in
/// [`RemoteSystem::failure`]; the calls then return empty answers.
#[derive(Debug)]
pub struct RemoteSystem<R, W> {
    remote: Remote<R, W>,
}

impl<R: std::io::BufRead, W: std::io::Write> RemoteSystem<R, W> {
    /// Ask the server for a fresh run of `controllers` of plan set `set`.
    pub fn open(input: R, output: W, set: usize, controllers: &[&str]) -> Result<Self, String> {
        let mut remote = Remote {
            input,
            output,
            name: "the run".to_string(),
            failure: None,
        };
        match remote.call(&Request::NewSystem {
            set,
            controllers: controllers.iter().map(|c| c.to_string()).collect(),
        }) {
            Some(Response::Done) => Ok(RemoteSystem { remote }),
            _ => Err(remote
                .failure
                .unwrap_or_else(|| "unexpected answer".to_string())),
        }
    }

    /// Give the connection back.
    pub fn into_parts(self) -> (R, W) {
        self.remote.into_parts()
    }

    /// Why the connection failed, if it did.
    pub fn failure(&self) -> Option<&str> {
        self.remote.failure()
    }
}

impl<R: std::io::BufRead, W: std::io::Write> DrivenSystem for RemoteSystem<R, W> {
    fn command(&mut self, root: &str, verb: &str, args: &[Value]) -> Result<u32, DriveError> {
        self.remote.serial(&Request::SystemCommand {
            root: root.to_string(),
            verb: verb.to_string(),
            args: args.to_vec(),
        })
    }

    fn set_read(&mut self, buffer: &str, value: &Value) -> Result<(), DriveError> {
        self.remote.unit(&Request::SystemSetRead {
            buffer: buffer.to_string(),
            value: value.clone(),
        })
    }

    fn set_hook(&mut self, controller: &str, hook: &str, value: &Value) -> Result<(), DriveError> {
        self.remote.unit(&Request::SystemSetHook {
            controller: controller.to_string(),
            hook: hook.to_string(),
            value: value.clone(),
        })
    }

    fn set_var(&mut self, controller: &str, var: &str, value: &Value) -> Result<(), DriveError> {
        self.remote.unit(&Request::SystemSetVar {
            controller: controller.to_string(),
            var: var.to_string(),
            value: value.clone(),
        })
    }

    fn run_cpu(&mut self, cpu: &str) -> Result<Vec<(String, Record)>, DriveError> {
        match self.remote.call(&Request::RunCpu {
            cpu: cpu.to_string(),
        }) {
            Some(Response::Records(r)) => Ok(r),
            Some(Response::Refused(e)) => Err(e),
            _ => Ok(Vec::new()),
        }
    }
}
