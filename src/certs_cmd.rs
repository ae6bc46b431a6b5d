//! `rcsc certs DIR [PATHS…]`: a development certificate authority and one
//! certificate per process of the plan sets (and one for the operator), for
//! the mutual TLS the generated access-control policies rely on. Thin over
//! `rcs_runtime::acl::certs`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use crate::args::Common;
use crate::commands::check_sets;
use crate::output::{default_paths, fail};

pub(crate) const CERTS_HELP: &str = "\
Writes DIR/ca.pem and DIR/ca.key (a development CA, reused if present) and,
for each process of the plan sets' manifests (`process:`) and for the
operator, DIR/NAME.pem and DIR/NAME.key: a certificate whose common name is
the name, which is the identity the generated access-control policy
checks. Keys are written readable by their owner only.

For production, use your own CA instead (docs/distribution.md, \"Using
your own CA\"): any certificate signed by it with CN = the process name.

Examples:
  rcsc certs target/certs examples/submarine-split/plans
  rcsc certs target/certs --name helm --name engine --host 10.0.0.7";

#[derive(Args)]
pub(crate) struct CertsArgs {
    /// Where to write the certificates.
    pub(crate) dir: PathBuf,
    /// Plan-set folders whose processes get certificates [default: none
    /// when --name is given, else .]
    pub(crate) paths: Vec<PathBuf>,
    /// A further identity to certify (repeatable).
    #[arg(long = "name", value_name = "NAME")]
    pub(crate) names: Vec<String>,
    /// A host name or address to put in the certificates besides localhost
    /// (repeatable; only checked by peers that verify names).
    #[arg(long = "host", value_name = "HOST")]
    pub(crate) hosts: Vec<String>,
    #[command(flatten)]
    pub(crate) common: Common,
}

pub(crate) fn certs(args: CertsArgs) -> ExitCode {
    let mut names: Vec<String> = Vec::new();
    if !args.paths.is_empty() || args.names.is_empty() {
        let sets = match rcs_dsl::load_paths(&default_paths(args.paths)) {
            Ok(sets) => sets,
            Err(e) => return fail(e),
        };
        let irs = match check_sets(&sets, &args.common, false, None, None) {
            Ok(irs) => irs,
            Err(code) => return code,
        };
        for ir in &irs {
            let placement = rcs_dsl::placement::Placement::of(ir);
            names.extend(placement.processes);
        }
    }
    names.extend(args.names);
    names.push(rcs_codegen::acl::OPERATOR.to_owned());
    names.sort();
    names.dedup();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let hosts: Vec<&str> = args.hosts.iter().map(String::as_str).collect();
    match rcs_runtime::acl::certs::make_dev_certs(&args.dir, &names, &hosts) {
        Ok(made) => {
            // Process names come from the manifests, the folder from the
            // user: no control character of theirs reaches the terminal.
            let shown = rcs_dsl::render::escape_controls;
            let dir = rcs_dsl::load::display(&args.dir);
            let dir = shown(&dir);
            if made.new_ca {
                outln!("made a development CA in {dir} (keep ca.key off the plant network)");
            } else {
                outln!("reused the CA in {dir}");
            }
            outln!("certificates for: {}", shown(&names.join(", ")));
            ExitCode::SUCCESS
        }
        Err(e) => fail(e),
    }
}
