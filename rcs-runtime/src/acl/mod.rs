//! Who may talk to a distributed hierarchy: identities and the bridge's
//! security setting.
//!
//! Where it sits: beside the Zenoh bridge ([`crate::bridge`]). rcsc knows
//! from the plan set which process writes every buffer, which process
//! supervises every controller and which processes read what, so it
//! generates each process's Zenoh access-control policy (`rcs-codegen`'s
//! `acl` back end; `System::process` installs it). This module holds the
//! other half, what the running process brings: its identity, a certificate
//! whose common name is the process name, signed by a CA every process
//! trusts ([`TlsFiles`]), or the explicit, loudly logged opt-out
//! ([`Security::Insecure`]). With [`Security::Tls`] every link is mutual TLS
//! and every message is checked against the policy with the peer's
//! certificate name as its subject; default `deny`.
//!
//! [`certs`] (feature `certs`) makes a development CA and certificates.

#[cfg(feature = "certs")]
pub mod certs;

use std::path::{Path, PathBuf};

/// The identity of a process under mutual TLS: PEM files of the CA every
/// process trusts, and of this process's certificate and private key (the
/// certificate's common name is the process name).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TlsFiles {
    /// The CA certificate (`ca.pem`).
    pub ca: PathBuf,
    /// This process's certificate (`NAME.pem`).
    pub cert: PathBuf,
    /// This process's private key (`NAME.key`).
    pub key: PathBuf,
}

impl TlsFiles {
    /// The files `rcsc certs DIR` writes for identity `name`:
    /// `DIR/ca.pem`, `DIR/NAME.pem`, `DIR/NAME.key`.
    pub fn in_dir(dir: &Path, name: &str) -> Self {
        Self {
            ca: dir.join("ca.pem"),
            cert: dir.join(format!("{name}.pem")),
            key: dir.join(format!("{name}.key")),
        }
    }

    /// The first of the three files that cannot be read, if any.
    pub fn missing(&self) -> Option<&Path> {
        [&self.ca, &self.cert, &self.key]
            .into_iter()
            .find(|p| std::fs::metadata(p).is_err())
            .map(PathBuf::as_path)
    }
}

/// How a process's bridge protects the hierarchy.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Security {
    /// Not chosen yet: starting a bridge refuses to run (a plant must not
    /// run open by accident).
    #[default]
    Unset,
    /// Mutual TLS with these files; the access-control policy of the
    /// process applies (default deny).
    Tls(TlsFiles),
    /// No encryption, no authentication, no access control: anyone who can
    /// reach a listener can read every buffer and command every controller.
    /// For a bench on one machine only; the bridge says so on standard
    /// error when it starts and [`Bridge::is_insecure`](crate::Bridge::is_insecure)
    /// tells.
    Insecure,
}
