//! The `foxglove.websocket.v1` messages this server speaks (the protocol's
//! spec: github.com/foxglove/ws-protocol, `docs/spec.md`): what it sends —
//! Server Info, Advertise, Status, binary Message Data — and what it reads
//! from a client — Subscribe and Unsubscribe, and every other operation,
//! which it names in order to refuse it ([`ClientOp`]).
//!
//! Kept apart from the sockets so that the wire format is tested without a
//! network, and so that a read-only server is visible in one place: it
//! declares no capability, so a client may publish nothing, call no
//! service, set no parameter and watch no connection graph.

use serde::{Deserialize, Serialize};
use serde_json::json;

/// The WebSocket subprotocol the server selects; a client must offer it.
pub const SUBPROTOCOL: &str = "foxglove.websocket.v1";

/// The binary opcode of Message Data (server to client).
pub const OP_MESSAGE_DATA: u8 = 0x01;

/// Status levels (`status` op).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// Information.
    Info = 0,
    /// A warning.
    Warning = 1,
    /// An error: the client asked for something refused.
    Error = 2,
}

/// One channel as advertised.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct ChannelAd {
    /// The server's id of the channel (from 1).
    pub id: u32,
    /// Its topic (`/rcs/<executive>/<controller>`).
    pub topic: String,
    /// The messages' encoding: `json`.
    pub encoding: &'static str,
    /// The schema's name (`rcs.ControllerCycle`).
    pub schema_name: String,
    /// The JSON Schema, as text.
    pub schema: String,
    /// How the schema is written: `jsonschema`.
    pub schema_encoding: &'static str,
}

/// The Server Info message: no capabilities (read-only), the system's name
/// and a session id (the server's start time), so that a client tells a
/// reconnection from a new server.
pub fn server_info(name: &str, session_id: &str) -> String {
    json!({
        "op": "serverInfo",
        "name": name,
        "capabilities": [],
        "metadata": { "rcs-runtime": env!("CARGO_PKG_VERSION") },
        "sessionId": session_id,
    })
    .to_string()
}

/// The Advertise message for `channels`.
pub fn advertise(channels: &[ChannelAd]) -> String {
    json!({ "op": "advertise", "channels": channels }).to_string()
}

/// A Status message.
pub fn status(level: Level, message: &str) -> String {
    json!({ "op": "status", "level": level as u8, "message": message }).to_string()
}

/// A binary Message Data frame: opcode, subscription id, receive time (ns),
/// payload; integers little-endian.
pub fn message_data(subscription: u32, time_ns: u64, payload: &[u8]) -> Vec<u8> {
    let mut frame = Vec::with_capacity(1 + 4 + 8 + payload.len());
    frame.push(OP_MESSAGE_DATA);
    frame.extend_from_slice(&subscription.to_le_bytes());
    frame.extend_from_slice(&time_ns.to_le_bytes());
    frame.extend_from_slice(payload);
    frame
}

/// One subscription a client asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Subscription {
    /// The client's id for it.
    pub id: u32,
    /// The advertised channel.
    pub channel_id: u32,
}

/// What a client's text message asks, as far as this server cares.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ClientOp {
    /// Start streaming channels.
    Subscribe(Vec<Subscription>),
    /// Stop streaming subscriptions.
    Unsubscribe(Vec<u32>),
    /// An operation of a capability this server does not offer (client
    /// publishing, parameters, services, connection graph, assets), by its
    /// `op` and the capability it needs: refused.
    NotOffered {
        /// The operation (`advertise`, `setParameters`…).
        op: String,
        /// The capability it would need (`clientPublish`…).
        capability: &'static str,
    },
    /// An operation the protocol does not have, or a message that is not
    /// one (its fault, in words).
    Invalid(String),
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct SubscribeMsg {
    subscriptions: Vec<Subscription>,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct UnsubscribeMsg {
    subscription_ids: Vec<u32>,
}

/// The capability a client operation needs, for those this server refuses.
fn capability_of(op: &str) -> Option<&'static str> {
    Some(match op {
        "advertise" | "unadvertise" => "clientPublish",
        "getParameters" | "setParameters" => "parameters",
        "subscribeParameterUpdates" | "unsubscribeParameterUpdates" => "parametersSubscribe",
        "subscribeConnectionGraph" | "unsubscribeConnectionGraph" => "connectionGraph",
        "fetchAsset" => "assets",
        "serviceCallRequest" => "services",
        _ => return None,
    })
}

/// Read a client's text message.
pub fn parse_client_text(text: &str) -> ClientOp {
    let value: serde_json::Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(e) => return ClientOp::Invalid(format!("not a JSON message: {e}")),
    };
    let Some(op) = value.get("op").and_then(|o| o.as_str()) else {
        return ClientOp::Invalid("a JSON message without a string `op`".to_string());
    };
    match op {
        "subscribe" => match serde_json::from_value::<SubscribeMsg>(value.clone()) {
            Ok(m) => ClientOp::Subscribe(m.subscriptions),
            Err(e) => ClientOp::Invalid(format!("a `subscribe` this server cannot read: {e}")),
        },
        "unsubscribe" => match serde_json::from_value::<UnsubscribeMsg>(value.clone()) {
            Ok(m) => ClientOp::Unsubscribe(m.subscription_ids),
            Err(e) => ClientOp::Invalid(format!("an `unsubscribe` this server cannot read: {e}")),
        },
        other => match capability_of(other) {
            Some(capability) => ClientOp::NotOffered {
                op: other.to_string(),
                capability,
            },
            None => ClientOp::Invalid(format!("`{other}` is no operation of {SUBPROTOCOL}")),
        },
    }
}

/// Why a client's binary message is refused: the protocol's client binary
/// opcodes are Client Message Data (publishing) and Service Call Request,
/// neither offered here.
pub fn refuse_binary(data: &[u8]) -> String {
    match data.first() {
        Some(0x01) => {
            "client message data refused: this server is read-only (no `clientPublish` capability)"
                .to_string()
        }
        Some(0x02) => {
            "service call refused: this server is read-only (no `services` capability)".to_string()
        }
        Some(op) => format!("binary opcode {op:#04x} is no client operation of {SUBPROTOCOL}"),
        None => "an empty binary message".to_string(),
    }
}

/// The words of a [`ClientOp::NotOffered`] refusal.
pub fn refuse_op(op: &str, capability: &str) -> String {
    format!("`{op}` refused: this server is read-only (no `{capability}` capability)")
}

/// Whether a `Sec-WebSocket-Protocol` header's value offers [`SUBPROTOCOL`].
pub fn offers_subprotocol(header: &str) -> bool {
    header.split(',').any(|p| p.trim() == SUBPROTOCOL)
}
