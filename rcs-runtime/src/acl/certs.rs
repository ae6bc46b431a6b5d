//! A development certificate authority and one certificate per process
//! (feature `certs`): what `rcsc certs DIR` writes and what the tests use.
//!
//! Where it sits: beside the bridge's [`Security`](super::Security), which
//! reads the files this writes. Each process's certificate carries the
//! process name as its common name (CN): Zenoh's access control identifies a
//! peer by that CN, so the generated policy ("process `engine` may put
//! `TB.status`") holds for whoever presents a certificate with `CN=engine`
//! signed by the CA. The CA's private key therefore *is* the authority over
//! the hierarchy: keep it off the plant network (docs/distribution.md says
//! how to use a real CA instead).
//!
//! Layout of the folder (PEM files):
//!
//! | file | what |
//! |---|---|
//! | `ca.pem` | the CA certificate every process trusts |
//! | `ca.key` | the CA's private key (only `rcsc certs` needs it) |
//! | `NAME.pem`, `NAME.key` | process `NAME`'s certificate and private key |
//!
//! An existing `ca.pem`/`ca.key` is reused, so that certificates for a new
//! process join an existing hierarchy; an existing process certificate is
//! replaced.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use rcgen::{
    BasicConstraints, CertificateParams, DistinguishedName, DnType, ExtendedKeyUsagePurpose, IsCa,
    Issuer, KeyPair, KeyUsagePurpose,
};

/// The CA's common name: the same for every development CA, so that a CA
/// read back from its key signs with the same issuer name.
const CA_COMMON_NAME: &str = "rcs development CA";

/// Why certificates could not be made.
#[derive(Debug, thiserror::Error)]
pub enum CertError {
    /// A process name that cannot be a certificate's common name here.
    #[error("`{0}` is not a process name (letters, digits and `_`, not starting with a digit)")]
    BadName(String),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: io::Error,
    },
    /// rcgen refused to make a key or certificate.
    #[error("certificate: {0}")]
    Rcgen(#[from] rcgen::Error),
}

/// What [`make_dev_certs`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DevCerts {
    /// Whether `ca.pem`/`ca.key` were made now (false: reused).
    pub new_ca: bool,
    /// The files written, in order.
    pub written: Vec<PathBuf>,
}

/// Make (or reuse) the development CA in `dir` and a certificate for each
/// of `names` (process names, and `operator` for the operator's identity),
/// valid for the host names and addresses in `hosts` besides `localhost`,
/// `127.0.0.1` and `::1`.
pub fn make_dev_certs(dir: &Path, names: &[&str], hosts: &[&str]) -> Result<DevCerts, CertError> {
    for n in names {
        if !is_identifier(n) {
            return Err(CertError::BadName((*n).to_owned()));
        }
    }
    fs::create_dir_all(dir).map_err(|source| CertError::Io {
        path: dir.to_owned(),
        source,
    })?;
    let mut written = Vec::new();
    let (ca_key, new_ca) = match read(&dir.join("ca.key")) {
        Ok(pem) if dir.join("ca.pem").exists() => (KeyPair::from_pem(&pem)?, false),
        _ => {
            let key = KeyPair::generate()?;
            let cert = ca_params().self_signed(&key)?;
            write(&dir.join("ca.pem"), &cert.pem(), &mut written)?;
            write_secret(&dir.join("ca.key"), &key.serialize_pem(), &mut written)?;
            (key, true)
        }
    };
    let issuer = Issuer::new(ca_params(), ca_key);
    let mut sans: Vec<String> = vec!["localhost".into(), "127.0.0.1".into(), "::1".into()];
    sans.extend(hosts.iter().map(|h| (*h).to_owned()));
    for name in names {
        let key = KeyPair::generate()?;
        let mut params = CertificateParams::new(sans.clone())?;
        params.distinguished_name = DistinguishedName::new();
        params.distinguished_name.push(DnType::CommonName, *name);
        params.key_usages = vec![
            KeyUsagePurpose::DigitalSignature,
            KeyUsagePurpose::KeyEncipherment,
        ];
        params.extended_key_usages = vec![
            ExtendedKeyUsagePurpose::ServerAuth,
            ExtendedKeyUsagePurpose::ClientAuth,
        ];
        let cert = params.signed_by(&key, &issuer)?;
        write(&dir.join(format!("{name}.pem")), &cert.pem(), &mut written)?;
        write_secret(
            &dir.join(format!("{name}.key")),
            &key.serialize_pem(),
            &mut written,
        )?;
    }
    Ok(DevCerts { new_ca, written })
}

fn ca_params() -> CertificateParams {
    let mut p = CertificateParams::default();
    p.distinguished_name = DistinguishedName::new();
    p.distinguished_name
        .push(DnType::CommonName, CA_COMMON_NAME);
    p.is_ca = IsCa::Ca(BasicConstraints::Constrained(0));
    p.key_usages = vec![
        KeyUsagePurpose::KeyCertSign,
        KeyUsagePurpose::CrlSign,
        KeyUsagePurpose::DigitalSignature,
    ];
    p
}

fn is_identifier(n: &str) -> bool {
    n.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

fn read(path: &Path) -> Result<String, CertError> {
    fs::read_to_string(path).map_err(|source| CertError::Io {
        path: path.to_owned(),
        source,
    })
}

fn write(path: &Path, text: &str, written: &mut Vec<PathBuf>) -> Result<(), CertError> {
    fs::write(path, text).map_err(|source| CertError::Io {
        path: path.to_owned(),
        source,
    })?;
    written.push(path.to_owned());
    Ok(())
}

/// A private key: readable by its owner only where the OS has modes.
fn write_secret(path: &Path, text: &str, written: &mut Vec<PathBuf>) -> Result<(), CertError> {
    write(path, text, written)?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        fs::set_permissions(path, fs::Permissions::from_mode(0o600)).map_err(|source| {
            CertError::Io {
                path: path.to_owned(),
                source,
            }
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn makes_a_ca_and_reuses_it_for_a_new_process() {
        let dir = std::env::temp_dir().join(format!("rcs-certs-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        let first = make_dev_certs(&dir, &["helm", "engine"], &["10.1.2.3"]).unwrap();
        assert!(first.new_ca);
        assert_eq!(first.written.len(), 6);
        let ca = fs::read_to_string(dir.join("ca.pem")).unwrap();
        assert!(ca.starts_with("-----BEGIN CERTIFICATE-----"));
        let again = make_dev_certs(&dir, &["operator"], &[]).unwrap();
        assert!(!again.new_ca);
        assert_eq!(fs::read_to_string(dir.join("ca.pem")).unwrap(), ca);
        assert!(dir.join("operator.key").exists());
        assert!(matches!(
            make_dev_certs(&dir, &["../evil"], &[]),
            Err(CertError::BadName(_))
        ));
        fs::remove_dir_all(&dir).unwrap();
    }
}
