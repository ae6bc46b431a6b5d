//! The interpreter's side of `X <- cmd` (lowered to [`Job::Forward`]):
//! which of the subordinate's commands the running verb becomes, with the
//! arguments exactly as received.

use super::{Interpreter, Sent};
use crate::ir::{CommandId, CtrlId, Job};
use rcs_runtime::driver::Value;

impl Interpreter<'_> {
    /// The command a `Forward` job sends for the running verb, and its
    /// arguments; `None` when the job is no `Forward` or the verb is not
    /// among its plan's (lowering guarantees it is).
    pub(super) fn forwarded(&self, j: &Job) -> Option<(CommandId, Vec<Value>)> {
        let Job::Forward { commands, .. } = j else {
            return None;
        };
        let verb = CommandId(u32::from(self.bk.verb()));
        let (_, theirs) = commands.iter().find(|(ours, _)| *ours == verb)?;
        Some((*theirs, self.active_params.clone()))
    }

    /// Send `command(args)` to `sub` under a new serial (a `Send` job and a
    /// `Forward` job alike).
    pub(super) fn send(
        &mut self,
        sub: CtrlId,
        command: CommandId,
        args: Vec<Value>,
        sent: &mut Vec<Sent>,
    ) {
        let i = self.ctrl.subordinate_index(sub).expect("a subordinate");
        let serial = self.subs[i].link.next_command();
        sent.push(Sent {
            sub,
            command,
            args,
            serial,
        });
    }
}
