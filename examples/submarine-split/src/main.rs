//! # The submarine in two processes: Global Memory over Zenoh
//!
//! The plan set in `plans/` is Appendix C's submarine (`plans/submarine`)
//! with a manifest that places SM and PR in process `helm` and TB in
//! process `engine`, beside the simulated turbine and ship that write the
//! external inputs `turbine` and `ship`. build.rs generates it; the
//! generated `System::process` starts one process's CPU and a Zenoh bridge
//! that carries `TB.command`, `TB.status` and `ship` between the two
//! (docs/distribution.md). PR has one row more than in `plans/submarine`:
//! `E2: *2 when TB.stale_cycles > 30 -> Error(TURBINE_SILENT)`.
//!
//! ```text
//! cargo run -- certs /tmp/sub examples/submarine-split/plans              # once: a development CA and certificates
//! cargo run -p submarine-split-example --features zenoh -- helm --certs /tmp/sub     # terminal 1: SM + PR, orders TRANSIT(15)
//! cargo run -p submarine-split-example --features zenoh -- engine --certs /tmp/sub   # terminal 2: TB + turbine and ship simulators
//! ```
//!
//! Every link is mutual TLS, and each process accepts only what the plan
//! set says its peer writes (the policy rcsc generated; docs/distribution.md
//! "Security"). `--insecure` instead runs plain TCP without access control,
//! and says so. `helm` listens on `tls/127.0.0.1:7447` and `engine` connects
//! to it (`--listen`/`--connect` change that). `helm` waits for TB's first status,
//! orders `SM <- TRANSIT(speed)`, and prints a line whenever a status
//! changes; `transit KNOTS` on its standard input orders again. Stop
//! `engine` and PR's E2 fires 31 cycles after TB's last status; start it
//! again and order again: the hierarchy recovers. `one-process` runs the same
//! plan set with `System::new` in one process, flat out, for comparison.
//!
//! Both processes serve a remote console (`Bridge::serve_console`): `rcsc
//! console examples/submarine-split/plans --connect HELM --connect ENGINE
//! --certs DIR` (the `operator` certificate) shows their controllers live,
//! pauses, steps and resumes their executives (the main loops run each
//! cycle through `Executive::step_unless_paused`) and commands SM
//! (docs/console.md). Give the engine a `--listen` endpoint of its own for
//! that: peers do not relay each other's samples.
//!
//! `--report-generations` makes both processes check, every cycle, that
//! what the bridge imports never arrives out of order (`generations.rs`;
//! the fault tests in `tests/netns_faults.rs` use it). The crate's second
//! binary, `fault-relay` (`src/bin/fault_relay.rs`), is those tests' TCP
//! relay that injects delays, stalls, resets and reordered connection
//! attempts between the two processes.
//!
//! Everything lives in `split.rs`, behind this crate's feature `zenoh`
//! (which turns on `rcs-runtime/zenoh`): a workspace build without it
//! compiles nothing from Zenoh.

#[cfg(feature = "zenoh")]
mod generations;
#[cfg(feature = "zenoh")]
mod split;

fn main() -> std::process::ExitCode {
    #[cfg(feature = "zenoh")]
    {
        split::main()
    }
    #[cfg(not(feature = "zenoh"))]
    {
        eprintln!(
            "submarine-split: built without Zenoh; run `cargo run -p submarine-split-example --features zenoh -- helm`"
        );
        std::process::ExitCode::from(2)
    }
}
