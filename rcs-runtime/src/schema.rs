//! Schema hashes: a stable 64-bit fingerprint of a buffer type's structure.
//!
//! The Zenoh bridge ([`crate::bridge`], feature `zenoh`) sends each Global
//! Memory sample with the [`Schema::SCHEMA`] of its type, and the receiving
//! process refuses a sample whose hash differs from its own: two processes
//! built from different plan sets would otherwise decode each other's bytes
//! into garbage. `rcsc` computes the hash of every generated type from its
//! structure (field names and types, verbs and parameters) when the plan set
//! places CPUs in more than one process; this module gives the runtime's own
//! types theirs. Hashes are FNV-1a (64 bit): deterministic across builds,
//! machines and compiler versions, unlike `std::hash`.

use crate::handshake::{CommandBuffer, ErrorCode, Status, StatusBuffer};

/// A type with a stable structural fingerprint.
pub trait Schema {
    /// FNV-1a of the type's structure; equal on both ends of a bridge iff
    /// they were built from the same declaration.
    const SCHEMA: u64;
}

/// The FNV-1a offset basis.
pub const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// FNV-1a of `bytes`, continuing from `hash` (start with [`FNV_OFFSET`]).
pub const fn fnv1a(mut hash: u64, bytes: &[u8]) -> u64 {
    let mut i = 0;
    while i < bytes.len() {
        hash ^= bytes[i] as u64;
        hash = hash.wrapping_mul(FNV_PRIME);
        i += 1;
    }
    hash
}

/// The hash of a type named `name` whose parts hash to `parts`, in order.
pub const fn combine(name: &str, parts: &[u64]) -> u64 {
    let mut h = fnv1a(FNV_OFFSET, name.as_bytes());
    let mut i = 0;
    while i < parts.len() {
        h = fnv1a(h, &parts[i].to_le_bytes());
        i += 1;
    }
    h
}

macro_rules! primitive_schema {
    ($($t:ty),*) => {$(
        impl Schema for $t {
            const SCHEMA: u64 = fnv1a(FNV_OFFSET, stringify!($t).as_bytes());
        }
    )*};
}
primitive_schema!(bool, u8, u16, u32, u64, i8, i16, i32, i64, f32, f64, ());

impl<T: Schema, const N: usize> Schema for [T; N] {
    const SCHEMA: u64 = combine("array", &[T::SCHEMA, N as u64]);
}

impl Schema for StatusBuffer {
    const SCHEMA: u64 = combine(
        "StatusBuffer{echo_serial:u32,echo_epoch:u32,status:u16,error:u16,verb:u16,state:u16,refused_serial:u32,refused_epoch:u32}",
        &[],
    );
}

impl Schema for ErrorCode {
    const SCHEMA: u64 = combine("ErrorCode(u16)", &[]);
}

impl Schema for Status {
    const SCHEMA: u64 = combine("Status(u16)", &[]);
}

impl<C: Schema> Schema for CommandBuffer<C> {
    const SCHEMA: u64 = combine("CommandBuffer{serial:u32,epoch:u32,command}", &[C::SCHEMA]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_fnv1a_values() {
        // Reference values of FNV-1a 64.
        assert_eq!(fnv1a(FNV_OFFSET, b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(FNV_OFFSET, b"a"), 0xaf63_dc4c_8601_ec8c);
    }

    #[test]
    fn structure_changes_the_hash() {
        assert_ne!(<[u8; 3]>::SCHEMA, <[u8; 4]>::SCHEMA);
        assert_ne!(<[u8; 3]>::SCHEMA, <[i8; 3]>::SCHEMA);
        assert_ne!(CommandBuffer::<u16>::SCHEMA, CommandBuffer::<u32>::SCHEMA);
        assert_ne!(StatusBuffer::SCHEMA, CommandBuffer::<u16>::SCHEMA);
    }
}
