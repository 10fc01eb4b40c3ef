//! The checks of readings and of a restored state for values in the filter's float type:
//! the test itself in `T`, and on failure the `f64` error of `truenorth-core`'s checks,
//! into which every `T` converts exactly (a conversion a single-precision FPU does in
//! software, so it is made only for the message).

use nalgebra::Vector3;
use truenorth_core::{Real, Result, check_finite, check_finite3, check_range};

/// `value` is finite.
pub(crate) fn check_finite_in<T: Real>(what: &'static str, value: T) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        check_finite(what, value.to_f64()).map(|_| ())
    }
}

/// Every component of `v` is finite.
pub(crate) fn check_finite3_in<T: Real>(what: &'static str, v: &Vector3<T>) -> Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        check_finite3(what, &v.map(T::to_f64))
    }
}

/// A timestamp is finite: told by its exponent bits, as `f64::is_finite` is a software
/// comparison on an FPU without `f64`.
pub(crate) fn check_finite_time(what: &'static str, t_s: f64) -> Result<()> {
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    if t_s.to_bits() & EXPONENT != EXPONENT {
        Ok(())
    } else {
        check_finite(what, t_s).map(|_| ())
    }
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
