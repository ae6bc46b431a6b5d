//! The configuration of one process's bridge: its names, its Zenoh
//! endpoints and pacing, and the Zenoh configuration built from them.

use std::time::Duration;

use super::BridgeError;

/// How a process joins the others: its names and Zenoh endpoints.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BridgeConfig {
    /// The system (the manifest's `system:`): the second part of every key.
    pub system: String,
    /// This process's name (the manifest's `process:`), for thread names
    /// and messages.
    pub process: String,
    /// Zenoh endpoints to listen on, e.g. `tcp/127.0.0.1:7447`.
    pub listen: Vec<String>,
    /// Zenoh endpoints of other processes to connect to (retried in the
    /// background until they answer).
    pub connect: Vec<String>,
    /// Find peers by UDP multicast scouting as well (off: explicit
    /// endpoints only, which is what tests and most plants want).
    pub multicast_scouting: bool,
    /// The fallback poll: how often the export thread looks for writes
    /// of exported buffers that nobody signalled. Writes followed by a
    /// raise of [`Bridge::signal`](super::Bridge::signal) (every executive
    /// of a generated `System::process` raises it after each cycle) are
    /// published at once, whatever this says. `None`: every 10 ms.
    pub poll_period: Option<Duration>,
    /// How often every exported buffer is published again even if
    /// unchanged, for processes that join late or restart.
    pub resend_period: Duration,
}

impl BridgeConfig {
    /// A configuration for process `process` of system `system`, with no
    /// endpoints, multicast scouting off, the default polling and a 100 ms
    /// resend.
    pub fn new(system: &str, process: &str) -> Self {
        Self {
            system: system.to_owned(),
            process: process.to_owned(),
            listen: Vec::new(),
            connect: Vec::new(),
            multicast_scouting: false,
            poll_period: None,
            resend_period: Duration::from_millis(100),
        }
    }

    /// Add an endpoint to listen on.
    pub fn listen(mut self, endpoint: &str) -> Self {
        self.listen.push(endpoint.to_owned());
        self
    }

    /// Add an endpoint to connect to.
    pub fn connect(mut self, endpoint: &str) -> Self {
        self.connect.push(endpoint.to_owned());
        self
    }

    /// The key expression of buffer `buffer`: `rcs/<system>/<buffer>`.
    pub fn key(&self, buffer: &str) -> String {
        format!("rcs/{}/{}", self.system, buffer)
    }

    /// The Zenoh configuration a bridge opens its session with (public so
    /// that measurements can open plain Zenoh sessions configured alike).
    pub fn zenoh_config(&self) -> Result<zenoh::Config, BridgeError> {
        let list = |v: &[String]| -> Result<String, BridgeError> {
            serde_json::to_string(v).map_err(|e| BridgeError::Zenoh(e.to_string()))
        };
        let mut c = zenoh::Config::default();
        let mut set = |key: &str, value: String| {
            c.insert_json5(key, &value)
                .map_err(|e| BridgeError::Zenoh(format!("config `{key}`: {e}")))
        };
        set("mode", "\"peer\"".into())?;
        set("listen/endpoints", list(&self.listen)?)?;
        set("connect/endpoints", list(&self.connect)?)?;
        set(
            "scouting/multicast/enabled",
            self.multicast_scouting.to_string(),
        )?;
        Ok(c)
    }
}
