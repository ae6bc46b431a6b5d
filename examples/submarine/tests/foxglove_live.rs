//! `--foxglove` as a person would use it: the submarine runs on its 30 ms
//! heartbeat with the live server on a free loopback port; a WebSocket
//! client speaking `foxglove.websocket.v1` (what Foxglove and Lichtblick
//! open) finds every controller and buffer channel, named from the plan
//! set, and watches PR reach AT_GOAL while the ship's speed rises.
//!
//! No timing is asserted: every wait is bounded by a generous deadline.

use std::io::{BufRead, BufReader};
use std::net::SocketAddr;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Instant;

use serde_json::{json, Value};
use tungstenite::Message;

#[path = "../../../rcs-runtime/tests/foxglove_client/mod.rs"]
mod foxglove_client;

use foxglove_client::{connect, data, next, next_json, DEADLINE};

/// The submarine process, killed when the test ends however it ends.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn foxglove_shows_the_submarine_live() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_submarine"))
        .args([
            "--foxglove",
            "127.0.0.1:0",
            "--hold",
            "100000",
            "--every",
            "1000",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run the submarine example");
    let stderr = child.stderr.take().unwrap();
    let _running = Running(child);
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let url = loop {
        let line = rx
            .recv_timeout(DEADLINE)
            .expect("the submarine printed no ws:// address");
        if let Some(at) = line.find("ws://") {
            break line[at..].split_whitespace().next().unwrap().to_string();
        }
    };
    let addr: SocketAddr = url
        .trim_start_matches("ws://")
        .parse()
        .expect("the printed address");
    let (mut ws, _) = connect(addr, "foxglove.websocket.v1").expect("the handshake");

    let info = next_json(&mut ws);
    assert_eq!(info["op"], "serverInfo");
    assert_eq!(info["capabilities"], json!([]));
    let ad = next_json(&mut ws);
    let channels = ad["channels"].as_array().unwrap();
    let topics: Vec<&str> = channels
        .iter()
        .map(|c| c["topic"].as_str().unwrap())
        .collect();
    let id_of = |suffix: &str| {
        channels
            .iter()
            .find(|c| c["topic"].as_str().unwrap().ends_with(suffix))
            .and_then(|c| c["id"].as_u64())
            .unwrap_or_else(|| panic!("no channel …{suffix} in {topics:?}"))
    };
    for suffix in [
        "/SM",
        "/PR",
        "/TB",
        "/gm/SM.status",
        "/gm/PR.status",
        "/gm/TB.status",
        "/gm/ship",
        "/gm/turbine",
        "/gm/drive",
    ] {
        id_of(suffix);
    }
    let (pr, ship) = (id_of("/PR"), id_of("/gm/ship"));
    ws.send(Message::text(
        json!({"op": "subscribe", "subscriptions": [
            {"id": 1, "channelId": pr},
            {"id": 2, "channelId": ship},
        ]})
        .to_string(),
    ))
    .unwrap();

    let start = Instant::now();
    let (mut at_goal, mut max_speed) = (false, 0.0f64);
    while !(at_goal && max_speed > 1.0) {
        assert!(
            start.elapsed() < DEADLINE,
            "PR never reported AT_GOAL with the ship under way (fastest: {max_speed} kn)"
        );
        let Message::Binary(b) = next(&mut ws) else {
            continue;
        };
        let (sub, m): (u32, Value) = data(&b);
        match sub {
            1 => {
                assert_eq!(m["controller"], "PR");
                if m["status_name"] == "AT_GOAL" {
                    assert_eq!(m["verb_name"], "AHEAD", "{m}");
                    assert!(m["state_name"].is_string(), "{m}");
                    at_goal = true;
                }
            }
            2 => {
                assert_eq!(
                    (&m["buffer"], &m["writer"]),
                    (&json!("ship"), &json!("plant"))
                );
                max_speed = max_speed.max(m["value"]["speed"].as_f64().unwrap());
            }
            other => panic!("a message for subscription {other}"),
        }
    }
}
