//! A minimal `foxglove.websocket.v1` client for the tests of the live
//! server: this crate's (`foxglove_live.rs`) and the submarine example's
//! (`#[path]`-included there). It connects offering a subprotocol, reads
//! with a bounded wait, and decodes Message Data frames. Every wait is
//! bounded by [`DEADLINE`]; no timing is asserted.

#![allow(dead_code)] // each including test uses part of it

use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

use serde_json::Value;
use tungstenite::client::IntoClientRequest;
use tungstenite::http::HeaderValue;
use tungstenite::{Message, WebSocket};

/// Generous: the machine may be loaded by other builds.
pub const DEADLINE: Duration = Duration::from_secs(180);

pub type Client = WebSocket<TcpStream>;

/// Connect to `addr` offering `subprotocol` (the server's answer, or its
/// refusal, is the caller's to check).
pub fn connect(
    addr: SocketAddr,
    subprotocol: &'static str,
) -> Result<(Client, tungstenite::handshake::client::Response), tungstenite::Error> {
    let stream = TcpStream::connect(addr).expect("the server accepts a connection");
    stream
        .set_read_timeout(Some(Duration::from_millis(200)))
        .expect("a read timeout");
    let mut request = format!("ws://{addr}")
        .into_client_request()
        .expect("a request");
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        HeaderValue::from_static(subprotocol),
    );
    // The read timeout interrupts a slow handshake: go on until the
    // deadline.
    let start = Instant::now();
    let mut attempt = tungstenite::client(request, stream);
    loop {
        match attempt {
            Ok(done) => return Ok(done),
            Err(tungstenite::HandshakeError::Failure(e)) => return Err(e),
            Err(tungstenite::HandshakeError::Interrupted(mid)) => {
                assert!(
                    start.elapsed() < DEADLINE,
                    "the handshake did not finish within {DEADLINE:?}"
                );
                attempt = mid.handshake();
            }
        }
    }
}

/// The next message, waiting up to [`DEADLINE`].
pub fn next(ws: &mut Client) -> Message {
    let start = Instant::now();
    loop {
        match ws.read() {
            Ok(m) => return m,
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                assert!(start.elapsed() < DEADLINE, "no message within {DEADLINE:?}");
            }
            Err(e) => panic!("the connection failed: {e}"),
        }
    }
}

/// The next text message, as JSON (binary ones in between are skipped).
pub fn next_json(ws: &mut Client) -> Value {
    loop {
        if let Message::Text(t) = next(ws) {
            return serde_json::from_str(t.as_str()).expect("JSON");
        }
    }
}

/// A Message Data frame: subscription id and payload as JSON (checked:
/// the opcode, and the frame's time equal to the payload's `time_ns`).
pub fn data(frame: &[u8]) -> (u32, Value) {
    assert_eq!(frame[0], 0x01, "Message Data's opcode");
    assert!(frame.len() > 13, "a frame without payload");
    let sub = u32::from_le_bytes(frame[1..5].try_into().expect("4 bytes"));
    let time_ns = u64::from_le_bytes(frame[5..13].try_into().expect("8 bytes"));
    let payload: Value = serde_json::from_slice(&frame[13..]).expect("JSON payload");
    assert_eq!(payload["time_ns"].as_u64(), Some(time_ns), "{payload}");
    (sub, payload)
}

/// The next Message Data frame (no text message may come in between).
pub fn next_data(ws: &mut Client) -> (u32, Value) {
    loop {
        match next(ws) {
            Message::Binary(b) => return data(&b),
            Message::Text(t) => panic!("unexpected text message: {t}"),
            _ => {}
        }
    }
}
