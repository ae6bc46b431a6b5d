//! The typed ids of the IR: each indexes one `Vec` of [`Ir`](super::Ir) or
//! of one of its entities, so a reference is a number that cannot be mixed
//! up with another kind's. The built-in states and statuses have names here.

use serde::Serialize;

macro_rules! id {
    ($(#[$m:meta])* $name:ident) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
        #[serde(transparent)]
        pub struct $name(pub u32);
        impl $name {
            pub fn index(self) -> usize {
                self.0 as usize
            }
        }
    };
}

id!(/// Index into [`Ir::enums`](super::Ir::enums).
    EnumId);
id!(/// Index into [`Ir::buffer_types`](super::Ir::buffer_types).
    BufferTypeId);
id!(/// Index into [`Ir::buffers`](super::Ir::buffers) (Global Memory instances).
    BufferId);
id!(/// Index into [`Ir::controllers`](super::Ir::controllers).
    CtrlId);
id!(/// Index into [`Controller::commands`](super::Controller::commands).
    CommandId);
id!(/// Index into [`Command::params`](super::Command::params).
    ParamId);
id!(/// Index into [`Controller::statuses`](super::Controller::statuses); 0..=3 are the built-ins.
    StatusId);
id!(/// Index into [`Controller::errors`](super::Controller::errors).
    ErrorId);
id!(/// Index into [`Controller::vars`](super::Controller::vars).
    VarId);
id!(/// Index into [`Controller::hooks`](super::Controller::hooks).
    HookId);
id!(/// Index into [`Controller::plans`](super::Controller::plans).
    PlanId);
id!(/// Index into [`Plan::states`](super::Plan::states); `StateId(0)` is always `S0`.
    StateId);
id!(/// Index into [`Plan::rows`](super::Plan::rows), equal to the row's precedence position.
    RowId);

impl StateId {
    /// The state a plan is in right after a new command arrives.
    pub const S0: StateId = StateId(0);
}

impl StatusId {
    pub const NOT_READY: StatusId = StatusId(0);
    pub const EXECUTING: StatusId = StatusId(1);
    pub const DONE: StatusId = StatusId(2);
    pub const ERROR: StatusId = StatusId(3);
    /// Names of the built-in statuses, in id order.
    pub const BUILTIN: [&'static str; 4] = ["NOT_READY", "EXECUTING", "DONE", "ERROR"];
}
