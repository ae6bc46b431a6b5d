//! The remote console's protocol against the running split submarine,
//! without the terminal UI: with the `operator` certificate a session sees
//! both processes' figures, pauses the helm's executive, single-steps it by
//! exactly one cycle and resumes it. An outsider — a peer with another
//! process's certificate, or one without a certificate — is refused: its
//! pause never pauses anything and it sees no figures. Without access
//! control (`--insecure`) the same outsider pauses the helm, which is what
//! makes the refusals above able to fail.
//!
//! The console's command encoding (it has no generated types) is compared
//! byte for byte with the typed encoding of the generated `sm::Command`.
//!
//! Every wait has a generous deadline; nothing asserts on timing.

#![cfg(feature = "zenoh")]

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use rcs_runtime::bridge::console::{
    control_key, decode_figures, encode_sample, figures_key, random_instance, ExecutiveAction,
    ExecutiveControl, ExecutiveFigures, ProcessFigures,
};
use rcs_runtime::bridge::zenoh::{self, Wait};
use rcs_runtime::{BridgeConfig, Schema, TlsFiles};

mod common;
use common::{security_args, Proc};

const SYSTEM: &str = "submarine_split";

fn free_endpoint(scheme: &str) -> String {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    format!(
        "{scheme}/127.0.0.1:{}",
        l.local_addr().expect("address").port()
    )
}

/// Helm and engine, each listening on an endpoint of its own (a console
/// connects to both), once the ship holds its first order.
fn hierarchy(security: &[String], scheme: &str) -> (Proc, Proc, String, String) {
    let (helm_ep, engine_ep) = (free_endpoint(scheme), free_endpoint(scheme));
    let mut helm_args = vec!["helm".to_owned(), "--listen".into(), helm_ep.clone()];
    helm_args.extend_from_slice(security);
    let mut engine_args = vec![
        "engine".to_owned(),
        "--connect".into(),
        helm_ep.clone(),
        "--listen".into(),
        engine_ep.clone(),
    ];
    engine_args.extend_from_slice(security);
    let mut helm = Proc::spawn("helm", common::BIN, &helm_args);
    let engine = Proc::spawn("engine", common::BIN, &engine_args);
    helm.wait_for("the goal", |l| l.starts_with("goal "));
    (helm, engine, helm_ep, engine_ep)
}

/// A raw Zenoh session playing a console: `files` its identity (`None`:
/// no certificate, plain TCP), connected to `endpoints`. It grants itself
/// everything; what the processes allow is theirs to decide.
struct Console {
    session: zenoh::Session,
    latest: Arc<Mutex<Vec<(String, ProcessFigures)>>>,
    _subs: Vec<zenoh::pubsub::Subscriber<()>>,
    instance: u64,
    generation: u64,
}

impl Console {
    fn open(files: Option<TlsFiles>, endpoints: &[&str]) -> Console {
        let mut config = BridgeConfig::new(SYSTEM, "console");
        for e in endpoints {
            config = config.connect(e);
        }
        config = match files {
            Some(f) => {
                let mut c = config.tls(f);
                c.policy = Some(
                    r#"{"access_control": {"enabled": false, "default_permission": "allow"}}"#
                        .into(),
                );
                c
            }
            None => config.insecure(),
        };
        let session = zenoh::open(config.zenoh_config().expect("config"))
            .wait()
            .expect("the session opens");
        let latest: Arc<Mutex<Vec<(String, ProcessFigures)>>> = Arc::default();
        let subs = ["helm", "engine"]
            .iter()
            .map(|p| {
                let latest = Arc::clone(&latest);
                let process = (*p).to_owned();
                session
                    .declare_subscriber(figures_key(SYSTEM, p))
                    .callback(move |s| {
                        let bytes = s.payload().to_bytes();
                        let (_, _, f) = decode_figures(&bytes, &process).expect("figures");
                        let mut l = latest.lock().unwrap();
                        l.retain(|(n, _)| *n != process);
                        l.push((process.clone(), f));
                    })
                    .wait()
                    .expect("subscribe")
            })
            .collect();
        Console {
            session,
            latest,
            _subs: subs,
            instance: random_instance(),
            generation: 0,
        }
    }

    /// The latest figures of executive `cpu` of `process`, if any arrived.
    fn executive(&self, process: &str, cpu: &str) -> Option<ExecutiveFigures> {
        let l = self.latest.lock().unwrap();
        l.iter()
            .find(|(p, _)| p == process)
            .and_then(|(_, f)| f.executives.iter().find(|e| e.name == cpu).cloned())
    }

    fn control(&mut self, process: &str, cpu: &str, action: ExecutiveAction) {
        self.generation += 1;
        let bytes = encode_sample(
            ExecutiveControl::SCHEMA,
            "operator",
            self.instance,
            self.generation,
            self.generation,
            &ExecutiveControl {
                executive: cpu.into(),
                action,
            },
        )
        .expect("encode");
        let _ = self.session.put(control_key(SYSTEM, process), bytes).wait();
    }
}

fn until<R>(what: &str, mut f: impl FnMut() -> Option<R>) -> R {
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        if let Some(r) = f() {
            return r;
        }
        assert!(Instant::now() < deadline, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn certs_dir() -> PathBuf {
    PathBuf::from(&security_args(Path::new(env!("CARGO_TARGET_TMPDIR")))[1])
}

#[test]
fn the_operator_watches_pauses_steps_once_and_resumes() {
    let certs = certs_dir();
    let (_helm, _engine, helm_ep, engine_ep) = hierarchy(&security_args(&certs), "tls");
    let mut op = Console::open(
        Some(TlsFiles::in_dir(&certs, "operator")),
        &[&helm_ep, &engine_ep],
    );
    // Both processes' figures: SM and PR from the helm, TB from the engine.
    let helm = until("the helm's figures", || op.executive("helm", "helm"));
    let names: Vec<&str> = helm.controllers.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["SM", "PR"]);
    let engine = until("the engine's figures", || op.executive("engine", "engine"));
    assert!(engine.controllers.iter().any(|c| c.name == "TB"));
    // The helm says which root the operator may command, and its schema.
    let roots = op.latest.lock().unwrap().clone();
    let helm_roots = &roots.iter().find(|(p, _)| p == "helm").unwrap().1.roots;
    assert_eq!(helm_roots.len(), 1);
    assert_eq!(helm_roots[0].root, "SM");

    // Pause: the cycle count stops.
    op.control("helm", "helm", ExecutiveAction::Pause);
    let paused = until("the helm paused", || {
        op.executive("helm", "helm").filter(|e| e.paused)
    });
    // Two figures later than the pause, the count has not moved.
    let frozen = until("a stable count", || {
        let a = op.executive("helm", "helm")?;
        std::thread::sleep(Duration::from_millis(200));
        let b = op.executive("helm", "helm")?;
        (a.cycle == b.cycle).then_some(b.cycle)
    });
    assert!(frozen >= paused.cycle);
    // One step: exactly one more cycle.
    op.control("helm", "helm", ExecutiveAction::Step(1));
    until("the step run", || {
        op.executive("helm", "helm")
            .filter(|e| e.cycle != frozen && e.pending_steps == 0)
    });
    std::thread::sleep(Duration::from_millis(500));
    let after = op.executive("helm", "helm").unwrap();
    assert_eq!(after.cycle, frozen + 1, "{after:?}");
    assert!(after.paused);
    // Resume: it runs again.
    op.control("helm", "helm", ExecutiveAction::Resume);
    until("the helm running", || {
        op.executive("helm", "helm")
            .filter(|e| !e.paused && e.cycle > frozen + 10)
    });
}

#[test]
fn outsiders_cannot_pause_or_watch() {
    let certs = certs_dir();
    let (mut helm, _engine, helm_ep, engine_ep) = hierarchy(&security_args(&certs), "tls");
    let op = Console::open(
        Some(TlsFiles::in_dir(&certs, "operator")),
        &[&helm_ep, &engine_ep],
    );
    until("the helm's figures", || op.executive("helm", "helm"));
    // The engine's certificate: the session opens, the policy denies its
    // subscription to the figures and its puts of controls.
    let mut engine_cert = Console::open(Some(TlsFiles::in_dir(&certs, "engine")), &[&helm_ep]);
    // No certificate at all: plain TCP to a TLS listener opens no session.
    let mut naked = Console::open(None, &[&helm_ep.replacen("tls/", "tcp/", 1)]);
    // The certificate is valid: its session with the helm is open.
    until("the helm as the outsider's peer", || {
        (engine_cert.session.info().peers_zid().wait().count() > 0).then_some(())
    });
    let start = op.executive("helm", "helm").unwrap().cycle;
    for _ in 0..20 {
        engine_cert.control("helm", "helm", ExecutiveAction::Pause);
        engine_cert.control("helm", "helm", ExecutiveAction::Step(1));
        naked.control("helm", "helm", ExecutiveAction::Pause);
        std::thread::sleep(Duration::from_millis(50));
    }
    // The helm runs on: a hundred cycles later it was never paused.
    until("the helm a hundred cycles on", || {
        let e = op.executive("helm", "helm")?;
        assert!(!e.paused, "an outsider paused the helm: {e:?}");
        (e.cycle > start + 100).then_some(())
    });
    assert!(engine_cert.latest.lock().unwrap().is_empty());
    assert!(naked.latest.lock().unwrap().is_empty());
    helm.assert_running();
}

#[test]
fn without_access_control_an_outsider_pauses_the_helm() {
    let (_helm, _engine, helm_ep, _) = hierarchy(&["--insecure".to_owned()], "tcp");
    let mut naked = Console::open(None, &[&helm_ep]);
    until("the helm's figures", || naked.executive("helm", "helm"));
    naked.control("helm", "helm", ExecutiveAction::Pause);
    until("the helm paused", || {
        naked.executive("helm", "helm").filter(|e| e.paused)
    });
}

#[allow(dead_code)]
mod plans {
    rcs_runtime::include_plans!("submarine_split");
}

#[test]
fn the_console_encodes_a_root_command_as_the_generated_type_does() {
    use plans::submarine_split::sm;
    use rcs_console::remote::encode::{encode_root_command, Stamps};
    use rcs_console::{ArgValue, Catalog};
    use rcs_runtime::CommandBuffer;

    let plans = Path::new(env!("CARGO_MANIFEST_DIR")).join("plans");
    let catalog = Catalog::load(&plans).expect("the split plan set");
    let schema = <CommandBuffer<sm::Command> as Schema>::SCHEMA;
    let stamps = Stamps {
        instance: 77,
        generation: 3,
        serial: 300,
        epoch: 0xdead_beef,
    };
    let typed = |command: sm::Command| {
        encode_sample(
            schema,
            "operator",
            stamps.instance,
            stamps.generation,
            stamps.generation,
            &CommandBuffer {
                serial: stamps.serial,
                epoch: stamps.epoch,
                command,
            },
        )
        .expect("typed")
    };
    let console = |verb: &str, args: &[ArgValue]| {
        encode_root_command(&catalog, schema, "SM", verb, args, stamps).expect("console")
    };
    assert_eq!(
        console("TRANSIT", &[ArgValue::Float(8.25)]),
        typed(sm::Command::Transit { speed: 8.25 })
    );
    assert_eq!(console("INIT", &[]), typed(sm::Command::Init));
    assert_ne!(
        console("TRANSIT", &[ArgValue::Float(8.0)]),
        typed(sm::Command::Transit { speed: 8.25 })
    );
}
