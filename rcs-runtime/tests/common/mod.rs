//! A small hand-written hierarchy for the integration tests: `Relay`
//! controllers in the template's shape, each optionally commanding one
//! subordinate.
#![allow(dead_code)]

use rcs_runtime::{
    Bookkeeping, CommandBuffer, Controller, CycleContext, ErrorCode, GlobalMemory, Reader,
    SetupError, StatusBuffer, Subordinate, SubordinateView, Target, VerbId, Writer,
};

/// Verb GO: command the subordinate (if any) and finish when it is done, or
/// after `work` cycles in S1 for a leaf.
pub const GO: VerbId = 0;
/// Verb HOLD: enter S1 and stay there (a continuous plan).
pub const HOLD: VerbId = 1;
/// Verbs at or above this have no plan.
pub const VERB_COUNT: VerbId = 2;
/// Error reported when the subordinate fails.
pub const SUB_FAILED: ErrorCode = ErrorCode::custom(0);

pub struct Relay {
    pub name: &'static str,
    cmd_in: Reader<CommandBuffer<VerbId>>,
    status_out: Writer<StatusBuffer>,
    pub sub: Option<Subordinate<VerbId>>,
    pub bk: Bookkeeping,
    pub work: u32,
    cmd: CommandBuffer<VerbId>,
    /// The subordinate's view as of the last cycle (for tests).
    pub last_view: SubordinateView,
}

impl Relay {
    /// Controller `name` commanding `sub` (if any); a leaf finishes GO after
    /// `work` cycles in S1.
    pub fn new(
        gm: &GlobalMemory,
        name: &'static str,
        sub: Option<&str>,
        work: u32,
    ) -> Result<Self, SetupError> {
        gm.declare_controller::<VerbId>(name)?;
        let sub = match sub {
            Some(s) => Some(Subordinate::connect(gm, s)?),
            None => None,
        };
        Ok(Self {
            name,
            cmd_in: gm.command_reader(name)?,
            status_out: gm.status_writer(name)?,
            sub,
            bk: Bookkeeping::new(usize::from(VERB_COUNT)),
            work,
            cmd: CommandBuffer::default(),
            last_view: SubordinateView::default(),
        })
    }

    fn pre_process(&mut self) {
        self.cmd = self.cmd_in.read().value;
        if let Some(sub) = &mut self.sub {
            self.last_view = sub.read();
        }
    }

    fn decide(&mut self, ctx: &CycleContext) {
        let verb = self.cmd.verb();
        self.bk
            .begin_cycle(ctx.tick(), &self.cmd, verb < VERB_COUNT);
        if !self.bk.is_active() {
            return;
        }
        let new = self.bk.new_command();
        let state = self.bk.state();
        let view = self.last_view;
        match verb {
            GO => {
                if new {
                    // E0: *0 when new_command -> S1 { SUB <- GO }
                    if let Some(sub) = &mut self.sub {
                        sub.send(GO);
                    }
                    self.bk.fire(0, Target::State(1));
                } else if state == 1 && self.sub.is_some() && view.error() {
                    // E1: S1 when SUB.error -> Error(SUB_FAILED)
                    self.bk.fire(1, Target::Error(SUB_FAILED));
                } else if state == 1
                    && match self.sub {
                        Some(_) => view.done(),
                        None => self.bk.state_cycles() >= self.work,
                    }
                {
                    // E2: S1 when SUB.done (or state_cycles >= work) -> Done
                    self.bk.fire(2, Target::Done);
                }
            }
            HOLD if new => {
                // E0: *0 when new_command -> S1 { SUB <- HOLD }
                if let Some(sub) = &mut self.sub {
                    sub.send(HOLD);
                }
                self.bk.fire(0, Target::State(1));
            }
            _ => {}
        }
    }

    fn post_process(&mut self, ctx: &CycleContext) {
        self.status_out.write(self.bk.status_buffer(), ctx.cycle);
        if let Some(sub) = &mut self.sub {
            sub.flush(ctx.cycle);
        }
        self.bk.end_cycle();
    }
}

impl Controller for Relay {
    fn name(&self) -> &str {
        self.name
    }
    fn cycle(&mut self, ctx: &CycleContext) {
        self.pre_process();
        self.decide(ctx);
        self.post_process(ctx);
    }
    fn bookkeeping(&self) -> Option<&Bookkeeping> {
        Some(&self.bk)
    }
}
