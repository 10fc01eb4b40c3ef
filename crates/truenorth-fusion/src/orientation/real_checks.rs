//! The checks of a restored state for values in the filter's float type: through the `f64`
//! checks of `truenorth-core`, into which every `T` converts exactly.

use nalgebra::Vector3;
use truenorth_core::{Real, Result, check_finite, check_finite3, check_range};

/// `value` is finite.
pub(crate) fn check_finite_in<T: Real>(what: &'static str, value: T) -> Result<()> {
    check_finite(what, value.to_f64()).map(|_| ())
}

/// Every component of `v` is finite.
pub(crate) fn check_finite3_in<T: Real>(what: &'static str, v: &Vector3<T>) -> Result<()> {
    check_finite3(what, &v.map(T::to_f64))
}

/// `value` is finite and within `[min, max]`.
pub(crate) fn check_range_in<T: Real>(
    what: &'static str,
    value: T,
    min: f64,
    max: f64,
) -> Result<()> {
    check_range(what, value.to_f64(), min, max).map(|_| ())
}
