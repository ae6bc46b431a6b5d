//! The console's wire pieces without Zenoh: the generic command encodes
//! exactly as typed enums do, controls are checked before they act, and
//! figures round-trip.

use std::sync::Arc;
use std::time::Duration;

use serde::{Deserialize, Serialize};

use super::command::{encode_command, GenericCommand, WireArg};
use super::serve::{process_figures, ControlImport, Watched};
use super::*;
use crate::bridge::error::ErrorLog;
use crate::handshake::CommandBuffer;
use crate::{Executive, ExecutiveConfig, GlobalMemory};

#[derive(Serialize, Deserialize, Clone, Copy, PartialEq, Debug)]
enum Gear {
    Low,
    Mid,
    High,
}

/// A command enum shaped as rcsc generates them (unit and struct variants).
#[derive(Serialize, Deserialize, Clone, Copy, PartialEq, Debug)]
enum Typed {
    Init,
    Go {
        speed: f64,
        gear: Gear,
        n: u8,
        k: i16,
        big: u64,
        on: bool,
        f: f32,
        m: i64,
    },
    Hold {
        at: i32,
    },
}

fn typed_bytes(c: Typed) -> Vec<u8> {
    encode_sample(
        0xfeed,
        OPERATOR,
        9,
        3,
        3,
        &CommandBuffer {
            serial: 70_000,
            epoch: u32::MAX,
            command: c,
        },
    )
    .expect("typed")
}

fn generic_bytes(verb: u16, args: Vec<WireArg>) -> Vec<u8> {
    encode_command(
        0xfeed,
        9,
        3,
        70_000,
        u32::MAX,
        GenericCommand { verb, args },
    )
    .expect("generic")
}

#[test]
fn a_generic_command_encodes_as_the_typed_enum() {
    assert_eq!(typed_bytes(Typed::Init), generic_bytes(0, vec![]));
    let go = Typed::Go {
        speed: -12.5,
        gear: Gear::High,
        n: 250,
        k: -300,
        big: u64::MAX,
        on: true,
        f: 1.25,
        m: i64::MIN,
    };
    let args = vec![
        WireArg::F64(-12.5),
        WireArg::Enum(2),
        WireArg::U8(250),
        WireArg::I16(-300),
        WireArg::U64(u64::MAX),
        WireArg::Bool(true),
        WireArg::F32(1.25),
        WireArg::I64(i64::MIN),
    ];
    assert_eq!(typed_bytes(go), generic_bytes(1, args));
    assert_eq!(
        typed_bytes(Typed::Hold { at: -1 }),
        generic_bytes(2, vec![WireArg::I32(-1)])
    );
    // A wrong argument type is a different encoding (the test can fail).
    assert_ne!(
        typed_bytes(Typed::Hold { at: 7 }),
        generic_bytes(2, vec![WireArg::U8(7)])
    );
    // And the typed decoder reads the generic bytes back.
    let bytes = generic_bytes(2, vec![WireArg::I32(-1)]);
    let (h, v) = crate::bridge::wire::decode::<CommandBuffer<Typed>>(&bytes, 0xfeed).unwrap();
    assert_eq!((h.writer, h.generation), (OPERATOR, 3));
    assert_eq!(v.command, Typed::Hold { at: -1 });
    assert_eq!((v.serial, v.epoch), (70_000, u32::MAX));
}

fn executive(name: &str) -> (Executive, ExecutiveHandle) {
    let e = Executive::new(ExecutiveConfig::new(name, Duration::from_millis(10))).expect("exec");
    let h = e.handle();
    (e, h)
}
use crate::ExecutiveHandle;

fn control(instance: u64, generation: u64, executive: &str, action: ExecutiveAction) -> Vec<u8> {
    encode_sample(
        ExecutiveControl::SCHEMA,
        OPERATOR,
        instance,
        generation,
        generation,
        &ExecutiveControl {
            executive: executive.to_owned(),
            action,
        },
    )
    .expect("encode")
}

#[test]
fn controls_are_checked_before_they_act() {
    let (_e, h) = executive("helm");
    let errors = Arc::new(ErrorLog::default());
    let mut import = ControlImport::new(vec![("helm".into(), h.clone())], Arc::clone(&errors));
    import.receive(&control(1, 1, "helm", ExecutiveAction::Pause));
    assert!(h.is_paused());
    import.receive(&control(1, 2, "helm", ExecutiveAction::Step(3)));
    assert_eq!(h.pending_steps(), 3);
    // A replay of the same console's control: refused, nothing more.
    import.receive(&control(1, 2, "helm", ExecutiveAction::Step(3)));
    assert_eq!(h.pending_steps(), 3);
    // Another writer than the operator, an unknown executive, a step out
    // of range, junk, an oversized sample: refused.
    let mut rogue = encode_sample(
        ExecutiveControl::SCHEMA,
        "engine",
        2,
        1,
        1,
        &ExecutiveControl {
            executive: "helm".into(),
            action: ExecutiveAction::Resume,
        },
    )
    .unwrap();
    import.receive(&rogue);
    import.receive(&control(1, 3, "nowhere", ExecutiveAction::Resume));
    import.receive(&control(1, 4, "helm", ExecutiveAction::Step(0)));
    import.receive(&control(1, 5, "helm", ExecutiveAction::Step(MAX_STEPS + 1)));
    import.receive(&[1, 2, 3]);
    rogue.resize(CONTROL_MAX_LEN + 1, 0);
    import.receive(&rogue);
    assert!(h.is_paused());
    assert_eq!(h.pending_steps(), 3);
    let kinds: Vec<(&str, u64)> = errors
        .refusals()
        .iter()
        .map(|r| (r.kind, r.count))
        .collect();
    assert_eq!(
        kinds,
        [
            ("decode", 1),
            ("generation", 1),
            ("out_of_range", 3),
            ("oversized", 1),
            ("wrong_writer", 1)
        ]
    );
    assert!(errors.refusals().iter().all(|r| r.buffer == CONTROL));
    // A new console (another instance) starts its own generations.
    import.receive(&control(7, 1, "helm", ExecutiveAction::Resume));
    assert!(!h.is_paused());
    // Every prefix and single-byte corruption is refused or applied, never
    // a panic.
    let good = control(8, 1, "helm", ExecutiveAction::Step(2));
    for n in 0..good.len() {
        import.receive(&good[..n]);
        let mut bad = good.clone();
        bad[n] ^= 0xff;
        import.receive(&bad);
    }
}

#[test]
fn figures_round_trip_and_name_their_process() {
    let gm = GlobalMemory::new();
    let (mut e, h) = executive("helm");
    let monitor = e.attach_monitor(4);
    let watched = vec![Watched::new(&gm, h.clone(), monitor)];
    e.run_cycles(3).expect("run");
    let roots = vec![RootCommand {
        root: "SM".into(),
        schema: 42,
    }];
    let figures = process_figures(&watched, &roots);
    assert_eq!(figures.executives[0].cycle, 3);
    assert_eq!(figures.executives[0].period_ns, 10_000_000);
    assert_eq!(figures.roots, roots);
    let bytes = encode_sample(ProcessFigures::SCHEMA, "helm", 5, 1, 1, &figures).unwrap();
    let (instance, generation, back) = decode_figures(&bytes, "helm").expect("decode");
    assert_eq!((instance, generation), (5, 1));
    assert_eq!(back, figures);
    assert!(matches!(
        decode_figures(&bytes, "engine"),
        Err(ConsoleFiguresError::WrongWriter { .. })
    ));
    let wrong = encode_sample(42, "helm", 5, 1, 1, &figures).unwrap();
    assert!(matches!(
        decode_figures(&wrong, "helm"),
        Err(ConsoleFiguresError::Schema { .. })
    ));
    for n in 0..bytes.len() {
        let _ = decode_figures(&bytes[..n], "helm");
    }
}

#[test]
fn the_generated_policy_size_limit_covers_a_control() {
    // rcs-codegen's acl writes a size limit of 584 + 64 for the control
    // key, from this bound; a change here must change it there.
    assert_eq!(CONTROL_MAX_LEN, 584);
}
