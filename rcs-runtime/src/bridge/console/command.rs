//! A root's command built from its verb number and typed arguments, for a
//! console that has no generated types: it serializes exactly as the
//! generated `Command` enum of the root does (serde's data model through
//! postcard: the variant's index, then each parameter in declaration
//! order; a plan-set enum parameter as its variant's index), so that the
//! sample a console sends is the one `BridgeBuilder::import_operator`
//! decodes into the typed `CommandBuffer<Command>`. The tests compare the
//! bytes with those of typed enums, and the split example's tests with the
//! generated type.

use serde::ser::{SerializeStructVariant, Serializer};
use serde::Serialize;

use crate::handshake::CommandBuffer;

/// One parameter's value in its declared type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WireArg {
    /// `bool`.
    Bool(bool),
    /// `u8`.
    U8(u8),
    /// `u16`.
    U16(u16),
    /// `u32`.
    U32(u32),
    /// `u64`.
    U64(u64),
    /// `i8`.
    I8(i8),
    /// `i16`.
    I16(i16),
    /// `i32`.
    I32(i32),
    /// `i64`.
    I64(i64),
    /// `f32`.
    F32(f32),
    /// `f64`.
    F64(f64),
    /// A plan-set enum: the index of its variant.
    Enum(u32),
}

impl Serialize for WireArg {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match *self {
            WireArg::Bool(v) => s.serialize_bool(v),
            WireArg::U8(v) => s.serialize_u8(v),
            WireArg::U16(v) => s.serialize_u16(v),
            WireArg::U32(v) => s.serialize_u32(v),
            WireArg::U64(v) => s.serialize_u64(v),
            WireArg::I8(v) => s.serialize_i8(v),
            WireArg::I16(v) => s.serialize_i16(v),
            WireArg::I32(v) => s.serialize_i32(v),
            WireArg::I64(v) => s.serialize_i64(v),
            WireArg::F32(v) => s.serialize_f32(v),
            WireArg::F64(v) => s.serialize_f64(v),
            // Unit variants of a derived enum: names are not on the wire.
            WireArg::Enum(i) => s.serialize_unit_variant("", i, ""),
        }
    }
}

/// A command by verb number (the root's `VerbId`, the declaration order)
/// and arguments (its parameters in declaration order).
#[derive(Debug, Clone, PartialEq)]
pub struct GenericCommand {
    /// The verb's index.
    pub verb: u16,
    /// Its arguments.
    pub args: Vec<WireArg>,
}

impl Serialize for GenericCommand {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let verb = u32::from(self.verb);
        if self.args.is_empty() {
            return s.serialize_unit_variant("Command", verb, "");
        }
        let mut v = s.serialize_struct_variant("Command", verb, "", self.args.len())?;
        for a in &self.args {
            v.serialize_field("", a)?;
        }
        v.end()
    }
}

/// The sample a remote operator sends to root command buffer of schema
/// `schema`: `CommandBuffer { serial, epoch, command }` with the operator's
/// stamps (`generation` counts the commands this sender sent, from 1;
/// `writer_cycle` likewise), in the bridge's wire format.
pub fn encode_command(
    schema: u64,
    instance: u64,
    generation: u64,
    serial: u32,
    epoch: u32,
    command: GenericCommand,
) -> Result<Vec<u8>, String> {
    super::encode_sample(
        schema,
        super::OPERATOR,
        instance,
        generation,
        generation,
        &CommandBuffer {
            serial,
            epoch,
            command,
        },
    )
}
