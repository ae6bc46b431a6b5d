//! `--console`: the submarine under the operator's console (issue 31).
//!
//! Here the hierarchy runs as a deployed system would: each executive on a
//! thread of its own, on its heartbeat, with the ship and turbine simulator
//! as the last controller of the cycle (it reads TB's `drive` and writes the
//! `ship` and `turbine` inputs, as the table mode does between cycles). The
//! console runs in the foreground on the terminal, watching through the
//! executives' monitors and commanding SM through the operator; nothing is
//! commanded until the operator does it (`c`).

use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;

use rcs_console::{ArgValue, Catalog, InProcess};
use rcs_runtime::{Controller, CycleContext, Executive, ExecutiveHandle, ExecutiveMonitor};

use crate::submarine::types::TurbineDrive;
use crate::submarine::{sm, Hooks, System};
use crate::{Plant, Propulsion, DEAD_BAND_KN, MODEL_RPM_PER_KNOT};

/// The plan set the program was generated from (build.rs), for the
/// console's names and plan tables.
pub const PLANS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../plans/submarine");

/// The ship and turbine as a controller: steps the plant under TB's drive
/// output at the end of each cycle and writes what the sensors read next.
struct Simulator {
    plant: Plant,
    drive: rcs_runtime::Reader<TurbineDrive>,
    ship: rcs_runtime::Writer<crate::submarine::types::Ship>,
    turbine: rcs_runtime::Writer<crate::submarine::types::TurbineSensors>,
}

impl Controller for Simulator {
    fn name(&self) -> &str {
        "plant"
    }

    fn cycle(&mut self, ctx: &CycleContext) {
        let drive = self.drive.read().value;
        self.plant.step(drive, ctx.period.as_secs_f64());
        self.ship.write(self.plant.ship(), ctx.cycle + 1);
        self.turbine.write(self.plant.turbine(), ctx.cycle + 1);
    }
}

/// Run the submarine on its executives' threads and the console in the
/// foreground until the operator quits.
pub fn run(foxglove: Option<&crate::foxglove::FoxgloveArgs>) -> ExitCode {
    match try_run(foxglove) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("submarine: {e}");
            ExitCode::from(2)
        }
    }
}

fn try_run(foxglove: Option<&crate::foxglove::FoxgloveArgs>) -> Result<(), String> {
    let catalog = Catalog::load(Path::new(PLANS))?;
    let hooks = Propulsion {
        rpm_per_knot: MODEL_RPM_PER_KNOT,
        dead_band: DEAD_BAND_KN,
    };
    let system = System::new(Hooks { pr: hooks }).map_err(|e| format!("setup failed: {e}"))?;
    let System {
        gm,
        mut executives,
        mut inputs,
        outputs,
        operators,
        ..
    } = system;
    let plant = Plant::default();
    inputs.ship.write(plant.ship(), 0);
    inputs.turbine.write(plant.turbine(), 0);
    let simulator = Simulator {
        plant,
        drive: outputs.drive,
        ship: inputs.ship,
        turbine: inputs.turbine,
    };
    executives
        .first_mut()
        .ok_or("the plan set has no CPU")?
        .add(Box::new(simulator))
        .map_err(|e| e.to_string())?;

    let rows = catalog.max_rows();
    let monitors: Vec<Arc<ExecutiveMonitor>> = executives
        .iter_mut()
        .map(|e| e.attach_monitor(rows))
        .collect();
    let mut running: Vec<(ExecutiveHandle, std::thread::JoinHandle<Executive>)> = Vec::new();
    for exec in executives {
        running.push(
            exec.spawn()
                .map_err(|e| format!("cannot start an executive: {e}"))?,
        );
    }
    let live: Vec<_> = running
        .iter()
        .map(|(h, _)| h.clone())
        .zip(monitors.iter().cloned())
        .collect();
    // Served while the console runs (dropped when it returns).
    let _live = match foxglove {
        Some(args) => Some(crate::foxglove::start(args, &catalog, &gm, &live)?),
        None => None,
    };
    let mut sm_operator = operators.sm;
    let commander = Box::new(move |root: &str, verb: &str, args: &[ArgValue]| {
        let command = match (root, verb, args) {
            ("SM", "INIT", []) => sm::Command::Init,
            ("SM", "TRANSIT", [ArgValue::Float(speed)]) => sm::Command::Transit { speed: *speed },
            _ => {
                return Err(format!(
                    "{root} <- {verb}{args:?} is not a command of this program"
                ))
            }
        };
        Ok(sm_operator.command(command))
    });
    let mut source = InProcess::new(
        &gm,
        running
            .iter()
            .map(|(h, _)| h.clone())
            .zip(monitors)
            .collect(),
        commander,
    );
    let shown = rcs_console::run(catalog, &mut source);
    for (handle, _) in &running {
        handle.go();
        handle.stop();
    }
    for (_, join) in running {
        if join.join().is_err() {
            eprintln!("submarine: an executive thread panicked");
        }
    }
    shown.map_err(|e| format!("the console failed: {e}"))
}
