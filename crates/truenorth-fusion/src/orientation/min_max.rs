//! The smaller and the larger of a value and a bound by one comparison, for the per-sample
//! paths: `min` and `max` of `f32` are library calls on a Cortex-M4F (its FPU has no
//! minimum instruction), a comparison is a few instructions. For a bound that is never NaN
//! they give what `min` and `max` give, a NaN value included (it gives the bound).

use truenorth_core::Real;

/// `x.min(max)`, for a `max` that is never NaN.
#[inline]
pub(crate) fn at_most<T: Real>(x: T, max: T) -> T {
    if x < max { x } else { max }
}

/// `x.max(min)`, for a `min` that is never NaN.
#[inline]
pub(crate) fn at_least<T: Real>(x: T, min: T) -> T {
    if x > min { x } else { min }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn they_are_min_and_max(x in proptest::num::f64::ANY, bound in -1e300f64..1e300) {
            // Equal as numbers (a zero's sign aside, which `min` leaves open).
            prop_assert_eq!(at_most(x, bound), x.min(bound));
            prop_assert_eq!(at_least(x, bound), x.max(bound));
        }
    }
}
