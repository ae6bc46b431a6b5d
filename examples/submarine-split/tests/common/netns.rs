//! Network namespaces for the fault tests: made per test (names carry the
//! test's pid and tag), joined by veth pairs whose addresses (10.213.x.y)
//! exist only inside them, and deleted when the [`Netns`] guard drops, also
//! on panic. Nothing here touches the machine's own network namespace: the
//! veth ends are created directly in the test's namespaces.
//!
//! Needs root and iproute2 (`ip`, `tc`); [`Netns::make`] tells when
//! namespaces cannot be made so that the test can skip with a message.

use std::process::Command;

/// The namespaces of one test; deletes them when dropped.
pub struct Netns {
    /// `(role, namespace name)`.
    names: Vec<(String, String)>,
}

/// Run `ip ARGS…`; the error says what failed.
fn run(program: &str, args: &[&str]) -> Result<(), String> {
    let out = Command::new(program)
        .args(args)
        .output()
        .map_err(|e| format!("`{program}` cannot run: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "`{program} {}` failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}

impl Netns {
    /// One namespace per role, named `rcs-PID-TAG-ROLE`, each with its
    /// loopback up. `Err` (with the reason) when namespaces cannot be made
    /// here: not root, no `ip`, EPERM in a container.
    pub fn make(tag: &str, roles: &[&str]) -> Result<Netns, String> {
        let mut ns = Netns { names: Vec::new() };
        for role in roles {
            let name = format!("rcs-{}-{tag}-{role}", std::process::id());
            // A namespace left by a killed earlier run of this pid: remove.
            let _ = run("ip", &["netns", "del", &name]);
            run("ip", &["netns", "add", &name])?;
            ns.names.push(((*role).to_owned(), name.clone()));
            run("ip", &["-n", &name, "link", "set", "lo", "up"])?;
        }
        Ok(ns)
    }

    /// The namespace of `role`.
    pub fn name(&self, role: &str) -> &str {
        self.names
            .iter()
            .find(|(r, _)| r == role)
            .map(|(_, n)| n.as_str())
            .unwrap_or_else(|| panic!("no namespace for role {role}"))
    }

    /// Join `a` and `b` with a veth pair, up, `a_if` in `a` with address
    /// `a_addr` (CIDR) and `b_if` in `b` with `b_addr`.
    pub fn veth(
        &self,
        (a, a_if, a_addr): (&str, &str, &str),
        (b, b_if, b_addr): (&str, &str, &str),
    ) {
        let (na, nb) = (self.name(a), self.name(b));
        let ip = |args: &[&str]| run("ip", args).unwrap_or_else(|e| panic!("veth {a}–{b}: {e}"));
        ip(&[
            "link", "add", a_if, "netns", na, "type", "veth", "peer", "name", b_if, "netns", nb,
        ]);
        for (ns, ifc, addr) in [(na, a_if, a_addr), (nb, b_if, b_addr)] {
            ip(&["-n", ns, "addr", "add", addr, "dev", ifc]);
            ip(&["-n", ns, "link", "set", ifc, "up"]);
        }
    }

    /// `ip netns exec NS PROGRAM ARGS…` as the arguments of `ip`.
    pub fn exec_args(&self, role: &str, program: &str, args: &[String]) -> Vec<String> {
        ["netns", "exec", self.name(role), program]
            .iter()
            .map(|s| (*s).to_owned())
            .chain(args.iter().cloned())
            .collect()
    }

    /// Set interface `ifc` of `role` up or down (a partition).
    pub fn link(&self, role: &str, ifc: &str, up: bool) {
        let state = if up { "up" } else { "down" };
        run("ip", &["-n", self.name(role), "link", "set", ifc, state])
            .unwrap_or_else(|e| panic!("{e}"));
    }

    /// `tc ARGS…` inside `role`'s namespace; `Err` if tc refuses.
    pub fn tc(&self, role: &str, args: &[&str]) -> Result<(), String> {
        let mut all = vec!["netns", "exec", self.name(role), "tc"];
        all.extend_from_slice(args);
        run("ip", &all)
    }

    /// `(received, sent)` bytes of interface `ifc` of `role` so far.
    pub fn bytes(&self, role: &str, ifc: &str) -> (u64, u64) {
        let read = |what: &str| -> u64 {
            let path = format!("/sys/class/net/{ifc}/statistics/{what}");
            let out = Command::new("ip")
                .args(["netns", "exec", self.name(role), "cat", &path])
                .output()
                .expect("run ip netns exec cat");
            String::from_utf8_lossy(&out.stdout)
                .trim()
                .parse()
                .unwrap_or_else(|_| panic!("no {path} in {role}'s namespace"))
        };
        (read("rx_bytes"), read("tx_bytes"))
    }

    /// Whether this kernel has the `netem` qdisc (tried on `role`'s
    /// loopback, then removed).
    pub fn has_netem(&self, role: &str) -> bool {
        let ok = self
            .tc(
                role,
                &["qdisc", "add", "dev", "lo", "root", "netem", "delay", "1ms"],
            )
            .is_ok();
        if ok {
            let _ = self.tc(role, &["qdisc", "del", "dev", "lo", "root"]);
        }
        ok
    }
}

impl Drop for Netns {
    fn drop(&mut self) {
        for (_, name) in &self.names {
            if let Err(e) = run("ip", &["netns", "del", name]) {
                eprintln!("netns cleanup: {e}");
            }
        }
    }
}

/// The namespaces for test `test`, or `None` after printing why the test
/// is skipped (the test then returns and passes).
pub fn namespaces_or_skip(test: &str, tag: &str, roles: &[&str]) -> Option<Netns> {
    match Netns::make(tag, roles) {
        Ok(ns) => Some(ns),
        Err(e) => {
            println!(
                "SKIPPED {test}: cannot make network namespaces here ({e}); \
                 the fault tests need root and iproute2 (`ip netns`)"
            );
            None
        }
    }
}
