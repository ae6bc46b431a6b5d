//! The split submarine across network namespaces, with real faults between
//! helm and engine (issue 24): a 3 s partition (`ip link … down`), a thin
//! link (`tbf`, 128 kbit), and, through the test suite's own relay
//! (`fault-relay`, since the test kernel has no `netem`), a 20 ± 5 ms delay
//! per chunk, a stall, reset and refused connections, and connection
//! attempts that reach the helm late and out of order.
//!
//! Under each fault that silences the engine: PR's watchdog row E2 fires
//! while the fault holds, at `tb_stale=31` (its bound: `TB.stale_cycles >
//! 30`; the count, not the time, is checked); once healed the helm hears
//! the engine again and the next `transit 15` reaches the goal, with the
//! statuses of a one-process run. Throughout: no process ends, no bridge
//! error, and with `--report-generations` neither process ever saw an
//! imported buffer's generation or writer cycle go back. The figures
//! observed are printed (`-- --nocapture`).
//!
//! Needs root and iproute2; without them each test prints why it skips and
//! passes. Nothing asserts on timing: waits have generous deadlines, and a
//! fault is held until the watchdog fired (at least 3 s).

#![cfg(feature = "zenoh")]

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

use common::netns::{namespaces_or_skip, Netns};
use common::{endpoint, field, one_process_goal, submarine_args, Proc, BIN, E2_FIRES_AT, RELAY};

/// The helm's port inside its namespace (no other process uses it there).
const PORT: u16 = 7447;
/// How long a fault holds at least.
const FAULT: Duration = Duration::from_secs(3);

/// `submarine-split ROLE ARGS… --report-generations` inside `role`'s
/// namespace.
fn submarine_in(ns: &Netns, role: &str, args: &[&str]) -> Proc {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let mut all = submarine_args(role, args, dir);
    all.push("--report-generations".into());
    Proc::spawn(role, "ip", &ns.exec_args(role, BIN, &all))
}

/// What one fault's run showed, for the printed figures.
struct Recovery {
    stale_at_e2: u64,
    e2_after: Duration,
    silent_cycles: u64,
    answered_after_heal: Duration,
    goal_after_heal: Duration,
}

impl Recovery {
    fn figure(&self, fault: &str) -> String {
        format!(
            "{fault}: E2 fired at tb_stale={} ({:.2} s after the fault began); \
             engine heard again after {} silent cycles, {:.2} s after healing; \
             `transit 15` at the goal {:.2} s after healing",
            self.stale_at_e2,
            self.e2_after.as_secs_f64(),
            self.silent_cycles,
            self.answered_after_heal.as_secs_f64(),
            self.goal_after_heal.as_secs_f64(),
        )
    }
}

/// Apply a fault that silences the engine, hold it until PR's watchdog
/// fired (and at least [`FAULT`]), heal it, and check the recovery: the
/// helm hears the engine again and `transit 15` reaches `goal`.
fn silence_and_recover<C>(
    helm: &mut Proc,
    goal: &str,
    ctx: &mut C,
    apply: impl FnOnce(&mut C),
    heal: impl FnOnce(&mut C),
) -> Recovery {
    let began = Instant::now();
    apply(ctx);
    let stale_at_e2 = common::watchdog_fired(helm);
    let e2_after = began.elapsed();
    assert_eq!(
        stale_at_e2, E2_FIRES_AT,
        "E2 fires on the first cycle with TB.stale_cycles > 30"
    );
    std::thread::sleep(FAULT.saturating_sub(began.elapsed()));
    heal(ctx);
    let healed = Instant::now();
    let again = helm.wait_for("the engine heard again", |l| {
        l.starts_with("helm: engine answered again after ")
    });
    let answered_after_heal = healed.elapsed();
    let silent_cycles = again
        .split_whitespace()
        .find_map(|w| w.parse().ok())
        .expect("silent cycles on the line");
    helm.say("transit 15");
    helm.wait_for("the order", |l| l.starts_with("order "));
    let reached = helm.wait_for("goal line after healing", |l| l.starts_with("goal "));
    assert_eq!(reached, goal, "the goal after healing");
    Recovery {
        stale_at_e2,
        e2_after,
        silent_cycles,
        answered_after_heal,
        goal_after_heal: healed.elapsed(),
    }
}

/// The end of every test: each process still runs, reported no bridge
/// error and no out-of-order import, and its next `generations` summary
/// says nothing went back. Returns the summaries.
fn assert_healthy_and_in_order(procs: &mut [&mut Proc]) -> Vec<String> {
    let mut summaries = Vec::new();
    for p in procs.iter_mut() {
        p.assert_running();
    }
    for p in procs.iter_mut().filter(|p| p.name != "relay") {
        // The summary after everything so far (the figures are cumulative).
        p.drain();
        let summary = p.wait_for("a generations summary", |l| l.starts_with("generations "));
        let bad: Vec<&String> = p
            .history
            .iter()
            .filter(|l| {
                l.starts_with("out of order")
                    || l.starts_with("bridge error")
                    || (l.starts_with("generations ")
                        && (field(l, "generation_back") != Some(0)
                            || field(l, "cycle_back") != Some(0)))
            })
            .collect();
        assert!(bad.is_empty(), "{}: {bad:?}", p.name);
        summaries.push(format!("{}: {summary}", p.name));
    }
    for p in procs.iter_mut() {
        p.assert_running();
    }
    summaries
}

/// Send the relay a command and return its answer (`ok …` or `error …`).
fn relay_cmd(relay: &mut Proc, command: &str) -> String {
    relay.say(command);
    relay.wait_for(&format!("the relay's answer to `{command}`"), |l| {
        l.starts_with("ok ") || l.starts_with("error")
    })
}

/// The helm's address on the veth pair of [`helm_and_engine_joined`].
const HELM_ADDR: &str = "10.213.1.1";

/// Namespaces `helm` and `engine` joined by a veth pair (`to-engine` in
/// helm, [`HELM_ADDR`]; `to-helm` in engine), or `None` to skip.
fn helm_and_engine_joined(test: &str, tag: &str) -> Option<Netns> {
    let ns = namespaces_or_skip(test, tag, &["helm", "engine"])?;
    ns.veth(
        ("helm", "to-engine", &format!("{HELM_ADDR}/30")),
        ("engine", "to-helm", "10.213.1.2/30"),
    );
    Some(ns)
}

/// The bytes through the helm's end of the link while the helm runs 100
/// cycles (from one `generations` summary to the next), as a figure.
fn traffic(ns: &Netns, helm: &mut Proc, what: &str) -> String {
    let summary = |l: &str| l.starts_with("generations ");
    helm.wait_for("a generations summary", summary);
    let (rx0, tx0) = ns.bytes("helm", "to-engine");
    let t0 = Instant::now();
    helm.wait_for("a generations summary", summary);
    let (rx1, tx1) = ns.bytes("helm", "to-engine");
    let secs = t0.elapsed().as_secs_f64();
    format!(
        "{what}, at the helm's end over 100 cycles ({secs:.1} s): \
         {:.0} B/s engine→helm, {:.0} B/s helm→engine",
        (rx1 - rx0) as f64 / secs,
        (tx1 - tx0) as f64 / secs,
    )
}

/// Both ends of the helm–engine link limited to `rate` by `tbf`.
fn thin_link(ns: &Netns, rate: &str) {
    for (role, ifc) in [("helm", "to-engine"), ("engine", "to-helm")] {
        let args = [
            "qdisc", "replace", "dev", ifc, "root", "tbf", "rate", rate, "burst", "4kb", "latency",
            "200ms",
        ];
        ns.tc(role, &args).expect("tbf");
    }
}

fn print_figures(test: &str, figures: &[String]) {
    println!("figures of {test}:");
    for f in figures {
        println!("  {f}");
    }
}

/// Helm and engine in two namespaces joined by one veth pair: the engine's
/// link goes down for 3 s (E2 fires during the partition, the next order
/// reaches the goal after it), then the link gets thin (tbf 128 kbit): an
/// order still reaches the goal, and so does the next order after a 3 s
/// partition of the thin link (whose backlog drains through it). Where the
/// kernel has `netem`, both ends also get 20 ± 5 ms of delay until the
/// link gets thin.
#[test]
fn netns_partition_link_down_fires_the_watchdog_then_heals_and_a_thin_link_converges() {
    let test = "netns_partition_link_down_fires_the_watchdog_then_heals_and_a_thin_link_converges";
    let Some(ns) = helm_and_engine_joined(test, "part") else {
        return;
    };
    let mut figures = Vec::new();
    if ns.has_netem("helm") {
        for (role, ifc) in [("helm", "to-engine"), ("engine", "to-helm")] {
            ns.tc(
                role,
                &[
                    "qdisc", "add", "dev", ifc, "root", "netem", "delay", "20ms", "5ms",
                ],
            )
            .expect("netem delay");
        }
        figures.push("netem: 20 ± 5 ms on both veth ends".to_owned());
    } else {
        figures.push("netem: not in this kernel (the relay test supplies delays)".to_owned());
    }
    let ep = endpoint(HELM_ADDR, PORT);
    let mut helm = submarine_in(&ns, "helm", &["--listen", &ep]);
    let mut engine = submarine_in(&ns, "engine", &["--connect", &ep]);

    let started = Instant::now();
    let goal = helm.wait_for("goal line", |l| l.starts_with("goal "));
    assert_eq!(goal, one_process_goal());
    figures.push(format!(
        "first goal {:.2} s after start",
        started.elapsed().as_secs_f64()
    ));
    figures.push(traffic(&ns, &mut helm, "the bridge's traffic"));

    // A 3 s partition: the engine's end of the link goes down.
    let r = silence_and_recover(
        &mut helm,
        &goal,
        &mut (),
        |()| ns.link("engine", "to-helm", false),
        |()| ns.link("engine", "to-helm", true),
    );
    figures.push(r.figure("partition (link down 3 s)"));
    engine.assert_running();

    // A thin link: 128 kbit each way (under TLS the bridge sends about
    // 6 kB/s engine → helm); an order still reaches the goal.
    thin_link(&ns, "128kbit");
    let ordered = Instant::now();
    helm.say("transit 10");
    helm.wait_for("the order", |l| l.starts_with("order "));
    helm.wait_for("goal line on the thin link", |l| l.starts_with("goal "));
    figures.push(format!(
        "thin link (tbf 128 kbit): `transit 10` at the goal after {:.2} s",
        ordered.elapsed().as_secs_f64()
    ));
    // The watchdog on the thin link: how stale TB.status got at worst.
    helm.drain();
    let worst = helm
        .history
        .iter()
        .rev()
        .take_while(|l| !l.starts_with("order SM <- TRANSIT(speed: 10"))
        .filter_map(|l| field(l, "tb_stale"))
        .max();
    figures.push(format!(
        "thin link: highest tb_stale printed since the order: {worst:?}"
    ));
    // A 3 s partition of the thin link.
    let r = silence_and_recover(
        &mut helm,
        &goal,
        &mut (),
        |()| ns.link("engine", "to-helm", false),
        |()| ns.link("engine", "to-helm", true),
    );
    figures.push(r.figure("partition (link down 3 s) of the thin link"));
    figures.push(traffic(
        &ns,
        &mut helm,
        "the bridge's traffic on the thin link",
    ));

    figures.extend(assert_healthy_and_in_order(&mut [&mut helm, &mut engine]));
    print_figures(test, &figures);
}

/// Helm, relay and engine in three namespaces; the engine reaches the helm
/// only through `fault-relay`, which delays every chunk 20 ± 5 ms
/// throughout. On top of that, in one run of the three processes: a 3 s
/// stall, a reset (RST) of every connection with new attempts refused for
/// 3 s, and a close (FIN) after which new attempts are held and replayed
/// late, newest first, once a later attempt has connected.
#[test]
fn netns_relay_delay_stall_reset_and_reordered_attempts_recover() {
    let test = "netns_relay_delay_stall_reset_and_reordered_attempts_recover";
    let Some(ns) = namespaces_or_skip(test, "relay", &["helm", "relay", "engine"]) else {
        return;
    };
    ns.veth(
        ("helm", "to-relay", "10.213.2.1/30"),
        ("relay", "to-helm", "10.213.2.2/30"),
    );
    ns.veth(
        ("relay", "to-engine", "10.213.2.5/30"),
        ("engine", "to-relay", "10.213.2.6/30"),
    );
    let relay_args: Vec<String> = [
        "--listen",
        "10.213.2.5:7447",
        "--upstream",
        "10.213.2.1:7447",
    ]
    .map(String::from)
    .to_vec();
    let mut relay = Proc::spawn("relay", "ip", &ns.exec_args("relay", RELAY, &relay_args));
    relay.wait_for("the relay listening", |l| l.starts_with("relay: listening"));
    let ok = relay_cmd(&mut relay, "delay 20 5");
    assert_eq!(ok, "ok delay 20 5");

    let mut helm = submarine_in(&ns, "helm", &["--listen", &endpoint("10.213.2.1", PORT)]);
    let mut engine = submarine_in(&ns, "engine", &["--connect", &endpoint("10.213.2.5", PORT)]);
    let mut figures = Vec::new();

    let started = Instant::now();
    let goal = helm.wait_for("goal line", |l| l.starts_with("goal "));
    assert_eq!(goal, one_process_goal());
    figures.push(format!(
        "delay 20 ± 5 ms per chunk: first goal {:.2} s after start",
        started.elapsed().as_secs_f64()
    ));
    let stats = relay_cmd(&mut relay, "stats");
    assert!(field(&stats, "chunks").unwrap_or(0) > 0, "{stats}");
    figures.push(format!("relay under delay 20 ± 5: {stats}"));

    // A stall: connections stay open, nothing moves for 3 s, then the held
    // chunks go on in order.
    let r = silence_and_recover(
        &mut helm,
        &goal,
        &mut relay,
        |relay| assert_eq!(relay_cmd(relay, "stall"), "ok stall"),
        |relay| assert_eq!(relay_cmd(relay, "flow"), "ok flow"),
    );
    figures.push(r.figure("stall 3 s"));

    // Every connection reset (RST), new attempts reset for 3 s.
    let r = silence_and_recover(
        &mut helm,
        &goal,
        &mut relay,
        |relay| {
            relay_cmd(relay, "refuse");
            relay_cmd(relay, "reset");
        },
        |relay| assert_eq!(relay_cmd(relay, "accept"), "ok accept"),
    );
    figures.push(r.figure("reset + refused attempts 3 s"));

    // Reordered attempts: after a close (FIN), the engine's new attempts are held
    // (their first bytes kept, then reset); once a later attempt connects,
    // the held ones reach the helm late, newest first.
    let r = silence_and_recover(
        &mut helm,
        &goal,
        &mut relay,
        |relay| {
            relay_cmd(relay, "hold");
            relay_cmd(relay, "close");
            let held = |l: &str| l.starts_with("held attempt ");
            if !relay.history.iter().any(|l| held(l)) {
                relay.wait_for("a held attempt", held);
            }
        },
        |relay| assert_eq!(relay_cmd(relay, "release"), "ok release"),
    );
    figures.push(r.figure("held attempts, replayed late"));
    let replayed = relay.wait_for("the late replay", |l| {
        l.starts_with("replayed ") && l.ends_with("late attempts")
    });
    let replays: Vec<String> = relay
        .history
        .iter()
        .filter(|l| l.starts_with("replayed attempt") || l.starts_with("held attempt"))
        .cloned()
        .collect();
    figures.push(format!("{replayed}: {replays:?}"));
    // The late attempts did not disturb the live session: an order after
    // them reaches the goal without PR failing.
    let mark = helm.history.len();
    helm.say("transit 15");
    helm.wait_for("the order", |l| l.starts_with("order "));
    helm.wait_for("goal after the late attempts", |l| l.starts_with("goal "));
    assert!(
        !helm.history[mark..].iter().any(|l| common::is_pr_error(l)),
        "PR failed after the late attempts: {:?}",
        &helm.history[mark..]
    );

    figures.push(format!(
        "relay at the end: {}",
        relay_cmd(&mut relay, "stats")
    ));
    figures.extend(assert_healthy_and_in_order(&mut [
        &mut helm,
        &mut engine,
        &mut relay,
    ]));
    print_figures(test, &figures);
}

/// A link thinner than what the bridge sends (the engine publishes TB.status
/// and `ship` every cycle: about 4 kB/s, 32 kbit/s, on the wire) but wide
/// enough for a fresh value many times per watchdog period: 16 kbit. A
/// latest-value bridge should drop what the link cannot carry and keep the
/// engine heard; PR's watchdog should not fire while the engine runs, and
/// orders should reach the goal.
#[test]
#[ignore = "bridge: on a link thinner than its publish rate, samples queue in the kernel's \
            TCP send buffer (CongestionControl::Drop only drops when Zenoh's own queue is \
            full), so TB.status reaches the helm seconds late and in bursts and PR's watchdog \
            E2 fires although the engine runs; needs coalescing before the socket \
            (rcs-runtime/src/bridge/export.rs)"]
fn netns_thin_link_below_the_bridge_rate_keeps_the_engine_heard() {
    let test = "netns_thin_link_below_the_bridge_rate_keeps_the_engine_heard";
    let Some(ns) = helm_and_engine_joined(test, "thin") else {
        return;
    };
    let ep = endpoint(HELM_ADDR, PORT);
    let mut helm = submarine_in(&ns, "helm", &["--listen", &ep]);
    let mut engine = submarine_in(&ns, "engine", &["--connect", &ep]);
    helm.wait_for("goal line", |l| l.starts_with("goal "));

    thin_link(&ns, "16kbit");
    let mark = helm.history.len();
    let failed = |l: &str| common::is_pr_error(l);
    // 200 cycles on the thin link, then an order; three times (the backlog
    // builds up over a few hundred cycles).
    for speed in [10, 15, 10] {
        for _ in 0..2 {
            let l = helm.wait_for("a summary or PR failing", |l| {
                l.starts_with("generations ") || failed(l)
            });
            println!("16 kbit: {l}");
        }
        helm.say(&format!("transit {speed}"));
        helm.wait_for("the order", |l| l.starts_with("order "));
        let end = helm.wait_for("goal or PR failing", |l| {
            l.starts_with("goal ") || failed(l)
        });
        println!("16 kbit, transit {speed}: {end}");
        let queued = std::process::Command::new("ip")
            .args(["netns", "exec", ns.name("engine"), "ss", "-tn"])
            .output()
            .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
            .unwrap_or_default();
        println!("engine's sockets:\n{queued}");
        let seen = &helm.history[mark..];
        assert!(
            !seen.iter().any(|l| failed(l)),
            "PR failed on a 16 kbit link with the engine running:\n{}",
            seen.join("\n")
        );
    }
    assert_healthy_and_in_order(&mut [&mut helm, &mut engine]);
}
