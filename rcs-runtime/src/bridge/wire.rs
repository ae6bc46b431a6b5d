//! The bytes of one bridged sample: postcard of `(schema, generation,
//! writer_cycle)` followed by postcard of the value. The header decodes on
//! its own, so a sample of another schema is refused before its value is
//! looked at.

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::gm::Stamped;

/// Why a sample was not decoded.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum WireError {
    /// The sample carries this other schema hash.
    Schema(u64),
    /// The bytes are not a sample of this type.
    Decode(String),
}

/// Append the sample of `s` (whose type has `schema`) to `out`.
pub(crate) fn encode<T: Serialize>(
    out: &mut Vec<u8>,
    schema: u64,
    s: &Stamped<T>,
) -> Result<(), postcard::Error> {
    postcard::to_io(&(schema, s.generation, s.writer_cycle, &s.value), out).map(|_| ())
}

/// Decode a sample of a type whose schema is `schema`.
pub(crate) fn decode<T: DeserializeOwned>(
    bytes: &[u8],
    schema: u64,
) -> Result<Stamped<T>, WireError> {
    let ((got, generation, writer_cycle), rest) =
        postcard::take_from_bytes::<(u64, u64, u64)>(bytes)
            .map_err(|e| WireError::Decode(e.to_string()))?;
    if got != schema {
        return Err(WireError::Schema(got));
    }
    let value = postcard::from_bytes::<T>(rest).map_err(|e| WireError::Decode(e.to_string()))?;
    Ok(Stamped {
        value,
        generation,
        writer_cycle,
    })
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
        encode(&mut out, 99, &s).unwrap();
        assert_eq!(decode::<(f64, bool)>(&out, 99), Ok(s));
        assert_eq!(decode::<(f64, bool)>(&out, 98), Err(WireError::Schema(99)));
        assert!(matches!(
            decode::<(f64, bool)>(&out[..out.len() - 2], 99),
            Err(WireError::Decode(_))
        ));
    }
}
