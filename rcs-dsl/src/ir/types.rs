//! The data a plan set declares beside its controllers — enums, buffer
//! schemas, Global Memory buffer instances — and the resolved [`Type`] every
//! var, parameter, field and expression of the IR has.

use super::{BufferTypeId, CtrlId, EnumId};
use crate::source::Span;
use serde::Serialize;

#[derive(Clone, Debug, Serialize)]
pub struct EnumDef {
    pub name: String,
    pub docs: Vec<String>,
    /// Invariant: at least one variant; the first is the zero value.
    pub variants: Vec<Variant>,
    pub span: Span,
    /// The name in the declaration, for diagnostics.
    #[serde(skip)]
    pub name_span: Span,
}

#[derive(Clone, Debug, Serialize)]
pub struct Variant {
    pub name: String,
    pub docs: Vec<String>,
    pub span: Span,
}

/// A buffer schema (`buffer Name { … }`): plain, fixed-size data.
#[derive(Clone, Debug, Serialize)]
pub struct BufferType {
    pub name: String,
    pub docs: Vec<String>,
    pub fields: Vec<FieldDef>,
    pub span: Span,
    /// The name in the declaration, for diagnostics.
    #[serde(skip)]
    pub name_span: Span,
}

#[derive(Clone, Debug, Serialize)]
pub struct FieldDef {
    pub name: String,
    pub docs: Vec<String>,
    pub ty: Type,
    pub span: Span,
}

/// A Global Memory buffer instance named by `reads`/`writes`.
#[derive(Clone, Debug, Serialize)]
pub struct Buffer {
    pub name: String,
    pub ty: BufferTypeId,
    /// `None`: an external input (a sensor driver or simulator writes it).
    pub writer: Option<CtrlId>,
    pub readers: Vec<CtrlId>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum IntTy {
    I8,
    I16,
    I32,
    I64,
    U8,
    U16,
    U32,
    U64,
}

impl IntTy {
    pub fn name(self) -> &'static str {
        match self {
            IntTy::I8 => "i8",
            IntTy::I16 => "i16",
            IntTy::I32 => "i32",
            IntTy::I64 => "i64",
            IntTy::U8 => "u8",
            IntTy::U16 => "u16",
            IntTy::U32 => "u32",
            IntTy::U64 => "u64",
        }
    }

    pub fn signed(self) -> bool {
        matches!(self, IntTy::I8 | IntTy::I16 | IntTy::I32 | IntTy::I64)
    }

    /// Inclusive range of values, widened to i128.
    pub fn range(self) -> (i128, i128) {
        match self {
            IntTy::I8 => (i8::MIN as i128, i8::MAX as i128),
            IntTy::I16 => (i16::MIN as i128, i16::MAX as i128),
            IntTy::I32 => (i32::MIN as i128, i32::MAX as i128),
            IntTy::I64 => (i64::MIN as i128, i64::MAX as i128),
            IntTy::U8 => (0, u8::MAX as i128),
            IntTy::U16 => (0, u16::MAX as i128),
            IntTy::U32 => (0, u32::MAX as i128),
            IntTy::U64 => (0, u64::MAX as i128),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FloatTy {
    F32,
    F64,
}

impl FloatTy {
    pub fn name(self) -> &'static str {
        match self {
            FloatTy::F32 => "f32",
            FloatTy::F64 => "f64",
        }
    }
}

/// A resolved type.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Type {
    Bool,
    Int(IntTy),
    Float(FloatTy),
    Enum(EnumId),
    Buffer(BufferTypeId),
    Array(Box<Type>, u32),
    /// The status of a controller (built-ins plus its custom statuses).
    Status(CtrlId),
    /// An error code of a controller (built-ins plus the codes it
    /// declares): the type `error`, and `X.error_code` (§8).
    ErrorCode(CtrlId),
    /// What a hook without a return type gives.
    Unit,
}
