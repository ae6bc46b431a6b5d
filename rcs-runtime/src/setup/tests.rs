//! Unit tests of [`super`] (setup.rs): a setup with no error gives its
//! executives in order; one with errors gives every one of them, and none of
//! its stand-in handles reaches Global Memory.

use super::*;
use crate::exec::CycleContext;
use crate::handshake::{CommandBuffer, StatusBuffer, VerbId};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Go;

impl Command for Go {
    fn verb(&self) -> VerbId {
        0
    }
}

/// A controller that only has a name.
struct Named(&'static str);

impl Controller for Named {
    fn name(&self) -> &str {
        self.0
    }
    fn cycle(&mut self, _ctx: &CycleContext) {}
}

fn made(name: &'static str) -> Result<Box<dyn Controller>, SetupError> {
    Ok(Box::new(Named(name)))
}

const BUFFERS: [BufferDecl; 2] = [BufferDecl::of::<u32>("a"), BufferDecl::of::<f64>("b")];

#[test]
fn a_clean_setup_gives_its_executives_in_order() -> Result<(), SetupError> {
    let mut setup = Setup::new(&BUFFERS);
    let first = setup.executive("one", 1_000_000);
    let second = setup.executive("two", 2_000_000);
    setup.add(second, made("Y"));
    setup.add(first, made("X"));
    setup.add(first, made("Z"));
    let mut w = setup.writer::<u32>("a");
    let r = setup.reader::<u32>("a");
    let op = setup.operator::<Go>("ROOT");
    assert!(setup.errors().is_empty());
    let (gm, executives) = setup.finish()?;
    let names: Vec<(&str, Vec<&str>)> = executives
        .iter()
        .map(|e| (e.name(), e.controller_names().collect()))
        .collect();
    assert_eq!(names, [("one", vec!["X", "Z"]), ("two", vec!["Y"])]);
    assert_eq!(BUFFERS[1].name(), "b");
    // The handles are Global Memory's own.
    w.write(7, 1);
    assert_eq!(r.read().value, 7);
    assert_eq!(gm.reader::<u32>("a")?.read().value, 7);
    assert!(gm.has_writer("ROOT.command"));
    assert_eq!(op.status().value, StatusBuffer::default());
    Ok(())
}

#[test]
fn every_error_is_returned_and_no_stand_in_reaches_global_memory() {
    let mut setup = Setup::new(&[BufferDecl::of::<u32>("a"), BufferDecl::of::<u8>("a")]);
    let zero = setup.executive("zero", 0);
    let ok = setup.executive("ok", 1_000_000);
    setup.add(zero, made("LOST")); // its executive's error is the one reported
    setup.add(ok, made("X"));
    setup.add(ok, made("X"));
    setup.add(7, made("NOWHERE"));
    setup.add(
        ok,
        Err(SetupError::UnknownBuffer("from a controller".into())),
    );
    let _first = setup.writer::<u32>("a");
    let mut second = setup.writer::<u32>("a");
    let unknown = setup.reader::<u16>("nope");
    let _op = setup.operator::<Go>("ROOT");
    setup.declare_controller::<Go>("ROOT"); // again, same types: fine
    setup.declare::<f32>("ROOT.status"); // another type: an error
    let gm = setup.gm().clone();
    // A stand-in writer and reader are connected to nothing.
    second.write(99, 1);
    assert_eq!(gm.reader::<u32>("a").map(|r| r.read().value), Ok(0));
    assert_eq!(unknown.read().value, 0);
    let expected = [
        "TypeMismatch",
        "ZeroPeriod",
        "DuplicateController",
        "UnknownExecutive",
        "UnknownBuffer",
        "WriterTaken",
        "UnknownBuffer",
        "TypeMismatch",
    ];
    match setup.finish() {
        Err(SetupError::Several(errors)) => {
            let kinds: Vec<String> = errors
                .iter()
                .map(|e| {
                    format!("{e:?}")
                        .split(['(', ' '])
                        .next()
                        .unwrap_or("")
                        .to_owned()
                })
                .collect();
            assert_eq!(kinds, expected, "{errors:?}");
            let text = SetupError::Several(errors).to_string();
            assert!(
                text.starts_with("8 setup errors: buffer `a` holds `u32`, not `u8`; "),
                "{text}"
            );
        }
        other => panic!("expected every error, got {other:?}"),
    }
}

#[test]
fn a_single_error_is_returned_as_itself() {
    let mut setup = Setup::new(&BUFFERS);
    let _ = setup.reader::<CommandBuffer<Go>>("a");
    assert!(matches!(
        setup.finish(),
        Err(SetupError::TypeMismatch { .. })
    ));
}
