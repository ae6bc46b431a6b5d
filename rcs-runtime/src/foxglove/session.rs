//! One client of the live server, on a thread of its own: the WebSocket
//! handshake (the client must offer `foxglove.websocket.v1`), Server Info
//! and Advertise, then a loop that reads the client's requests and, at the
//! server's rate, samples each subscribed channel and sends what is new.
//!
//! Everything a client can make the server hold is bounded: its messages
//! (64 KiB), its subscriptions (one per channel), the time it may take to
//! finish the handshake or to take a write (a client that stops reading is
//! dropped, it never makes anything wait but its own thread).

use std::collections::BTreeMap;
use std::io;
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use tungstenite::handshake::server::{ErrorResponse, Request, Response};
use tungstenite::http::{HeaderValue, StatusCode};
use tungstenite::protocol::WebSocketConfig;
use tungstenite::{Message, WebSocket};

use super::channels::{Channels, Sent};
use super::protocol::{self, ClientOp, Level};

/// The largest message or frame a client may send: its requests are small
/// JSON; anything larger is a fault, refused before it is buffered.
const MAX_CLIENT_MESSAGE: usize = 64 << 10;
/// How long a client has to finish the handshake, and to take one write.
const IO_TIMEOUT: Duration = Duration::from_secs(10);

/// What every client's thread shares.
pub(super) struct Shared {
    pub(super) channels: Channels,
    pub(super) server_info: String,
    pub(super) advertise: String,
    /// Time between two samples.
    pub(super) period: Duration,
    pub(super) stop: Arc<AtomicBool>,
}

/// Nanoseconds since the Unix epoch, now: the messages' time.
fn now_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX))
        .unwrap_or(0)
}

/// Select the subprotocol, or refuse a client that does not offer it.
// The callback's signature is tungstenite's: its error is a whole response.
#[allow(clippy::result_large_err)]
fn select_subprotocol(
    request: &Request,
    mut response: Response,
) -> Result<Response, ErrorResponse> {
    let offered = request
        .headers()
        .get_all("Sec-WebSocket-Protocol")
        .iter()
        .filter_map(|v| v.to_str().ok())
        .any(protocol::offers_subprotocol);
    if !offered {
        let mut refusal = ErrorResponse::new(Some(format!(
            "this server speaks the WebSocket subprotocol {} only\n",
            protocol::SUBPROTOCOL
        )));
        *refusal.status_mut() = StatusCode::BAD_REQUEST;
        return Err(refusal);
    }
    response.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        HeaderValue::from_static(protocol::SUBPROTOCOL),
    );
    Ok(response)
}

/// Serve one client until it leaves, fails, or the server stops. Errors
/// end the session quietly: a client's fault never reaches the system.
pub(super) fn serve(stream: TcpStream, shared: &Shared) {
    if stream.set_nonblocking(false).is_err()
        || stream.set_read_timeout(Some(IO_TIMEOUT)).is_err()
        || stream.set_write_timeout(Some(IO_TIMEOUT)).is_err()
    {
        return;
    }
    let _ = stream.set_nodelay(true);
    let config = WebSocketConfig::default()
        .max_message_size(Some(MAX_CLIENT_MESSAGE))
        .max_frame_size(Some(MAX_CLIENT_MESSAGE));
    let Ok(mut ws) = tungstenite::accept_hdr_with_config(stream, select_subprotocol, Some(config))
    else {
        return;
    };
    let _ = run(&mut ws, shared);
    let _ = ws.close(None);
    let _ = ws.flush();
}

/// A client's subscriptions: its id → (channel id, what it was sent).
type Subscriptions = BTreeMap<u32, (u32, Sent)>;

fn run(ws: &mut WebSocket<TcpStream>, shared: &Shared) -> tungstenite::Result<()> {
    ws.send(Message::text(shared.server_info.as_str()))?;
    ws.send(Message::text(shared.advertise.as_str()))?;
    let mut subs = Subscriptions::new();
    let mut next = Instant::now();
    while !shared.stop.load(Ordering::Relaxed) {
        let now = Instant::now();
        if now >= next {
            publish(ws, shared, &mut subs)?;
            // On the rate's grid, but never catching up on missed samples.
            next = (next + shared.period).max(now);
        }
        // Wait for the client until the next sample is due.
        let wait = next
            .saturating_duration_since(Instant::now())
            .max(Duration::from_millis(1));
        ws.get_ref()
            .set_read_timeout(Some(wait))
            .map_err(tungstenite::Error::Io)?;
        match ws.read() {
            Ok(Message::Text(text)) => handle_text(ws, shared, &mut subs, text.as_str())?,
            Ok(Message::Binary(data)) => {
                ws.send(Message::text(protocol::status(
                    Level::Error,
                    &protocol::refuse_binary(&data),
                )))?;
            }
            Ok(Message::Close(_)) => return Ok(()),
            // Pings are answered by tungstenite itself on the next write.
            Ok(Message::Ping(_) | Message::Pong(_) | Message::Frame(_)) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
                ) => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// Send each subscription's new message, if any.
fn publish(
    ws: &mut WebSocket<TcpStream>,
    shared: &Shared,
    subs: &mut Subscriptions,
) -> tungstenite::Result<()> {
    if subs.is_empty() {
        return Ok(());
    }
    // Writes go as one batch: a client that stops reading meets the write
    // timeout here and is dropped.
    ws.get_ref()
        .set_write_timeout(Some(IO_TIMEOUT))
        .map_err(tungstenite::Error::Io)?;
    let time_ns = now_ns();
    let mut any = false;
    for (&sub, (channel, sent)) in subs.iter_mut() {
        if let Some(payload) = shared.channels.sample(*channel, time_ns, sent) {
            ws.write(Message::binary(protocol::message_data(
                sub, time_ns, &payload,
            )))?;
            any = true;
        }
    }
    if any {
        ws.flush()?;
    }
    Ok(())
}

/// Answer one text request.
fn handle_text(
    ws: &mut WebSocket<TcpStream>,
    shared: &Shared,
    subs: &mut Subscriptions,
    text: &str,
) -> tungstenite::Result<()> {
    let mut refusals = Vec::new();
    match protocol::parse_client_text(text) {
        ClientOp::Subscribe(list) => {
            for s in list {
                if !shared.channels.has(s.channel_id) {
                    refusals.push(format!(
                        "subscription {}: no channel {} was advertised",
                        s.id, s.channel_id
                    ));
                } else if subs.contains_key(&s.id) {
                    refusals.push(format!("subscription {}: the id is in use", s.id));
                } else if subs.values().any(|(c, _)| *c == s.channel_id) {
                    refusals.push(format!(
                        "subscription {}: channel {} is subscribed already",
                        s.id, s.channel_id
                    ));
                } else {
                    subs.insert(s.id, (s.channel_id, Sent::default()));
                }
            }
        }
        ClientOp::Unsubscribe(ids) => {
            for id in ids {
                subs.remove(&id);
            }
        }
        ClientOp::NotOffered { op, capability } => {
            refusals.push(protocol::refuse_op(&op, capability));
        }
        ClientOp::Invalid(why) => refusals.push(why),
    }
    for r in refusals {
        ws.send(Message::text(protocol::status(Level::Error, &r)))?;
    }
    Ok(())
}
