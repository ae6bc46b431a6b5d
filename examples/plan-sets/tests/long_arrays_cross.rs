//! Arrays longer than serde's 32 cross processes in generated code: the ok
//! case `0421_placement_long_arrays` run as its two processes (two
//! `System::process` in this test, two bridges on loopback). Buffers
//! (`scan` and `echo`: `[f64; 100]` and `[[u8; 40]; 3]`), a command
//! parameter (`LOOK(rows)`) and a status field (`SENSOR.last`) each carry
//! one; PLANNER reaches Done only once all of them arrived, and the echo
//! that comes back is compared whole. Waits are bounded by a generous
//! deadline; nothing is timed.
#![cfg(feature = "zenoh")]

use std::time::{Duration, Instant};

use rcs_plan_sets::set_0421_placement_long_arrays::_0421_placement_long_arrays::{
    planner, types, Hooks, System,
};
use rcs_runtime::{BridgeConfig, Status};

#[test]
fn a_buffer_a_command_and_status_fields_of_long_arrays_cross() {
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free port")
        .port();
    let ep = format!("tcp/127.0.0.1:{port}");
    let (mut planner_side, planner_bridge) = System::process(
        "planner",
        BridgeConfig::new("long_arrays", "planner")
            .listen(&ep)
            .insecure(),
        Hooks {},
    )
    .expect("the planner process");
    let (mut sensor_side, sensor_bridge) = System::process(
        "sensor",
        BridgeConfig::new("long_arrays", "sensor")
            .connect(&ep)
            .insecure(),
        Hooks {},
    )
    .expect("the sensor process");
    let scan = types::Scan {
        ranges: std::array::from_fn(|i| i as f64 / 10.0),
        rows: std::array::from_fn(|r| std::array::from_fn(|c| (r * 40 + c) as u8)),
    };
    let mut scan_writer = sensor_side
        .inputs
        .scan
        .take()
        .expect("sensor writes `scan`");
    assert!(planner_side.inputs.scan.is_none());
    scan_writer.write(scan, 0);

    // PLANNER waits for the scan, then sends LOOK once; it reaches SENSOR
    // even if the link came up late (the bridge resends every buffer).
    planner_side.operators.planner.command(planner::Command::Go);
    let deadline = Instant::now() + Duration::from_secs(120);
    let outcome = loop {
        planner_side.run_cycles(1).expect("no controller panics");
        sensor_side.run_cycles(1).expect("no controller panics");
        if let Some(outcome) = planner_side.operators.planner.outcome() {
            break outcome;
        }
        assert!(
            Instant::now() < deadline,
            "PLANNER never finished; bridge errors: {:?} / {:?}",
            planner_bridge.errors(),
            sensor_bridge.errors()
        );
        std::thread::sleep(Duration::from_millis(2));
    };
    assert_eq!(outcome.0, Status::DONE);
    let echo = planner_side.outputs.echo.read().value;
    assert_eq!(echo, scan, "the echo came back whole");
    assert!(planner_bridge.errors().is_empty());
    assert!(sensor_bridge.errors().is_empty());
}
