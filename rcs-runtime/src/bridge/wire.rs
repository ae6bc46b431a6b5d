//! The bytes of one bridged sample: postcard of the header `(schema,
//! writer, instance, generation, writer_cycle)` followed by postcard of the
//! value, and nothing after it.
//!
//! * `schema`: the [`Schema::SCHEMA`](crate::schema::Schema) of the buffer
//!   type, so that a sample of another declaration is refused before its
//!   value is looked at;
//! * `writer`: the name of the process that wrote it, checked against the
//!   plan set (the access-control policy already refused a sender whose
//!   certificate does not carry that name);
//! * `instance`: a random number per bridge, so that a restarted writer, or
//!   a second process with the same identity, is told apart;
//! * `generation`, `writer_cycle`: the writer's stamps. The importing side
//!   keeps them beside its own cell; the cell's generation is always its own
//!   count of imports.
//!
//! Decoding never trusts a length or a number from the wire: a sample longer
//! than the type's longest encoding is refused before decoding, bytes after
//! the value are refused, and decoding borrows the writer's name from the
//! bytes (no allocation).

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::gm::Stamped;

/// The largest generation a sample may carry: a writer writing a million
/// times a second reaches it after nine years. Beyond it, a sample is
/// forged or corrupt.
pub(crate) const MAX_GENERATION: u64 = 1 << 48;

/// The longest process name a bridge accepts (its own, or a sample's).
pub(crate) const MAX_NAME: usize = 255;

/// The longest header: four varints of at most ten bytes, and a process
/// name with its length.
pub(crate) const MAX_HEADER: usize = 4 * 10 + 2 + MAX_NAME;

/// The longest encoding of a value of type `T`, with margin: postcard
/// writes no integer or enum tag in more than twice its size in memory,
/// floats and bools as they are, arrays without a length.
pub(crate) const fn max_len<T>() -> usize {
    MAX_HEADER + 2 * std::mem::size_of::<T>() + 16
}

/// The header of a decoded sample, borrowing the writer's name.
#[derive(Debug, PartialEq, Eq)]
pub(crate) struct Header<'a> {
    pub writer: &'a str,
    pub instance: u64,
    pub generation: u64,
    pub writer_cycle: u64,
}

/// Why a sample was not decoded.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum WireError {
    /// The sample carries this other schema hash.
    Schema(u64),
    /// The bytes are not a sample of this type.
    Decode(String),
    /// This many bytes follow the value.
    Trailing(usize),
}

/// Append the sample of `s` (whose type has `schema`), written by process
/// `writer` (bridge instance `instance`), to `out`.
pub(crate) fn encode<T: Serialize>(
    out: &mut Vec<u8>,
    schema: u64,
    writer: &str,
    instance: u64,
    s: &Stamped<T>,
) -> Result<(), postcard::Error> {
    postcard::to_io(
        &(
            schema,
            writer,
            instance,
            s.generation,
            s.writer_cycle,
            &s.value,
        ),
        out,
    )
    .map(|_| ())
}

/// Decode a sample of a type whose schema is `schema`.
pub(crate) fn decode<T: DeserializeOwned>(
    bytes: &[u8],
    schema: u64,
) -> Result<(Header<'_>, T), WireError> {
    let ((got, writer, instance, generation, writer_cycle), rest) =
        postcard::take_from_bytes::<(u64, &str, u64, u64, u64)>(bytes)
            .map_err(|e| WireError::Decode(e.to_string()))?;
    if got != schema {
        return Err(WireError::Schema(got));
    }
    let (value, rest) =
        postcard::take_from_bytes::<T>(rest).map_err(|e| WireError::Decode(e.to_string()))?;
    if !rest.is_empty() {
        return Err(WireError::Trailing(rest.len()));
    }
    Ok((
        Header {
            writer,
            instance,
            generation,
            writer_cycle,
        },
        value,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_refusals() {
        let s = Stamped {
            value: (3.5f64, true),
            generation: 7,
            writer_cycle: 42,
        };
        let mut out = Vec::new();
        encode(&mut out, 99, "engine", 5, &s).unwrap();
        assert!(out.len() <= max_len::<(f64, bool)>());
        let (h, v) = decode::<(f64, bool)>(&out, 99).unwrap();
        assert_eq!(
            h,
            Header {
                writer: "engine",
                instance: 5,
                generation: 7,
                writer_cycle: 42
            }
        );
        assert_eq!(v, (3.5, true));
        assert_eq!(
            decode::<(f64, bool)>(&out, 98).unwrap_err(),
            WireError::Schema(99)
        );
        assert!(matches!(
            decode::<(f64, bool)>(&out[..out.len() - 2], 99),
            Err(WireError::Decode(_))
        ));
        let mut junk = out.clone();
        junk.extend_from_slice(&[0, 1, 2]);
        assert_eq!(
            decode::<(f64, bool)>(&junk, 99).unwrap_err(),
            WireError::Trailing(3)
        );
        // Every prefix and every single-byte corruption decodes or is
        // refused, never panics.
        for n in 0..out.len() {
            let _ = decode::<(f64, bool)>(&out[..n], 99);
            let mut bad = out.clone();
            bad[n] ^= 0xff;
            let _ = decode::<(f64, bool)>(&bad, 99);
        }
    }

    #[test]
    fn the_bound_holds_for_the_largest_values() {
        let s = Stamped {
            value: (u64::MAX, u16::MAX, i32::MIN, [u32::MAX; 8]),
            generation: MAX_GENERATION,
            writer_cycle: u64::MAX,
        };
        let mut out = Vec::new();
        let name = "p".repeat(MAX_NAME);
        encode(&mut out, u64::MAX, &name, u64::MAX, &s).unwrap();
        assert!(out.len() <= max_len::<(u64, u16, i32, [u32; 8])>());
    }
}
