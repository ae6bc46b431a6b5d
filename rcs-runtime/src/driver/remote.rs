//! The client side of the driver protocol: a [`Remote`] is a [`Driven`]
//! controller that lives in another process, each call one request line
//! and one answer line.

use super::{DriveError, Driven, Record, Request, Response, Value};
use crate::handshake::StatusBuffer;

/// A controller driven through the protocol, in another process (the
/// client side of [`serve`](super::serve)). A broken connection or a refused request is
/// kept in [`Remote::failure`]; the calls then return empty answers.
#[derive(Debug)]
pub struct Remote<R, W> {
    pub(super) input: R,
    pub(super) output: W,
    pub(super) name: String,
    pub(super) failure: Option<String>,
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

    pub(super) fn call(&mut self, request: &Request) -> Option<Response> {
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

    pub(super) fn unit(&mut self, request: &Request) -> Result<(), DriveError> {
        match self.call(request) {
            Some(Response::Refused(e)) => Err(e),
            _ => Ok(()),
        }
    }

    pub(super) fn serial(&mut self, request: &Request) -> Result<u32, DriveError> {
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
