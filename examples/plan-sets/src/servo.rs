//! Appendix C's S1 servo loop as a harness: the harness plays PR's
//! supervisor (one AHEAD command), the turbine (DONE to every command PR
//! sends) and the ship (speed cycling below, at and above the goal). The
//! same loop drives the generated controller, the hand-written one and the
//! C port, for the equivalence test and the benchmark.

use crate::set_submarine::submarine as sub;
use crate::{c_port, hand};
use rcs_runtime::{
    CommandBuffer, Controller, CycleContext, GlobalMemory, Operator, Reader, SetupError, Status,
    StatusBuffer, Writer,
};
use std::time::{Duration, Instant};

/// The commanded speed, and the ship speeds the loop cycles through.
pub const GOAL: f64 = 10.0;
pub const SHIP_SPEEDS: [f64; 3] = [9.0, 10.0, 11.0];

/// What one cycle of PR produced: state, status, last RPM sent to TB, and
/// its status fields (RPM ordered, ship speed).
pub type Observation = (u16, u16, f64, (f64, f64));

/// The generated controller's hooks: the same model as `hand`.
#[derive(Debug, Default)]
pub struct Model;

impl sub::pr::Hooks for Model {
    fn required_rpm(&mut self, _data: &sub::pr::Data, speed: f64) -> f64 {
        hand::required_rpm(speed)
    }

    fn speed_error(&mut self, data: &sub::pr::Data) -> sub::types::SpeedError {
        let goal = match data.command {
            sub::pr::Command::Ahead { speed } => speed,
            _ => 0.0,
        };
        let ship = hand::Ship {
            direction: hand::ShipDirection::Ahead,
            speed: data.reads.ship.speed,
        };
        match hand::speed_error(&ship, goal) {
            hand::SpeedError::Below => sub::types::SpeedError::Below,
            hand::SpeedError::At => sub::types::SpeedError::At,
            hand::SpeedError::Above => sub::types::SpeedError::Above,
        }
    }
}

fn context() -> CycleContext {
    CycleContext {
        cycle: 0,
        now: Instant::now(),
        period: Duration::from_millis(30),
    }
}

/// A Rust PR (generated or hand-written) with the world around it.
pub struct RustLoop<
    C,
    P: rcs_runtime::Command,
    T: rcs_runtime::Command,
    S: Copy + Default + Send + 'static,
    F: Copy + Default + Send + 'static,
> {
    pub ctrl: C,
    operator: Operator<P>,
    tb_command: Reader<CommandBuffer<T>>,
    tb_status: Writer<StatusBuffer>,
    ship: Writer<S>,
    make_ship: fn(f64) -> S,
    rpm_of: fn(&T) -> f64,
    pr_status: Reader<StatusBuffer>,
    pr_fields: Reader<F>,
    fields_of: fn(&F) -> (f64, f64),
    ctx: CycleContext,
    turn: usize,
}

impl<
        C: Controller,
        P: rcs_runtime::Command,
        T: rcs_runtime::Command,
        S: Copy + Default + Send + 'static,
        F: Copy + Default + Send + 'static,
    > RustLoop<C, P, T, S, F>
{
    /// One cycle: the world answers, then PR runs, called the way the
    /// runtime's `Executive` calls every controller: through
    /// `&mut dyn Controller`, so the cycle is never inlined into the caller.
    #[inline]
    pub fn step(&mut self) {
        self.world();
        let ctrl: &mut dyn Controller = &mut self.ctrl;
        std::hint::black_box(ctrl).cycle(&self.ctx);
        self.ctx.cycle += 1;
    }

    /// One cycle with PR's `cycle` called directly, so the compiler may
    /// inline it into the caller (the generated controller is generic over
    /// its hooks, so it is compiled in the caller's crate; the hand-written
    /// one is marked `#[inline]` for the same effect). How fast this runs
    /// depends on the caller's loop as much as on the controller; the
    /// benchmark reports it beside [`step`](Self::step).
    #[inline]
    pub fn step_inlined(&mut self) {
        self.world();
        self.ctrl.cycle(&self.ctx);
        self.ctx.cycle += 1;
    }

    /// The turbine answers DONE to the last command; the ship moves on.
    #[inline]
    fn world(&mut self) {
        let sent = self.tb_command.read().value;
        let done = StatusBuffer {
            echo_serial: sent.serial,
            echo_epoch: sent.epoch,
            status: Status::DONE,
            ..StatusBuffer::default()
        };
        self.tb_status.write(done, self.ctx.cycle);
        self.ship
            .write((self.make_ship)(SHIP_SPEEDS[self.turn % 3]), self.ctx.cycle);
        self.turn += 1;
    }

    pub fn observe(&self) -> Observation {
        let s = self.pr_status.read().value;
        (
            s.state,
            s.status.0,
            (self.rpm_of)(&self.tb_command.read().value.command),
            (self.fields_of)(&self.pr_fields.read().value),
        )
    }

    /// The harness around `ctrl` (already connected to `gm`): PR's
    /// supervisor, which sends `first` at once, the turbine and the ship.
    fn new(
        gm: &GlobalMemory,
        ctrl: C,
        make_ship: fn(f64) -> S,
        rpm_of: fn(&T) -> f64,
        fields_of: fn(&F) -> (f64, f64),
        first: P,
    ) -> Result<Self, SetupError> {
        gm.declare_controller::<T>("TB")?;
        let mut l = RustLoop {
            ctrl,
            operator: Operator::connect(gm, "PR")?,
            tb_command: gm.command_reader("TB")?,
            tb_status: gm.status_writer("TB")?,
            ship: gm.writer("ship")?,
            make_ship,
            rpm_of,
            pr_status: gm.status_reader("PR")?,
            pr_fields: gm.reader(&rcs_runtime::status_fields_buffer_name("PR"))?,
            fields_of,
            ctx: context(),
            turn: 0,
        };
        l.operator.command(first);
        Ok(l)
    }
}

pub type GeneratedLoop = RustLoop<
    sub::pr::Controller<Model>,
    sub::pr::Command,
    sub::tb::Command,
    sub::types::Ship,
    sub::pr::StatusFields,
>;
pub type HandLoop =
    RustLoop<hand::Propulsion, hand::PrCommand, hand::TbCommand, hand::Ship, hand::PrStatusFields>;

/// The generated PR, commanded AHEAD(GOAL).
pub fn generated() -> Result<GeneratedLoop, SetupError> {
    let gm = GlobalMemory::new();
    let ctrl = sub::pr::Controller::new(&gm, Model)?;
    RustLoop::new(
        &gm,
        ctrl,
        |speed| sub::types::Ship {
            direction: sub::types::ShipDirection::Ahead,
            speed,
        },
        |c| match c {
            sub::tb::Command::Ahead { rpm } => *rpm,
            _ => 0.0,
        },
        |f| (f.ordered_rpm, f.ship_speed),
        sub::pr::Command::Ahead { speed: GOAL },
    )
}

/// The hand-written PR, commanded AHEAD(GOAL).
pub fn hand_written() -> Result<HandLoop, SetupError> {
    let gm = GlobalMemory::new();
    let ctrl = hand::Propulsion::new(&gm)?;
    RustLoop::new(
        &gm,
        ctrl,
        |speed| hand::Ship {
            direction: hand::ShipDirection::Ahead,
            speed,
        },
        |c| match c {
            hand::TbCommand::Ahead { rpm } => *rpm,
            _ => 0.0,
        },
        |f| (f.ordered_rpm, f.ship_speed),
        hand::PrCommand::Ahead { speed: GOAL },
    )
}

/// The C port with the same world.
pub struct CLoop {
    pub pr: c_port::CPropulsion,
    turn: usize,
}

impl CLoop {
    pub fn new() -> Option<CLoop> {
        let mut pr = c_port::CPropulsion::take()?;
        pr.command_ahead(GOAL);
        Some(CLoop { pr, turn: 0 })
    }

    #[inline]
    pub fn step(&mut self) {
        self.pr.world(SHIP_SPEEDS[self.turn % 3]);
        self.turn += 1;
        self.pr.cycle();
    }

    pub fn observe(&self) -> Observation {
        (
            self.pr.state() as u16,
            self.pr.status() as u16,
            self.pr.rpm(),
            self.pr.status_fields(),
        )
    }
}
