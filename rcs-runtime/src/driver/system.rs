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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::handshake::Status;

    /// A run of one controller `A` on CPU `main` that counts its cycles,
    /// enough to carry every request over the protocol.
    #[derive(Default)]
    struct Counting {
        cycles: u64,
        hook: Option<Value>,
    }

    impl DrivenSystem for Counting {
        fn command(&mut self, root: &str, _: &str, _: &[Value]) -> Result<u32, DriveError> {
            match root {
                "A" => Ok(7),
                _ => Err(super::super::unknown("the run", "root controller", root)),
            }
        }
        fn set_read(&mut self, _: &str, _: &Value) -> Result<(), DriveError> {
            Ok(())
        }
        fn set_hook(&mut self, _: &str, _: &str, value: &Value) -> Result<(), DriveError> {
            self.hook = Some(value.clone());
            Ok(())
        }
        fn set_var(&mut self, _: &str, _: &str, _: &Value) -> Result<(), DriveError> {
            Ok(())
        }
        fn run_cpu(&mut self, cpu: &str) -> Result<Vec<(String, Record)>, DriveError> {
            if cpu != "main" {
                return Err(super::super::unknown("the run", "CPU", cpu));
            }
            self.cycles += 1;
            let status = if self.hook.is_some() {
                Status::DONE
            } else {
                Status::EXECUTING
            };
            Ok(vec![(
                "A".to_string(),
                Record {
                    cycle: self.cycles,
                    status,
                    ..Record::default()
                },
            )])
        }
    }

    fn make(run: &[&str]) -> Result<Box<dyn DrivenSystem>, String> {
        if run == ["A"] {
            Ok(Box::new(Counting::default()))
        } else {
            Err(format!("no run {run:?}"))
        }
    }

    #[test]
    fn a_system_run_is_served_and_driven_remotely() {
        // Play the client's requests into the server, then its answers back.
        let requests = [
            Request::NewSystem {
                set: 0,
                controllers: vec!["A".into()],
            },
            Request::SystemCommand {
                root: "A".into(),
                verb: "GO".into(),
                args: vec![],
            },
            Request::SystemCommand {
                root: "B".into(),
                verb: "GO".into(),
                args: vec![],
            },
            Request::SystemSetHook {
                controller: "A".into(),
                hook: "h".into(),
                value: Value::Bool(true),
            },
            Request::RunCpu { cpu: "main".into() },
            Request::RunCpu {
                cpu: "other".into(),
            },
            Request::Cycle,
        ];
        let input: String = requests
            .iter()
            .map(|r| serde_json::to_string(r).unwrap() + "\n")
            .collect();
        let mut answers = Vec::new();
        super::super::serve_systems(&[], &[make], input.as_bytes(), &mut answers).unwrap();
        let answers: Vec<Response> = String::from_utf8(answers)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(answers[0], Response::Done);
        assert_eq!(answers[1], Response::Serial(7));
        assert!(matches!(answers[2], Response::Refused(_)));
        assert_eq!(answers[3], Response::Done);
        let Response::Records(r) = &answers[4] else {
            panic!("{:?}", answers[4])
        };
        assert_eq!((r[0].0.as_str(), r[0].1.status), ("A", Status::DONE));
        assert!(matches!(answers[5], Response::Refused(_)));
        // A one-controller request with no controller open fails, it does not panic.
        assert!(matches!(answers[6], Response::Failed(_)));

        // The client side reads those same answers.
        let replies: String = answers[..5]
            .iter()
            .map(|a| serde_json::to_string(a).unwrap() + "\n")
            .collect();
        let mut sent = Vec::new();
        let mut remote = RemoteSystem::open(replies.as_bytes(), &mut sent, 0, &["A"]).unwrap();
        assert_eq!(remote.command("A", "GO", &[]), Ok(7));
        assert!(remote.command("B", "GO", &[]).is_err());
        assert_eq!(remote.set_hook("A", "h", &Value::Bool(true)), Ok(()));
        assert_eq!(remote.run_cpu("main").unwrap().len(), 1);
        // The connection ends: empty answers and a failure, not a panic.
        assert_eq!(remote.run_cpu("main").unwrap(), vec![]);
        assert!(remote.failure().is_some());
        drop(remote);
        let written = String::from_utf8(sent).unwrap();
        assert!(written.starts_with("{\"NewSystem\""), "{written}");

        // A run the factory refuses is a failure, reported.
        let input = serde_json::to_string(&Request::NewSystem {
            set: 0,
            controllers: vec!["Z".into()],
        })
        .unwrap();
        let mut out = Vec::new();
        super::super::serve_systems(&[], &[make], input.as_bytes(), &mut out).unwrap();
        assert!(String::from_utf8(out).unwrap().contains("no run"));
    }
}
