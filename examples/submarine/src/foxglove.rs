//! `--foxglove [ADDR]`: the submarine served live to Foxglove and
//! Lichtblick over the Foxglove WebSocket protocol (rcs-runtime's feature
//! `foxglove`; docs/console.md, "Live in Foxglove / Lichtblick").
//!
//! The same channels as a recording: one per controller (SM, PR, TB, and
//! the plant simulator under `--console`, where it runs as the cycle's last
//! controller) named from the plan set, the controllers' status
//! buffers, and the `ship`, `turbine` and `drive` buffers with their
//! values. The server samples what the executive publishes for other
//! threads (its monitor, Global Memory): the control cycle pays nothing.

use std::net::SocketAddr;
use std::sync::Arc;

use rcs_console::Catalog;
use rcs_runtime::foxglove::{
    parse_addr, ControllerNames, FoxgloveOptions, FoxgloveServer, LiveSystem,
};
use rcs_runtime::{ExecutiveHandle, ExecutiveMonitor, GlobalMemory};
use serde_json::json;

use crate::submarine::types::{Ship, TurbineDrive, TurbineSensors};

/// Where `--foxglove` listens, and whether beyond loopback.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FoxgloveArgs {
    /// The address (default `127.0.0.1:8765`).
    pub addr: SocketAddr,
    /// `--foxglove-allow-remote`: the explicit opt-in for a non-loopback
    /// address (the protocol has no authentication).
    pub allow_remote: bool,
}

impl FoxgloveArgs {
    /// `--foxglove` with `addr` (`None`: the default address).
    pub fn parse(addr: Option<&str>) -> Result<Self, String> {
        let addr = match addr {
            Some(a) => parse_addr(a).map_err(|e| format!("--foxglove: {e}"))?,
            None => FoxgloveOptions::default().addr,
        };
        Ok(Self {
            addr,
            allow_remote: false,
        })
    }
}

/// The names of every controller's ids, from the plan set.
fn names(catalog: &Catalog) -> Vec<(String, ControllerNames)> {
    catalog
        .controllers
        .iter()
        .map(|c| {
            let plan = |v: &rcs_console::catalog::Verb| v.plan.clone().unwrap_or_default();
            let names = ControllerNames {
                verbs: c.verbs.iter().map(|v| v.name.clone()).collect(),
                states: c.verbs.iter().map(|v| plan(v).states).collect(),
                rows: c
                    .verbs
                    .iter()
                    .map(|v| plan(v).rows.into_iter().map(|r| r.label).collect())
                    .collect(),
                statuses: c.statuses.clone(),
            };
            (c.name.clone(), names)
        })
        .collect()
}

/// Start serving the executives `running` (handles and monitors) and the
/// plant's buffers in `gm`; the URL goes to stderr. The server stops when
/// the returned value is dropped.
pub fn start(
    args: &FoxgloveArgs,
    catalog: &Catalog,
    gm: &GlobalMemory,
    running: &[(ExecutiveHandle, Arc<ExecutiveMonitor>)],
) -> Result<FoxgloveServer, String> {
    let mut system = LiveSystem::new(format!("{} (rcs)", catalog.system));
    for (handle, monitor) in running {
        system = system.executive(handle.clone(), Arc::clone(monitor), gm);
    }
    for (controller, n) in names(catalog) {
        system = system.names(controller, n);
    }
    let exec = running
        .first()
        .map(|(_, m)| m.name().to_string())
        .ok_or("the plan set has no CPU")?;
    let reader = |name: &str| format!("--foxglove: no buffer `{name}` in Global Memory");
    let number = json!({ "type": "number" });
    system = system
        .buffer(
            &exec,
            "plant",
            gm.reader::<Ship>("ship").map_err(|_| reader("ship"))?,
            "Ship",
            json!({
                "type": "object",
                "properties": {
                    "direction": { "enum": ["Ahead", "Stopped", "Backward"] },
                    "speed": { "type": "number", "description": "knots" },
                },
            }),
        )
        .buffer(
            &exec,
            "plant",
            gm.reader::<TurbineSensors>("turbine")
                .map_err(|_| reader("turbine"))?,
            "TurbineSensors",
            json!({ "type": "object", "properties": { "rpm": number } }),
        )
        .buffer(
            &exec,
            "TB",
            gm.reader::<TurbineDrive>("drive")
                .map_err(|_| reader("drive"))?,
            "TurbineDrive",
            json!({
                "type": "object",
                "properties": { "engaged": { "type": "boolean" }, "rpm_setpoint": number },
            }),
        );
    let options = FoxgloveOptions {
        addr: args.addr,
        allow_remote: args.allow_remote,
        ..FoxgloveOptions::default()
    };
    let server = FoxgloveServer::start(system, &options).map_err(|e| format!("--foxglove: {e}"))?;
    eprintln!(
        "submarine: live in Foxglove / Lichtblick at {} (open a Foxglove WebSocket connection)",
        server.url()
    );
    Ok(server)
}
