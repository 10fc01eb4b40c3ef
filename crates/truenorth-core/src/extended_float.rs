//! Serde for numbers that may legitimately be non-finite (a time not yet seen, an unknown
//! position's infinite covariance, a `-inf` "never" sentinel), so that a saved state reads
//! back bit for bit through formats such as JSON that have no NaN or infinity.
//!
//! A finite number is written as a plain number, exactly as serde writes an `f64`, so a
//! format that only ever held finite values does not change; a non-finite one is written as
//! the string `"NaN"`, `"inf"` or `"-inf"`. Use the modules with `#[serde(with = ...)]` on
//! exactly the fields that may be non-finite; every other number of a state must be finite,
//! which [`check_plain_numbers_finite`] checks in one pass over the whole state.
//!
//! ```
//! use serde::{Deserialize, Serialize};
//!
//! #[derive(Serialize, Deserialize)]
//! struct Clock {
//!     #[serde(with = "truenorth_core::extended_float::scalar")]
//!     last_s: f64,
//!     dt_s: f64,
//! }
//!
//! let never = Clock { last_s: f64::NEG_INFINITY, dt_s: 0.1 };
//! assert!(truenorth_core::extended_float::check_plain_numbers_finite(&never).is_ok());
//! let broken = Clock { last_s: 0.0, dt_s: f64::NAN };
//! assert!(truenorth_core::extended_float::check_plain_numbers_finite(&broken).is_err());
//! ```

use core::fmt;

use serde::de::{self, Deserializer, Visitor};
use serde::ser::{self, Serialize, Serializer};

use crate::{Error, Result};

/// The text written for a NaN.
pub const NAN: &str = "NaN";
/// The text written for `+∞`.
pub const INFINITY: &str = "inf";
/// The text written for `−∞`.
pub const NEG_INFINITY: &str = "-inf";

/// An `f64` that serialises as [this module](self) describes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Extended(f64);

impl Serialize for Extended {
    fn serialize<S: Serializer>(&self, serializer: S) -> core::result::Result<S::Ok, S::Error> {
        let v = self.0;
        if v.is_finite() {
            serializer.serialize_f64(v)
        } else if v.is_nan() {
            serializer.serialize_str(NAN)
        } else if v > 0.0 {
            serializer.serialize_str(INFINITY)
        } else {
            serializer.serialize_str(NEG_INFINITY)
        }
    }
}

struct ExtendedVisitor;

impl Visitor<'_> for ExtendedVisitor {
    type Value = Extended;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number or one of \"NaN\", \"inf\", \"-inf\"")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> core::result::Result<Extended, E> {
        Ok(Extended(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> core::result::Result<Extended, E> {
        Ok(Extended(v as f64))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> core::result::Result<Extended, E> {
        Ok(Extended(v as f64))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> core::result::Result<Extended, E> {
        match v {
            NAN => Ok(Extended(f64::NAN)),
            INFINITY => Ok(Extended(f64::INFINITY)),
            NEG_INFINITY => Ok(Extended(f64::NEG_INFINITY)),
            _ => Err(E::invalid_value(de::Unexpected::Str(v), &self)),
        }
    }
}

impl<'de> serde::Deserialize<'de> for Extended {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> core::result::Result<Self, D::Error> {
        deserializer.deserialize_any(ExtendedVisitor)
    }
}

/// `#[serde(with = "truenorth_core::extended_float::scalar")]` on an `f64` field.
pub mod scalar {
    use super::Extended;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes `v`: a number if finite, otherwise `"NaN"`, `"inf"` or `"-inf"`.
    pub fn serialize<S: Serializer>(v: &f64, serializer: S) -> Result<S::Ok, S::Error> {
        Extended(*v).serialize(serializer)
    }

    /// Reads a number or one of `"NaN"`, `"inf"`, `"-inf"`.
    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
        Extended::deserialize(deserializer).map(|e| e.0)
    }
}

/// `#[serde(with = "truenorth_core::extended_float::matrix2")]` on a `Matrix2<f64>` field:
/// the four entries in nalgebra's own layout (column by column), each as [`scalar`].
pub mod matrix2 {
    use super::Extended;
    use nalgebra::Matrix2;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes the entries column by column, as nalgebra does.
    pub fn serialize<S: Serializer>(m: &Matrix2<f64>, serializer: S) -> Result<S::Ok, S::Error> {
        let e = |i: usize| Extended(m.as_slice()[i]);
        (e(0), e(1), e(2), e(3)).serialize(serializer)
    }

    /// Reads four entries column by column.
    pub fn deserialize<'de, D: Deserializer<'de>>(
        deserializer: D,
    ) -> Result<Matrix2<f64>, D::Error> {
        let (a, b, c, d) = <(Extended, Extended, Extended, Extended)>::deserialize(deserializer)?;
        Ok(Matrix2::from_column_slice(&[a.0, b.0, c.0, d.0]))
    }
}

/// `#[serde(with = "truenorth_core::extended_float::array3")]` on a `[f64; 3]` field: the three
/// entries, each as [`scalar`].
pub mod array3 {
    use super::Extended;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes the three entries.
    pub fn serialize<S: Serializer>(v: &[f64; 3], serializer: S) -> Result<S::Ok, S::Error> {
        v.map(Extended).serialize(serializer)
    }

    /// Reads three entries.
    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<[f64; 3], D::Error> {
        <[Extended; 3]>::deserialize(deserializer).map(|v| v.map(|e| e.0))
    }
}

/// Checks that every number `value` serialises as a plain number is finite: the fields
/// marked with this module's `with` helpers may hold anything (they serialise non-finite
/// values as text), every other number of a saved state must be finite. Refuses with
/// [`Error::InvalidSnapshot`].
pub fn check_plain_numbers_finite<T: Serialize + ?Sized>(value: &T) -> Result<()> {
    value
        .serialize(FiniteCheck)
        .map_err(|_| Error::InvalidSnapshot {
            reason: "a number that must be finite is not",
        })
}

/// The error of [`FiniteCheck`]: a plain number that is not finite (or a serialiser's own
/// error, which a derived `Serialize` never raises on its own).
#[derive(Debug)]
struct NotFinite;

impl fmt::Display for NotFinite {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number that must be finite is not")
    }
}

impl core::error::Error for NotFinite {}

impl ser::Error for NotFinite {
    fn custom<T: fmt::Display>(_msg: T) -> Self {
        NotFinite
    }
}

/// A serialiser that writes nothing and fails at the first non-finite plain number.
struct FiniteCheck;

type Check = core::result::Result<(), NotFinite>;

macro_rules! accept {
    ($($method:ident: $t:ty),* $(,)?) => {
        $(fn $method(self, _v: $t) -> Check { Ok(()) })*
    };
}

impl Serializer for FiniteCheck {
    type Ok = ();
    type Error = NotFinite;
    type SerializeSeq = Self;
    type SerializeTuple = Self;
    type SerializeTupleStruct = Self;
    type SerializeTupleVariant = Self;
    type SerializeMap = Self;
    type SerializeStruct = Self;
    type SerializeStructVariant = Self;

    accept!(
        serialize_bool: bool, serialize_i8: i8, serialize_i16: i16, serialize_i32: i32,
        serialize_i64: i64, serialize_u8: u8, serialize_u16: u16, serialize_u32: u32,
        serialize_u64: u64, serialize_char: char, serialize_str: &str, serialize_bytes: &[u8],
    );

    fn serialize_f32(self, v: f32) -> Check {
        if v.is_finite() {
            Ok(())
        } else {
            Err(NotFinite)
        }
    }

    fn serialize_f64(self, v: f64) -> Check {
        if v.is_finite() {
            Ok(())
        } else {
            Err(NotFinite)
        }
    }

    fn serialize_none(self) -> Check {
        Ok(())
    }

    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Check {
        value.serialize(self)
    }

    fn serialize_unit(self) -> Check {
        Ok(())
    }

    fn serialize_unit_struct(self, _name: &'static str) -> Check {
        Ok(())
    }

    fn serialize_unit_variant(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
    ) -> Check {
        Ok(())
    }

    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        value: &T,
    ) -> Check {
        value.serialize(self)
    }

    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        value: &T,
    ) -> Check {
        value.serialize(self)
    }

    fn serialize_seq(self, _len: Option<usize>) -> core::result::Result<Self, NotFinite> {
        Ok(self)
    }

    fn serialize_tuple(self, _len: usize) -> core::result::Result<Self, NotFinite> {
        Ok(self)
    }

    fn serialize_tuple_struct(
        self,
        _name: &'static str,
        _len: usize,
    ) -> core::result::Result<Self, NotFinite> {
        Ok(self)
    }

    fn serialize_tuple_variant(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        _len: usize,
    ) -> core::result::Result<Self, NotFinite> {
        Ok(self)
    }

    fn serialize_map(self, _len: Option<usize>) -> core::result::Result<Self, NotFinite> {
        Ok(self)
    }

    fn serialize_struct(
        self,
        _name: &'static str,
        _len: usize,
    ) -> core::result::Result<Self, NotFinite> {
        Ok(self)
    }

    fn serialize_struct_variant(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        _len: usize,
    ) -> core::result::Result<Self, NotFinite> {
        Ok(self)
    }

    fn collect_str<T: fmt::Display + ?Sized>(self, _value: &T) -> Check {
        Ok(())
    }
}

/// Every element of a compound value is checked the same way.
macro_rules! compound {
    ($($trait:ident :: $method:ident),* $(,)?) => {
        $(impl ser::$trait for FiniteCheck {
            type Ok = ();
            type Error = NotFinite;
            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> Check {
                value.serialize(FiniteCheck)
            }
            fn end(self) -> Check {
                Ok(())
            }
        })*
    };
}

compound!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field,
);

impl ser::SerializeMap for FiniteCheck {
    type Ok = ();
    type Error = NotFinite;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Check {
        key.serialize(FiniteCheck)
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Check {
        value.serialize(FiniteCheck)
    }
    fn end(self) -> Check {
        Ok(())
    }
}

macro_rules! named_fields {
    ($($trait:ident),* $(,)?) => {
        $(impl ser::$trait for FiniteCheck {
            type Ok = ();
            type Error = NotFinite;
            fn serialize_field<T: Serialize + ?Sized>(&mut self, _key: &'static str, value: &T) -> Check {
                value.serialize(FiniteCheck)
            }
            fn end(self) -> Check {
                Ok(())
            }
        })*
    };
}

named_fields!(SerializeStruct, SerializeStructVariant);

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix2;
    use proptest::prelude::*;
    use serde::{Deserialize, Serialize};

    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    struct Held {
        #[serde(with = "scalar")]
        any: f64,
        #[serde(with = "matrix2")]
        cov: Matrix2<f64>,
        plain: f64,
    }

    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    struct Plain {
        any: f64,
        cov: Matrix2<f64>,
        plain: f64,
    }

    fn extended() -> impl Strategy<Value = f64> {
        prop_oneof![
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(f64::NEG_INFINITY),
            proptest::num::f64::NORMAL | proptest::num::f64::SUBNORMAL | proptest::num::f64::ZERO,
        ]
    }

    proptest! {
        #[test]
        fn only_the_marked_fields_may_be_non_finite(any in extended(), c in extended(), plain in extended()) {
            let held = Held { any, cov: Matrix2::new(1.0, c, c, 2.0), plain };
            prop_assert_eq!(check_plain_numbers_finite(&held).is_ok(), plain.is_finite());
        }
    }

    #[test]
    fn finite_states_pass_the_check_with_or_without_the_marks() {
        let plain = Plain {
            any: 3.0,
            cov: Matrix2::new(1.0, 2.0, 3.0, 4.0),
            plain: 0.1,
        };
        let marked = Held {
            any: 3.0,
            cov: plain.cov,
            plain: 0.1,
        };
        assert!(check_plain_numbers_finite(&plain).is_ok());
        assert!(check_plain_numbers_finite(&marked).is_ok());
        let broken = Plain {
            cov: Matrix2::new(1.0, f64::NAN, 3.0, 4.0),
            ..plain
        };
        assert_eq!(
            check_plain_numbers_finite(&broken),
            Err(Error::InvalidSnapshot {
                reason: "a number that must be finite is not"
            })
        );
    }
}
