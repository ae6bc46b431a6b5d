//! Propulsion (PR) written by hand over rcs-runtime: the plans of Appendix
//! C with the same Global Memory buffers and runtime calls as the generated
//! controller, in the shape an engineer would write it (one `match` on the
//! state, the speed error computed once per cycle), publishing the same
//! status fields (ordered RPM, ship speed) every cycle. The benchmark's
//! yardstick.

use rcs_runtime::{
    Bookkeeping, Command, CommandBuffer, Controller, CycleContext, GlobalMemory, Reader,
    SetupError, StateId, Status, StatusBuffer, Subordinate, SubordinateView, Target, VerbId,
    Writer,
};

/// Ship direction, as in `plans/submarine/propulsion.rcs`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShipDirection {
    #[default]
    Ahead,
    Stopped,
    Backward,
}

/// The `ship` buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ship {
    pub direction: ShipDirection,
    pub speed: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpeedError {
    Below,
    At,
    Above,
}

/// PR's verbs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum PrCommand {
    #[default]
    Init,
    Halt,
    Ahead {
        speed: f64,
    },
}

impl Command for PrCommand {
    fn verb(&self) -> VerbId {
        match self {
            PrCommand::Init => 0,
            PrCommand::Halt => 1,
            PrCommand::Ahead { .. } => 2,
        }
    }
}

/// TB's verbs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum TbCommand {
    #[default]
    Init,
    Halt,
    Ahead {
        rpm: f64,
    },
    Stop,
}

impl Command for TbCommand {
    fn verb(&self) -> VerbId {
        match self {
            TbCommand::Init => 0,
            TbCommand::Halt => 1,
            TbCommand::Ahead { .. } => 2,
            TbCommand::Stop => 3,
        }
    }
}

/// PR's status fields, as the generated `pr::StatusFields` (same Global
/// Memory buffer, `PR.status_fields`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PrStatusFields {
    pub ordered_rpm: f64,
    pub ship_speed: f64,
}

const AT_GOAL: Status = Status::custom(0);
const S1: StateId = 1;
const S2: StateId = 2;

/// The propulsion model: RPM for a speed.
pub fn required_rpm(speed: f64) -> f64 {
    speed * 10.0
}

/// Ship speed against the goal, inside a ±0.5 knot dead band.
pub fn speed_error(ship: &Ship, goal: f64) -> SpeedError {
    if ship.speed < goal - 0.5 {
        SpeedError::Below
    } else if ship.speed > goal + 0.5 {
        SpeedError::Above
    } else {
        SpeedError::At
    }
}

pub struct Propulsion {
    bk: Bookkeeping,
    cmd_in: Reader<CommandBuffer<PrCommand>>,
    status_out: Writer<StatusBuffer>,
    fields_out: Writer<PrStatusFields>,
    ship_in: Reader<Ship>,
    tb: Subordinate<TbCommand>,
    cmd: PrCommand,
    ship: Ship,
    rpm: f64,
    fields: PrStatusFields,
}

impl Propulsion {
    pub fn new(gm: &GlobalMemory) -> Result<Self, SetupError> {
        gm.declare_controller::<PrCommand>("PR")?;
        gm.declare::<Ship>("ship")?;
        gm.declare::<PrStatusFields>(&rcs_runtime::status_fields_buffer_name("PR"))?;
        Ok(Self {
            bk: Bookkeeping::new(3),
            cmd_in: gm.command_reader("PR")?,
            status_out: gm.status_writer("PR")?,
            fields_out: gm.writer(&rcs_runtime::status_fields_buffer_name("PR"))?,
            ship_in: gm.reader("ship")?,
            tb: Subordinate::connect(gm, "TB")?,
            cmd: PrCommand::default(),
            ship: Ship::default(),
            rpm: 0.0,
            fields: PrStatusFields::default(),
        })
    }

    fn send_ahead(&mut self) {
        self.tb.send(TbCommand::Ahead { rpm: self.rpm });
    }

    fn ahead(&mut self, speed: f64, tb: SubordinateView) {
        match self.bk.state() {
            S1 if tb.done() => match speed_error(&self.ship, speed) {
                SpeedError::Below => {
                    self.rpm += 1.0;
                    self.send_ahead();
                    self.bk.fire(2, Target::State(S1));
                }
                SpeedError::At => {
                    self.bk.report(AT_GOAL);
                    self.bk.fire(3, Target::State(S1));
                }
                SpeedError::Above => {
                    self.rpm -= 1.0;
                    self.send_ahead();
                    self.bk.fire(4, Target::State(S1));
                }
            },
            S2 if tb.done() => {
                self.rpm = required_rpm(speed);
                self.send_ahead();
                self.bk.fire(5, Target::State(S1));
            }
            _ if self.bk.new_command() => match self.ship.direction {
                ShipDirection::Ahead | ShipDirection::Stopped => {
                    self.rpm = required_rpm(speed);
                    self.send_ahead();
                    self.bk.fire(0, Target::State(S1));
                }
                ShipDirection::Backward => {
                    self.tb.send(TbCommand::Stop);
                    self.bk.fire(1, Target::State(S2));
                }
            },
            _ => {}
        }
    }

    /// INIT and HALT: command TB, then wait for it.
    fn pass_down(&mut self, command: TbCommand, tb: SubordinateView) {
        if self.bk.new_command() {
            self.tb.send(command);
            self.bk.fire(0, Target::State(S1));
        } else if self.bk.state() == S1 && tb.done() {
            self.bk.fire(1, Target::Done);
        }
    }
}

impl Controller for Propulsion {
    fn name(&self) -> &str {
        "PR"
    }

    // `#[inline]` so that a caller in another crate may inline it, as it may
    // the generated `cycle` (generic, so compiled in the caller's crate).
    #[inline]
    fn cycle(&mut self, ctx: &CycleContext) {
        let cmd = self.cmd_in.read().value;
        self.ship = self.ship_in.read().value;
        let tb = self.tb.read();
        self.bk.begin_cycle(ctx.tick(), &cmd, true);
        if self.bk.new_command() {
            self.cmd = cmd.command;
        }
        // pre: the ship speed as read this cycle.
        self.fields.ship_speed = self.ship.speed;
        if self.bk.is_active() {
            match self.cmd {
                PrCommand::Init => {
                    if self.bk.new_command() {
                        self.rpm = 0.0;
                    }
                    self.pass_down(TbCommand::Init, tb);
                }
                PrCommand::Halt => self.pass_down(TbCommand::Halt, tb),
                PrCommand::Ahead { speed } => self.ahead(speed, tb),
            }
        }
        // post: the RPM last ordered.
        self.fields.ordered_rpm = self.rpm;
        self.status_out.write(self.bk.status_buffer(), ctx.cycle);
        self.fields_out.write(self.fields, ctx.cycle);
        self.tb.flush(ctx.cycle);
        self.bk.end_cycle();
    }

    fn bookkeeping(&self) -> Option<&Bookkeeping> {
        Some(&self.bk)
    }
}
