//! The live server (feature `foxglove`) as Foxglove or Lichtblick meets it:
//! a WebSocket client offering `foxglove.websocket.v1` connects to a
//! running hierarchy (SM → PR → TB on its executive's thread), reads Server
//! Info and the advertised channels — the recording's topics, each with a
//! JSON Schema — subscribes to SM and sees its serials and cycles advance
//! as the operator commands it. And the server is read-only: a client that
//! publishes, sets parameters or calls a service is refused, and one that
//! does not speak the subprotocol is turned away at the handshake.
//!
//! No timing is asserted: every wait is bounded by a generous deadline.
#![cfg(feature = "foxglove")]

mod common;
mod foxglove_client;

use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use common::{Relay, GO, HOLD};
use foxglove_client::{connect, next_data, next_json, Client, DEADLINE};
use rcs_runtime::foxglove::{
    ControllerNames, FoxgloveError, FoxgloveOptions, FoxgloveServer, LiveSystem,
};
use rcs_runtime::{
    Executive, ExecutiveConfig, ExecutiveHandle, ExecutiveMonitor, GlobalMemory, Operator, VerbId,
};
use serde_json::{json, Value};
use tungstenite::Message;

/// SM → PR → TB on executive `main` (TB finishes GO after 3 cycles), its
/// monitor attached, and the operator of SM.
fn hierarchy() -> (
    GlobalMemory,
    Executive,
    Arc<ExecutiveMonitor>,
    Operator<VerbId>,
) {
    let gm = GlobalMemory::new();
    let mut e = Executive::new(ExecutiveConfig::new("main", Duration::from_millis(5))).unwrap();
    e.add(Box::new(Relay::new(&gm, "SM", Some("PR"), 0).unwrap()))
        .unwrap();
    e.add(Box::new(Relay::new(&gm, "PR", Some("TB"), 0).unwrap()))
        .unwrap();
    e.add(Box::new(Relay::new(&gm, "TB", None, 3).unwrap()))
        .unwrap();
    let monitor = e.attach_monitor(3);
    let op = Operator::connect(&gm, "SM").unwrap();
    (gm, e, monitor, op)
}

fn relay_names() -> ControllerNames {
    ControllerNames {
        verbs: vec!["GO".into(), "HOLD".into()],
        states: vec![vec!["S0".into(), "S1".into()]; 2],
        rows: vec![
            vec!["E0".into(), "E1".into(), "E2".into()],
            vec!["E0".into()],
        ],
        statuses: Vec::new(),
    }
}

/// Serve `e`'s hierarchy on a free loopback port, then spawn `e`.
fn serve(
    gm: &GlobalMemory,
    e: Executive,
    monitor: Arc<ExecutiveMonitor>,
) -> (FoxgloveServer, ExecutiveHandle, JoinHandle<Executive>) {
    let system = LiveSystem::new("relay test")
        .executive(e.handle(), monitor, gm)
        .names("SM", relay_names());
    let options = FoxgloveOptions {
        addr: "127.0.0.1:0".parse().unwrap(),
        ..FoxgloveOptions::default()
    };
    let server = FoxgloveServer::start(system, &options).unwrap();
    assert!(server.warning().is_none());
    let (handle, join) = e.spawn().unwrap();
    (server, handle, join)
}

/// Server Info then Advertise, checked; the advertised channels.
fn handshake_messages(ws: &mut Client) -> Vec<Value> {
    let info = next_json(ws);
    assert_eq!(info["op"], "serverInfo", "{info}");
    assert_eq!(info["name"], "relay test");
    assert_eq!(info["capabilities"], json!([]), "read-only: no capability");
    let ad = next_json(ws);
    assert_eq!(ad["op"], "advertise", "{ad}");
    ad["channels"].as_array().unwrap().clone()
}

fn channel_id(channels: &[Value], topic: &str) -> u64 {
    channels
        .iter()
        .find(|c| c["topic"] == topic)
        .and_then(|c| c["id"].as_u64())
        .unwrap_or_else(|| panic!("no channel {topic}"))
}

#[test]
fn a_client_subscribes_to_a_controller_and_sees_its_serials_and_cycles_advance() {
    let (gm, e, monitor, mut op) = hierarchy();
    let (server, handle, join) = serve(&gm, e, monitor);
    assert!(server.url().starts_with("ws://127.0.0.1:"));

    let (mut ws, response) = connect(server.local_addr(), "foxglove.websocket.v1").unwrap();
    assert_eq!(
        response.headers()["Sec-WebSocket-Protocol"],
        "foxglove.websocket.v1"
    );
    let channels = handshake_messages(&mut ws);
    let topics: Vec<&str> = channels
        .iter()
        .map(|c| c["topic"].as_str().unwrap())
        .collect();
    assert_eq!(
        topics,
        [
            "/rcs/main/SM",
            "/rcs/main/PR",
            "/rcs/main/TB",
            "/rcs/main/gm/SM.status",
            "/rcs/main/gm/PR.status",
            "/rcs/main/gm/TB.status",
        ]
    );
    for c in &channels {
        assert_eq!(c["encoding"], "json", "{c}");
        assert_eq!(c["schemaEncoding"], "jsonschema", "{c}");
        let schema: Value = serde_json::from_str(c["schema"].as_str().unwrap())
            .unwrap_or_else(|e| panic!("the schema of {} is not JSON: {e}", c["topic"]));
        assert_eq!(schema["type"], "object");
        let controller = !c["topic"].as_str().unwrap().contains("/gm/");
        let expected: &[&str] = if controller {
            assert_eq!(c["schemaName"], "rcs.ControllerCycle");
            &[
                "executive",
                "cycle",
                "time_ns",
                "controller",
                "verb",
                "verb_name",
                "state",
                "state_name",
                "status",
                "status_name",
                "error",
                "fired",
                "new_command",
                "serial",
                "cycle_ns",
            ]
        } else {
            assert_eq!(c["schemaName"], "rcs.buffer.StatusBuffer");
            &["executive", "buffer", "writer", "cycle", "time_ns", "value"]
        };
        for field in expected {
            assert!(
                schema["properties"].get(field).is_some(),
                "{}: no `{field}` in its schema",
                c["topic"]
            );
        }
    }

    let sm = channel_id(&channels, "/rcs/main/SM");
    ws.send(Message::text(
        json!({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": sm}]}).to_string(),
    ))
    .unwrap();

    // Command SM twice; each serial must show on SM's channel, with the
    // cycle count rising from message to message.
    let mut last_cycle = None;
    let mut last_serial = None;
    let mut serials_seen = Vec::new();
    for _ in 0..2 {
        let serial = op.command(GO);
        let start = Instant::now();
        loop {
            assert!(
                start.elapsed() < DEADLINE,
                "serial {serial} never showed on SM's channel"
            );
            let (sub, m) = next_data(&mut ws);
            assert_eq!(sub, 7);
            assert_eq!(m["executive"], "main");
            assert_eq!(m["controller"], "SM");
            let cycle = m["cycle"].as_u64().unwrap();
            if let Some(last) = last_cycle {
                assert!(cycle > last, "cycle {cycle} after {last}: {m}");
            }
            last_cycle = Some(cycle);
            // New exactly when the serial changed since the last message.
            let serial_now = m["serial"].as_u64();
            assert_eq!(
                m["new_command"],
                last_serial.is_some() && serial_now != last_serial,
                "{m}"
            );
            last_serial = serial_now;
            if m["serial"].as_u64() == Some(u64::from(serial)) {
                assert_eq!(m["verb"], u64::from(GO));
                assert_eq!(m["verb_name"], "GO", "{m}");
                assert!(m["status_name"].is_string(), "{m}");
                serials_seen.push((serial, cycle));
                break;
            }
        }
    }
    assert!(serials_seen[1].0 > serials_seen[0].0, "{serials_seen:?}");
    assert!(serials_seen[1].1 > serials_seen[0].1, "{serials_seen:?}");

    // A status buffer's channel carries the buffer's value.
    let pr_status = channel_id(&channels, "/rcs/main/gm/PR.status");
    ws.send(Message::text(
        json!({"op": "subscribe", "subscriptions": [{"id": 8, "channelId": pr_status}]})
            .to_string(),
    ))
    .unwrap();
    ws.send(Message::text(
        json!({"op": "unsubscribe", "subscriptionIds": [7]}).to_string(),
    ))
    .unwrap();
    op.command(HOLD);
    let start = Instant::now();
    loop {
        assert!(start.elapsed() < DEADLINE, "PR's status never showed HOLD");
        let (sub, m) = next_data(&mut ws);
        if sub == 7 {
            continue; // sent before the unsubscribe arrived
        }
        assert_eq!(sub, 8);
        assert_eq!(
            (&m["buffer"], &m["writer"]),
            (&json!("PR.status"), &json!("PR"))
        );
        if m["value"]["verb"] == u64::from(HOLD) {
            break;
        }
    }

    server.stop();
    handle.stop();
    join.join().unwrap();
}

#[test]
fn the_server_is_read_only_and_refuses_what_it_does_not_offer() {
    let (gm, e, monitor, _op) = hierarchy();
    let (server, handle, join) = serve(&gm, e, monitor);
    let addr = server.local_addr();

    // Without the subprotocol: turned away at the handshake.
    match connect(addr, "some.other.protocol") {
        Err(tungstenite::Error::Http(response)) => assert_eq!(response.status(), 400),
        Err(e) => panic!("refused, but not as expected: {e}"),
        Ok(_) => panic!("a client without foxglove.websocket.v1 was accepted"),
    }

    let (mut ws, _) = connect(addr, "foxglove.websocket.v1").unwrap();
    let channels = handshake_messages(&mut ws);
    let attempts = [
        (
            Message::text(
                json!({"op": "advertise", "channels": [{"id": 1, "topic": "/rcs/main/SM", "encoding": "json", "schemaName": "x"}]})
                    .to_string(),
            ),
            "clientPublish",
        ),
        (
            Message::binary(vec![0x01, 1, 0, 0, 0, b'{', b'}']),
            "clientPublish",
        ),
        (
            Message::text(
                json!({"op": "setParameters", "parameters": [{"name": "/SM/speed", "value": 3}], "id": "p1"})
                    .to_string(),
            ),
            "parameters",
        ),
        (
            Message::text(json!({"op": "getParameters", "parameterNames": [], "id": "p2"}).to_string()),
            "parameters",
        ),
        (
            Message::binary(vec![0x02, 1, 0, 0, 0, 9, 0, 0, 0, 4, 0, 0, 0, b'j', b's', b'o', b'n']),
            "services",
        ),
        (
            Message::text(json!({"op": "subscribeConnectionGraph"}).to_string()),
            "connectionGraph",
        ),
    ];
    for (attempt, capability) in attempts {
        ws.send(attempt).unwrap();
        let status = next_json(&mut ws);
        assert_eq!(status["op"], "status", "{status}");
        assert_eq!(status["level"], 2, "{status}");
        let message = status["message"].as_str().unwrap();
        assert!(
            message.contains("read-only") && message.contains(capability),
            "{message}"
        );
    }
    // Malformed requests and bad subscriptions get an error status too.
    ws.send(Message::text("{not json")).unwrap();
    assert_eq!(next_json(&mut ws)["level"], 2);
    ws.send(Message::text(
        json!({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": 999}]}).to_string(),
    ))
    .unwrap();
    let status = next_json(&mut ws);
    assert!(
        status["message"]
            .as_str()
            .unwrap()
            .contains("no channel 999"),
        "{status}"
    );

    // Nothing changed: a new client sees the same channels, and this one
    // is still served.
    let (mut other, _) = connect(addr, "foxglove.websocket.v1").unwrap();
    assert_eq!(handshake_messages(&mut other), channels);
    let tb = channel_id(&channels, "/rcs/main/TB");
    ws.send(Message::text(
        json!({"op": "subscribe", "subscriptions": [{"id": 3, "channelId": tb}]}).to_string(),
    ))
    .unwrap();
    let (sub, m) = next_data(&mut ws);
    assert_eq!((sub, &m["controller"]), (3, &json!("TB")));

    server.stop();
    handle.stop();
    join.join().unwrap();
}

#[test]
fn a_non_loopback_address_is_refused_without_the_opt_in() {
    let (gm, e, monitor, _op) = hierarchy();
    let system = LiveSystem::new("x").executive(e.handle(), monitor, &gm);
    let options = FoxgloveOptions {
        // Refused before any socket is opened.
        addr: "0.0.0.0:0".parse().unwrap(),
        ..FoxgloveOptions::default()
    };
    match FoxgloveServer::start(system, &options) {
        Err(FoxgloveError::NotLoopback(_)) => {}
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn clients_beyond_the_limit_are_turned_away_until_one_leaves() {
    let (gm, e, monitor, _op) = hierarchy();
    let (server, handle, join) = serve(&gm, e, monitor);
    let addr = server.local_addr();
    let mut clients: Vec<Client> = (0..rcs_runtime::foxglove::MAX_CLIENTS)
        .map(|_| {
            let (mut ws, _) = connect(addr, "foxglove.websocket.v1").unwrap();
            handshake_messages(&mut ws);
            ws
        })
        .collect();
    assert!(
        connect(addr, "foxglove.websocket.v1").is_err(),
        "a client beyond the limit was served"
    );
    // One leaves: within the deadline, a new client is served again.
    let mut leaving = clients.pop().unwrap();
    leaving.close(None).unwrap();
    drop(leaving);
    let start = Instant::now();
    let mut ws = loop {
        if let Ok((ws, _)) = connect(addr, "foxglove.websocket.v1") {
            break ws;
        }
        assert!(
            start.elapsed() < DEADLINE,
            "no room again after a client left"
        );
        std::thread::sleep(Duration::from_millis(50));
    };
    handshake_messages(&mut ws);

    server.stop();
    handle.stop();
    join.join().unwrap();
}

#[test]
fn a_sampling_rate_out_of_range_is_refused() {
    let (gm, e, monitor, _op) = hierarchy();
    for rate_hz in [0, rcs_runtime::foxglove::MAX_RATE_HZ + 1] {
        let system = LiveSystem::new("x").executive(e.handle(), Arc::clone(&monitor), &gm);
        let options = FoxgloveOptions {
            addr: "127.0.0.1:0".parse().unwrap(),
            rate_hz,
            ..FoxgloveOptions::default()
        };
        assert!(matches!(
            FoxgloveServer::start(system, &options),
            Err(FoxgloveError::BadRate(r)) if r == rate_hz
        ));
    }
}
