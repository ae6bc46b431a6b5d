//! Live in Foxglove and Lichtblick (feature `foxglove`): a server of the
//! Foxglove WebSocket protocol (`foxglove.websocket.v1`) for a running
//! system, serving the channels of an MCAP recording — one per controller,
//! `/rcs/<executive>/<controller>` with the schema `rcs.ControllerCycle`,
//! and one per Global Memory buffer, `/rcs/<executive>/gm/<buffer>` —
//! so that the tools a robotics engineer already has show the hierarchy
//! live (docs/console.md, "Live in Foxglove / Lichtblick").
//!
//! **The control cycle pays nothing.** The server never touches an
//! executive: each client's thread samples, at the server's rate, what the
//! executives already publish for other threads — the monitor's atomics
//! ([`Executive::attach_monitor`](crate::Executive::attach_monitor)), the
//! handle's cycle count, Global Memory's seqlocked buffers. No lock the
//! executive takes, no allocation or hand-off on its path, and a slow or
//! stuck client slows only its own thread. A sample's figures may come from
//! two neighbouring cycles, as the console's do.
//!
//! **Security.** The protocol has no authentication and no encryption:
//! anyone who reaches the port sees the whole system. So the server binds
//! loopback unless the program opts in explicitly
//! ([`FoxgloveOptions::allow_remote`]), and then it warns on stderr
//! ([`FoxgloveServer::warning`]). It is read-only: it declares no
//! capability, and a client that publishes, calls a service, gets or sets
//! parameters, asks for the connection graph or an asset is answered with
//! an error status and nothing else happens. At most [`MAX_CLIENTS`]
//! clients at a time.
//!
//! Why a small server on `tungstenite` rather than the Foxglove SDK
//! (`foxglove` crate): the SDK's server runs on a tokio runtime and brings
//! prost, parking_lot, tracing, flume and more — a large tree for a feature
//! that sends JSON on a handful of channels — and its API has changed from
//! release to release; the subset a read-only JSON server needs is a few
//! hundred lines, tested here against the spec.

mod channels;
pub mod protocol;
mod session;
#[cfg(test)]
mod tests;

use std::io;
use std::net::{IpAddr, Ipv4Addr, SocketAddr, TcpListener};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

pub use channels::{ControllerNames, LiveSystem};

/// The port Foxglove and Lichtblick suggest for a WebSocket connection.
pub const DEFAULT_PORT: u16 = 8765;
/// Samples per second by default: smooth in a plot, light on the machine.
pub const DEFAULT_RATE_HZ: u32 = 50;
/// The highest sampling rate accepted.
pub const MAX_RATE_HZ: u32 = 1_000;
/// Clients served at once; more are turned away at accept.
pub const MAX_CLIENTS: usize = 16;

/// Where and how the server listens.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FoxgloveOptions {
    /// The address to listen on (default `127.0.0.1:8765`; port 0: any).
    pub addr: SocketAddr,
    /// Allow an address other than loopback (the protocol has no
    /// authentication: see the module docs). Off by default.
    pub allow_remote: bool,
    /// Samples per second, 1 to [`MAX_RATE_HZ`].
    pub rate_hz: u32,
}

impl Default for FoxgloveOptions {
    fn default() -> Self {
        Self {
            addr: SocketAddr::new(IpAddr::V4(Ipv4Addr::LOCALHOST), DEFAULT_PORT),
            allow_remote: false,
            rate_hz: DEFAULT_RATE_HZ,
        }
    }
}

/// Why the server does not start.
#[derive(Debug, thiserror::Error)]
pub enum FoxgloveError {
    /// Not an address: `HOST:PORT` with a numeric host, or a port.
    #[error(
        "`{0}` is not an address to listen on: give IP:PORT (127.0.0.1:8765, [::1]:8765) or a port"
    )]
    BadAddress(String),
    /// A non-loopback address without the opt-in.
    #[error("refusing to listen on {0}: it is not a loopback address, and the Foxglove WebSocket protocol has no authentication (anyone who reaches the port sees the whole system); listen on 127.0.0.1, or opt in explicitly to serve the network")]
    NotLoopback(SocketAddr),
    /// A rate out of range.
    #[error("a sampling rate of {0} Hz is out of range (1 to {MAX_RATE_HZ})")]
    BadRate(u32),
    /// The socket could not be opened.
    #[error("cannot listen on {addr}: {source}")]
    Listen {
        /// The address.
        addr: SocketAddr,
        /// Why.
        source: io::Error,
    },
}

/// Read an address to listen on: `IP:PORT`, or a port alone (loopback).
/// No host names: resolving one could pick an address nobody meant.
pub fn parse_addr(text: &str) -> Result<SocketAddr, FoxgloveError> {
    let text = text.trim();
    if let Ok(port) = text.parse::<u16>() {
        return Ok(SocketAddr::new(IpAddr::V4(Ipv4Addr::LOCALHOST), port));
    }
    text.parse()
        .map_err(|_| FoxgloveError::BadAddress(text.to_string()))
}

/// Whether the server may listen on `addr`: `Ok(None)` for loopback,
/// `Ok(Some(warning))` for another address with `allow_remote`, else
/// [`FoxgloveError::NotLoopback`].
pub fn check_bind(addr: SocketAddr, allow_remote: bool) -> Result<Option<String>, FoxgloveError> {
    if addr.ip().is_loopback() {
        return Ok(None);
    }
    if !allow_remote {
        return Err(FoxgloveError::NotLoopback(addr));
    }
    Ok(Some(format!(
        "warning: the Foxglove server listens on {addr}, beyond this machine: the protocol has no authentication and no encryption, so anyone who reaches that port sees every controller of the system (read-only); prefer 127.0.0.1 and an SSH tunnel"
    )))
}

/// A running live server; stops when dropped or [`FoxgloveServer::stop`]ped.
#[derive(Debug)]
pub struct FoxgloveServer {
    addr: SocketAddr,
    warning: Option<String>,
    stop: Arc<AtomicBool>,
    acceptor: Option<JoinHandle<()>>,
}

impl FoxgloveServer {
    /// Listen on `options.addr` and serve `system` from threads of the
    /// server's own. A non-loopback address without `allow_remote` is
    /// refused; with it, the warning goes to stderr (and
    /// [`FoxgloveServer::warning`]).
    pub fn start(system: LiveSystem, options: &FoxgloveOptions) -> Result<Self, FoxgloveError> {
        if !(1..=MAX_RATE_HZ).contains(&options.rate_hz) {
            return Err(FoxgloveError::BadRate(options.rate_hz));
        }
        let warning = check_bind(options.addr, options.allow_remote)?;
        let listen = |source| FoxgloveError::Listen {
            addr: options.addr,
            source,
        };
        let listener = TcpListener::bind(options.addr).map_err(listen)?;
        let addr = listener.local_addr().map_err(listen)?;
        listener.set_nonblocking(true).map_err(listen)?;
        if let Some(w) = &warning {
            eprintln!("{w}");
        }
        let stop = Arc::new(AtomicBool::new(false));
        let session_id = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos().to_string())
            .unwrap_or_default();
        let server_info = protocol::server_info(system.name(), &session_id);
        let channels = system.into_channels();
        let shared = Arc::new(session::Shared {
            advertise: protocol::advertise(&channels.ads),
            channels,
            server_info,
            period: Duration::from_secs(1) / options.rate_hz,
            stop: Arc::clone(&stop),
        });
        let acceptor = std::thread::Builder::new()
            .name("rcs-foxglove".to_string())
            .spawn(move || accept_loop(&listener, &shared))
            .map_err(listen)?;
        Ok(Self {
            addr,
            warning,
            stop,
            acceptor: Some(acceptor),
        })
    }

    /// The address it listens on (the port chosen when 0 was asked).
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// The URL to open in Foxglove or Lichtblick: `ws://127.0.0.1:8765`.
    pub fn url(&self) -> String {
        format!("ws://{}", self.addr)
    }

    /// The warning given for a non-loopback address, if it is one.
    pub fn warning(&self) -> Option<&str> {
        self.warning.as_deref()
    }

    /// Stop serving: close every client and wait for the server's threads.
    pub fn stop(mut self) {
        self.shutdown();
    }

    fn shutdown(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(acceptor) = self.acceptor.take() {
            let _ = acceptor.join();
        }
    }
}

impl Drop for FoxgloveServer {
    fn drop(&mut self) {
        self.shutdown();
    }
}

/// How often the acceptor looks for a connection or a stop.
const ACCEPT_POLL: Duration = Duration::from_millis(20);

/// Accept clients until stopped, each on a thread; then wait for them.
fn accept_loop(listener: &TcpListener, shared: &Arc<session::Shared>) {
    let active = Arc::new(AtomicUsize::new(0));
    let mut sessions: Vec<JoinHandle<()>> = Vec::new();
    while !shared.stop.load(Ordering::Relaxed) {
        sessions.retain(|s| !s.is_finished());
        match listener.accept() {
            Ok((stream, _peer)) => {
                if active.load(Ordering::Relaxed) >= MAX_CLIENTS {
                    // Turned away: closing the socket is the answer.
                    drop(stream);
                    continue;
                }
                active.fetch_add(1, Ordering::Relaxed);
                let (shared, active2) = (Arc::clone(shared), Arc::clone(&active));
                let spawned = std::thread::Builder::new()
                    .name("rcs-foxglove-client".to_string())
                    .spawn(move || {
                        session::serve(stream, &shared);
                        active2.fetch_sub(1, Ordering::Relaxed);
                    });
                match spawned {
                    Ok(s) => sessions.push(s),
                    Err(_) => {
                        active.fetch_sub(1, Ordering::Relaxed);
                    }
                }
            }
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => std::thread::sleep(ACCEPT_POLL),
            // A connection that failed before it was accepted, or the
            // process out of descriptors: wait, then go on.
            Err(_) => std::thread::sleep(ACCEPT_POLL),
        }
    }
    for s in sessions {
        let _ = s.join();
    }
}
