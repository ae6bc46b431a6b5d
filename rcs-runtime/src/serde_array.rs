//! serde for arrays of any length, nested as deep as need be.
//!
//! Where it sits: under the generated types of a plan set. serde implements
//! its traits for arrays up to 32 elements only, so a buffer with a field
//! `[f64; 100]` (or `[[u8; 40]; 3]`, whose elements are such arrays) could
//! not derive them and could not cross processes. rcsc puts
//! `#[serde(with = "…")]` on exactly those fields, naming a *codec* type
//! built from [`Leaf`] (a type serde handles itself) and [`Array`] (an
//! array of some codec's values):
//!
//! ```
//! use rcs_runtime::serde_array::{Array, Leaf};
//!
//! #[derive(serde::Serialize, serde::Deserialize, Debug, PartialEq)]
//! struct Scan {
//!     #[serde(with = "Array::<Leaf<f64>, 100>")]
//!     ranges: [f64; 100],
//!     #[serde(with = "Array::<Array<Leaf<u8>, 40>, 3>")]
//!     rows: [[u8; 40]; 3],
//! }
//!
//! let scan = Scan { ranges: [1.5; 100], rows: [[7; 40]; 3] };
//! let json = serde_json::to_string(&scan).unwrap();
//! assert_eq!(serde_json::from_str::<Scan>(&json).unwrap(), scan);
//! ```
//!
//! An array is written as a tuple of its elements, exactly what serde does
//! for the short arrays it supports (postcard: the elements back to back,
//! no length; JSON: a list), and read back into a zeroed array element by
//! element: no allocation, no `unsafe`, and a short or long input is an
//! error, not a panic.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{DeserializeOwned, DeserializeSeed, Error as _, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserializer, Serialize, Serializer};

/// How values of one type are written and read: a [`Leaf`] or an [`Array`].
pub trait Codec {
    /// The type written and read.
    type Value;
    /// Write `value`.
    fn encode<S: Serializer>(value: &Self::Value, s: S) -> Result<S::Ok, S::Error>;
    /// Read a value.
    fn decode<'de, D: Deserializer<'de>>(d: D) -> Result<Self::Value, D::Error>;
    /// The value an array is filled with before its elements are read.
    fn zero() -> Self::Value;
}

/// A type serde handles itself (a number, an enum, a buffer type, a short
/// array of those).
pub struct Leaf<T>(PhantomData<T>);

/// An array of `N` values of codec `E`, any `N`.
pub struct Array<E, const N: usize>(PhantomData<E>);

impl<T: Serialize + DeserializeOwned + Default> Codec for Leaf<T> {
    type Value = T;
    fn encode<S: Serializer>(value: &T, s: S) -> Result<S::Ok, S::Error> {
        value.serialize(s)
    }
    fn decode<'de, D: Deserializer<'de>>(d: D) -> Result<T, D::Error> {
        T::deserialize(d)
    }
    fn zero() -> T {
        T::default()
    }
}

impl<E: Codec, const N: usize> Codec for Array<E, N> {
    type Value = [E::Value; N];
    fn encode<S: Serializer>(value: &Self::Value, s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(N)?;
        for v in value {
            t.serialize_element(&Encoded::<E>(v))?;
        }
        t.end()
    }
    fn decode<'de, D: Deserializer<'de>>(d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_tuple(N, ArrayVisitor::<E, N>(PhantomData))
    }
    fn zero() -> Self::Value {
        std::array::from_fn(|_| E::zero())
    }
}

/// What `#[serde(with = "Array::<…>")]` calls.
impl<E: Codec, const N: usize> Array<E, N> {
    /// Write `value` as a tuple of `N` elements.
    pub fn serialize<S: Serializer>(value: &[E::Value; N], s: S) -> Result<S::Ok, S::Error> {
        <Self as Codec>::encode(value, s)
    }
    /// Read a tuple of exactly `N` elements.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[E::Value; N], D::Error> {
        <Self as Codec>::decode(d)
    }
}

/// One element, written through its codec.
struct Encoded<'a, E: Codec>(&'a E::Value);

impl<E: Codec> Serialize for Encoded<'_, E> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        E::encode(self.0, s)
    }
}

/// One element, read through its codec.
struct Decoded<E>(PhantomData<E>);

impl<'de, E: Codec> DeserializeSeed<'de> for Decoded<E> {
    type Value = E::Value;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<E::Value, D::Error> {
        E::decode(d)
    }
}

struct ArrayVisitor<E, const N: usize>(PhantomData<E>);

impl<'de, E: Codec, const N: usize> Visitor<'de> for ArrayVisitor<E, N> {
    type Value = [E::Value; N];

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "an array of {N} elements")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = <Array<E, N> as Codec>::zero();
        for (i, slot) in out.iter_mut().enumerate() {
            *slot = seq
                .next_element_seed(Decoded::<E>(PhantomData))?
                .ok_or_else(|| A::Error::invalid_length(i, &self))?;
        }
        // A self-describing input (JSON) may hold more than N.
        if seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
            return Err(A::Error::invalid_length(N + 1, &self));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    struct Big {
        #[serde(with = "Array::<Leaf<f64>, 100>")]
        xs: [f64; 100],
        #[serde(with = "Array::<Array<Leaf<u8>, 40>, 3>")]
        grid: [[u8; 40]; 3],
        short: [u16; 2],
    }

    fn big() -> Big {
        Big {
            xs: std::array::from_fn(|i| i as f64 * 0.5),
            grid: std::array::from_fn(|r| std::array::from_fn(|c| (r * 40 + c) as u8)),
            short: [7, 9],
        }
    }

    #[test]
    fn long_and_nested_arrays_round_trip_through_json() {
        let v = big();
        let json = serde_json::to_string(&v).expect("encode");
        assert!(json.starts_with(r#"{"xs":[0.0,0.5,1.0,"#), "{json}");
        assert_eq!(serde_json::from_str::<Big>(&json).expect("decode"), v);
    }

    #[test]
    fn a_wrong_length_is_an_error() {
        let json = serde_json::to_string(&big()).expect("encode");
        let short = json.replacen("[0.0,0.5,", "[0.5,", 1);
        let e = serde_json::from_str::<Big>(&short).expect_err("99 elements");
        assert!(e.to_string().contains("an array of 100 elements"), "{e}");
        let long = json.replacen("[0.0,", "[0.0,0.0,", 1);
        assert!(serde_json::from_str::<Big>(&long).is_err(), "101 elements");
    }

    /// postcard writes a tuple as its elements back to back, as serde does
    /// for arrays of 32 or fewer: a long array is the same bytes as its
    /// two halves.
    #[cfg(feature = "zenoh")]
    #[test]
    fn postcard_sees_the_elements_back_to_back() {
        #[derive(serde::Serialize)]
        struct Halves([u8; 20], [u8; 20]);
        #[derive(serde::Serialize, serde::Deserialize, Debug, PartialEq)]
        struct Whole(#[serde(with = "Array::<Leaf<u8>, 40>")] [u8; 40]);
        let whole = Whole(std::array::from_fn(|i| i as u8 * 3));
        let mut a = [0; 20];
        let mut b = [0; 20];
        a.copy_from_slice(&whole.0[..20]);
        b.copy_from_slice(&whole.0[20..]);
        let bytes = postcard::to_allocvec(&whole).expect("encode");
        assert_eq!(bytes, postcard::to_allocvec(&Halves(a, b)).expect("encode"));
        assert_eq!(
            postcard::from_bytes::<Whole>(&bytes).expect("decode"),
            whole
        );
        assert!(postcard::from_bytes::<Whole>(&bytes[..39]).is_err());
    }
}
