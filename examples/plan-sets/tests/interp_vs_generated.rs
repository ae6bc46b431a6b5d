//! The reference interpreter and the generated Rust run propulsion (PR) of
//! `plans/submarine` identically: for random sequences of supervisor
//! commands, ship states and turbine answers, both give the same fired row,
//! state, status, error, `rpm` var and commands sent, cycle by cycle.

use proptest::prelude::*;
use rcs_dsl::interp::{HookData, Hooks, Interpreter, Value};
use rcs_dsl::ir::{CommandId, HookId, Ir};
use rcs_plan_sets::set_submarine::submarine as sub;
use rcs_runtime::{
    CommandBuffer, Controller, CycleContext, GlobalMemory, Operator, Reader, Status, StatusBuffer,
    Writer,
};
use std::time::{Duration, Instant};

/// One cycle of the world around PR.
#[derive(Clone, Copy, Debug)]
struct Step {
    /// A new command from the supervisor first: 0 none, 1 INIT, 2 HALT, 3 AHEAD.
    command: u8,
    goal: f64,
    ship_speed: f64,
    /// 0 Ahead, 1 Stopped, 2 Backward.
    direction: u8,
    /// The turbine: 0 silent, 1 DONE for the last command, 2 DONE for an older one, 3 ERROR.
    answer: u8,
}

fn step() -> impl Strategy<Value = Step> {
    (
        prop_oneof![6 => Just(0u8), 1 => Just(1), 1 => Just(2), 2 => Just(3)],
        0u8..30,
        0u8..30,
        0u8..3,
        0u8..4,
    )
        .prop_map(|(command, goal, speed, direction, answer)| Step {
            command,
            goal: f64::from(goal),
            ship_speed: f64::from(speed),
            direction,
            answer,
        })
}

fn speed_error(speed: f64, goal: f64) -> u32 {
    if speed < goal - 0.5 {
        0
    } else if speed > goal + 0.5 {
        2
    } else {
        1
    }
}

struct Model;

impl sub::pr::Hooks for Model {
    fn required_rpm(&mut self, _: &sub::pr::Data, speed: f64) -> f64 {
        speed * 10.0
    }
    fn speed_error(&mut self, data: &sub::pr::Data) -> sub::types::SpeedError {
        let goal = match data.command {
            sub::pr::Command::Ahead { speed } => speed,
            _ => 0.0,
        };
        match speed_error(data.reads.ship.speed, goal) {
            0 => sub::types::SpeedError::Below,
            1 => sub::types::SpeedError::At,
            _ => sub::types::SpeedError::Above,
        }
    }
}

impl Hooks for Model {
    fn call(&mut self, data: &HookData, hook: HookId, args: &[Value]) -> Value {
        match data.ctrl.hooks[hook.index()].name.as_str() {
            "required_rpm" => match args {
                [Value::Float(s)] => Value::Float(s * 10.0),
                _ => Value::Unit,
            },
            _ => {
                let goal = match data.params {
                    [Value::Float(g)] => *g,
                    _ => 0.0,
                };
                let speed = match &data.reads[0] {
                    Value::Buffer(fs) => match fs[1] {
                        Value::Float(s) => s,
                        _ => 0.0,
                    },
                    _ => 0.0,
                };
                Value::Enum(speed_error(speed, goal))
            }
        }
    }
}

/// What both sides report after a cycle.
type Trace = (Option<u16>, u16, u16, u16, f64, Vec<String>);

struct Generated {
    pr: sub::pr::Controller<Model>,
    operator: Operator<sub::pr::Command>,
    tb_command: Reader<CommandBuffer<sub::tb::Command>>,
    tb_status: Writer<StatusBuffer>,
    ship: Writer<sub::types::Ship>,
    ctx: CycleContext,
    previous_serial: u32,
}

impl Generated {
    fn new() -> Generated {
        let gm = GlobalMemory::new();
        let pr = sub::pr::Controller::new(&gm, Model).expect("setup");
        gm.declare_controller::<sub::tb::Command>("TB")
            .expect("setup");
        Generated {
            pr,
            operator: Operator::connect(&gm, "PR").expect("setup"),
            tb_command: gm.command_reader("TB").expect("setup"),
            tb_status: gm.status_writer("TB").expect("setup"),
            ship: gm.writer("ship").expect("setup"),
            ctx: CycleContext {
                cycle: 0,
                now: Instant::now(),
                period: Duration::from_millis(30),
            },
            previous_serial: 0,
        }
    }

    fn run(&mut self, s: &Step) -> Trace {
        match s.command {
            1 => drop(self.operator.command(sub::pr::Command::Init)),
            2 => drop(self.operator.command(sub::pr::Command::Halt)),
            3 => drop(
                self.operator
                    .command(sub::pr::Command::Ahead { speed: s.goal }),
            ),
            _ => {}
        }
        let last = self.tb_command.read().value.serial;
        let answer = match s.answer {
            1 => Some((last, Status::DONE)),
            2 => Some((self.previous_serial, Status::DONE)),
            3 => Some((last, Status::ERROR)),
            _ => None,
        };
        if let Some((echo, status)) = answer {
            self.tb_status.write(
                StatusBuffer {
                    echo_serial: echo,
                    status,
                    ..StatusBuffer::default()
                },
                self.ctx.cycle,
            );
        }
        let direction = [
            sub::types::ShipDirection::Ahead,
            sub::types::ShipDirection::Stopped,
            sub::types::ShipDirection::Backward,
        ][s.direction as usize];
        self.ship.write(
            sub::types::Ship {
                direction,
                speed: s.ship_speed,
            },
            self.ctx.cycle,
        );
        let before = self.tb_command.read().value.serial;
        self.pr.cycle(&self.ctx);
        self.ctx.cycle += 1;
        let after = self.tb_command.read().value;
        let mut sent = Vec::new();
        if after.serial != before {
            self.previous_serial = before;
            sent.push(format!("{}:{:?}", after.serial, after.command));
        }
        let bk = self.pr.bookkeeping();
        (
            bk.fired(),
            bk.state(),
            bk.status().0,
            bk.error().0,
            self.pr.data().vars.rpm,
            sent,
        )
    }
}

struct Interpreted<'ir> {
    interp: Interpreter<'ir>,
    ir: &'ir Ir,
    previous_serial: u32,
}

impl Interpreted<'_> {
    fn run(&mut self, s: &Step) -> Trace {
        let verb = |name: &str| {
            let c = self.interp.controller();
            CommandId(
                c.commands
                    .iter()
                    .position(|k| k.name == name)
                    .expect("verb") as u32,
            )
        };
        match s.command {
            1 => drop(self.interp.command(verb("INIT"), vec![])),
            2 => drop(self.interp.command(verb("HALT"), vec![])),
            3 => drop(
                self.interp
                    .command(verb("AHEAD"), vec![Value::Float(s.goal)]),
            ),
            _ => {}
        }
        let last = self.interp.last_sent(0);
        let answer = match s.answer {
            1 => Some((last, Status::DONE)),
            2 => Some((self.previous_serial, Status::DONE)),
            3 => Some((last, Status::ERROR)),
            _ => None,
        };
        if let Some((echo, status)) = answer {
            self.interp.write_sub_status(
                0,
                StatusBuffer {
                    echo_serial: echo,
                    status,
                    ..StatusBuffer::default()
                },
            );
        }
        self.interp.set_read(
            0,
            Value::Buffer(vec![
                Value::Enum(u32::from(s.direction)),
                Value::Float(s.ship_speed),
            ]),
        );
        let rec = self.interp.cycle(&mut Model);
        let tb = self.ir.controller(
            rec.sent
                .first()
                .map(|x| x.sub)
                .unwrap_or(self.interp.controller().subordinates[0]),
        );
        let sent = rec
            .sent
            .iter()
            .map(|x| {
                self.previous_serial = x.serial - 1;
                let name = &tb.commands[x.command.index()].name;
                let cmd = match (name.as_str(), x.args.as_slice()) {
                    ("INIT", _) => sub::tb::Command::Init,
                    ("HALT", _) => sub::tb::Command::Halt,
                    ("STOP", _) => sub::tb::Command::Stop,
                    (_, [Value::Float(rpm)]) => sub::tb::Command::Ahead { rpm: *rpm },
                    _ => sub::tb::Command::Init,
                };
                format!("{}:{:?}", x.serial, cmd)
            })
            .collect();
        let rpm = match self.interp.vars()[0] {
            Value::Float(r) => r,
            _ => f64::NAN,
        };
        (
            rec.fired.map(|r| r.0 as u16),
            rec.state.0 as u16,
            rec.status.0 as u16,
            rec.error.unwrap_or(0),
            rpm,
            sent,
        )
    }
}

fn submarine_ir() -> Ir {
    let sets = rcs_dsl::load_paths(&["../../plans/submarine".into()]).expect("plans");
    rcs_dsl::check(&sets[0], &rcs_dsl::Options::default())
        .ir
        .expect("clean")
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    #[test]
    fn interpreter_and_generated_code_agree_on_pr(steps in proptest::collection::vec(step(), 1..60)) {
        let ir = submarine_ir();
        let pr = ir.controller_by_name("PR").expect("PR");
        let mut interp = Interpreted { interp: Interpreter::new(&ir, pr), ir: &ir, previous_serial: 0 };
        let mut generated = Generated::new();
        for (cycle, s) in steps.iter().enumerate() {
            let g = generated.run(s);
            let i = interp.run(s);
            prop_assert_eq!(&g, &i, "cycle {} after {:?}", cycle, &steps[..=cycle]);
        }
    }
}
