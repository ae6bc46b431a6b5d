//! The live server's wire format and listening policy, without a network:
//! client requests read or refused by name, Message Data framed as the
//! spec says, loopback by default and anything else only by opt-in.

use std::net::SocketAddr;

use super::protocol::{self, ClientOp, Subscription};
use super::{check_bind, parse_addr, FoxgloveError};

#[test]
fn subscribe_and_unsubscribe_are_read() {
    let op = protocol::parse_client_text(
        r#"{"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":7,"channelId":5}]}"#,
    );
    assert_eq!(
        op,
        ClientOp::Subscribe(vec![
            Subscription {
                id: 0,
                channel_id: 3
            },
            Subscription {
                id: 7,
                channel_id: 5
            },
        ])
    );
    let op = protocol::parse_client_text(r#"{"op":"unsubscribe","subscriptionIds":[0,7]}"#);
    assert_eq!(op, ClientOp::Unsubscribe(vec![0, 7]));
}

#[test]
fn every_operation_of_a_capability_not_offered_is_refused_by_name() {
    for (op, capability) in [
        ("advertise", "clientPublish"),
        ("unadvertise", "clientPublish"),
        ("getParameters", "parameters"),
        ("setParameters", "parameters"),
        ("subscribeParameterUpdates", "parametersSubscribe"),
        ("subscribeConnectionGraph", "connectionGraph"),
        ("fetchAsset", "assets"),
    ] {
        let text = format!(r#"{{"op":"{op}","channels":[],"parameters":[]}}"#);
        assert_eq!(
            protocol::parse_client_text(&text),
            ClientOp::NotOffered {
                op: op.to_string(),
                capability
            }
        );
    }
    assert!(protocol::refuse_op("setParameters", "parameters").contains("read-only"));
    assert!(protocol::refuse_binary(&[0x01, 0, 0, 0, 0]).contains("clientPublish"));
    assert!(protocol::refuse_binary(&[0x02]).contains("services"));
    assert!(protocol::refuse_binary(&[]).contains("empty"));
}

#[test]
fn malformed_requests_are_named_not_panicked_on() {
    for text in [
        "",
        "not json",
        "[1,2]",
        r#"{"op":3}"#,
        r#"{"op":"subscribe"}"#,
        r#"{"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]}"#,
        r#"{"op":"unsubscribe","subscriptionIds":"all"}"#,
        r#"{"op":"launchMissiles"}"#,
    ] {
        assert!(
            matches!(protocol::parse_client_text(text), ClientOp::Invalid(_)),
            "{text}"
        );
    }
}

#[test]
fn message_data_is_framed_little_endian() {
    let frame = protocol::message_data(0x0102_0304, 0x1122_3344_5566_7788, b"{}");
    assert_eq!(frame[0], protocol::OP_MESSAGE_DATA);
    assert_eq!(&frame[1..5], &[4, 3, 2, 1]);
    assert_eq!(
        &frame[5..13],
        &[0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11]
    );
    assert_eq!(&frame[13..], b"{}");
}

#[test]
fn server_info_declares_no_capability() {
    let info: serde_json::Value = serde_json::from_str(&protocol::server_info("sub", "1")).unwrap();
    assert_eq!(info["op"], "serverInfo");
    assert_eq!(info["capabilities"], serde_json::json!([]));
    assert!(info.get("supportedEncodings").is_none());
}

#[test]
fn the_subprotocol_is_found_in_a_list() {
    assert!(protocol::offers_subprotocol("foxglove.websocket.v1"));
    assert!(protocol::offers_subprotocol(
        "foxglove.sdk.v1, foxglove.websocket.v1"
    ));
    assert!(!protocol::offers_subprotocol("foxglove.websocket.v2"));
    assert!(!protocol::offers_subprotocol(""));
}

#[test]
fn loopback_is_served_and_anything_else_only_by_opt_in() {
    let addr = |s: &str| s.parse::<SocketAddr>().unwrap();
    assert!(matches!(
        check_bind(addr("127.0.0.1:8765"), false),
        Ok(None)
    ));
    assert!(matches!(check_bind(addr("[::1]:8765"), false), Ok(None)));
    for remote in ["0.0.0.0:8765", "[::]:8765", "192.168.1.5:8765"] {
        assert!(
            matches!(
                check_bind(addr(remote), false),
                Err(FoxgloveError::NotLoopback(_))
            ),
            "{remote}"
        );
        let warning = check_bind(addr(remote), true).unwrap().unwrap();
        assert!(warning.contains("no authentication"), "{warning}");
    }
    let refusal = check_bind(addr("0.0.0.0:1"), false)
        .unwrap_err()
        .to_string();
    assert!(refusal.contains("no authentication"), "{refusal}");
}

#[test]
fn addresses_are_read_without_resolving_names() {
    assert_eq!(parse_addr("9000").unwrap(), addr_of("127.0.0.1:9000"));
    assert_eq!(parse_addr(" [::1]:8765 ").unwrap(), addr_of("[::1]:8765"));
    for bad in [
        "localhost:8765",
        "",
        "127.0.0.1",
        "70000",
        "ws://127.0.0.1:8765",
    ] {
        assert!(
            matches!(parse_addr(bad), Err(FoxgloveError::BadAddress(_))),
            "{bad}"
        );
    }
}

fn addr_of(s: &str) -> SocketAddr {
    s.parse().unwrap()
}
