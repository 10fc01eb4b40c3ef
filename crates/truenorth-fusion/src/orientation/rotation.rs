//! Rotations by small rotation vectors without trigonometric functions, for the per-sample
//! steps of the filters (a strapdown step turns by |ω| dt, at most a few hundredths of a
//! radian at the sample rates of an IMU; a correction step by at most 10⁻³ rad).

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use truenorth_core::Real;

/// Below this angle, rad, [`rotation_from_vector`] uses its series.
const SERIES_MAX_RAD: f64 = 0.1;

/// The quaternion `exp(v/2) = (cos(θ/2), sin(θ/2) v/θ)`, θ = |v|, of the rotation by the
/// rotation vector `v` (not normalised: the caller normalises the product it forms).
///
/// Below [`SERIES_MAX_RAD`] the cosine and `sin(x)/x` are their Taylor series to the fourth
/// power of x = θ/2; the first term left out is x⁶/720 < 2·10⁻¹¹ at θ = 0.1. Above it the
/// exact functions are used.
#[inline]
pub(crate) fn rotation_from_vector<T: Real>(v: &Vector3<T>) -> Quaternion<T> {
    let t2 = v.norm_squared();
    let c = T::of;
    if t2 < c(SERIES_MAX_RAD * SERIES_MAX_RAD) {
        let x2 = c(0.25) * t2;
        let w = T::one() - x2 * (c(0.5) - x2 / c(24.0));
        let s = c(0.5) * (T::one() - x2 * (c(1.0 / 6.0) - x2 / c(120.0)));
        Quaternion::new(w, s * v.x, s * v.y, s * v.z)
    } else {
        UnitQuaternion::from_scaled_axis(*v).into_inner()
    }
}

/// The rotation by the rotation vector `v` of one correction step, limited to 0.1 rad: only
/// a reading far outside any sensor's range asks for more, and it must not flip the
/// attitude in one sample. Exact to the series of [`rotation_from_vector`], which needs no
/// square root for its norm.
#[inline]
pub(crate) fn small_rotation<T: Real>(v: &Vector3<T>) -> UnitQuaternion<T> {
    const MAX_STEP_RAD: f64 = 0.1;
    let n2 = v.norm_squared();
    let max = T::of(MAX_STEP_RAD);
    let v = if n2 > max * max {
        v * (max / n2.sqrt())
    } else {
        *v
    };
    UnitQuaternion::new_unchecked(rotation_from_vector(&v))
}

/// Below this departure of a squared norm from 1, [`inv_norm`] takes its Newton step.
const NEWTON_MAX: f64 = 1e-5;

/// `1/√n2` for the squared norm `n2` of a quaternion (or a unit pair) that one step moved
/// off 1 by at most a rounding or a series' remainder: one Newton step from 1,
/// `(3 − n2)/2`, which leaves the norm within `3 (n2 − 1)²/8 < 4·10⁻¹¹` of 1 for
/// `|n2 − 1| < 10⁻⁵` (the next step's takes that off again); the square root beyond, where
/// a step turned by more than a few milliradians, or a restored attitude is off by more.
#[inline]
pub(crate) fn inv_norm<T: Real>(n2: T) -> T {
    let d = n2 - T::one();
    if d < T::of(NEWTON_MAX) && d > T::of(-NEWTON_MAX) {
        T::of(0.5) * (T::of(3.0) - n2)
    } else {
        T::one() / n2.sqrt()
    }
}

/// `q` scaled to unit norm by [`inv_norm`].
#[inline]
pub(crate) fn renormalized<T: Real>(q: Quaternion<T>) -> UnitQuaternion<T> {
    UnitQuaternion::new_unchecked(q * inv_norm(q.norm_squared()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn series_matches_the_exponential(v in proptest::array::uniform3(-0.2f64..0.2)) {
            let v = Vector3::from(v);
            let exact = UnitQuaternion::from_scaled_axis(v).into_inner();
            let ours = rotation_from_vector(&v);
            // First terms left out: x⁶/720 of the cosine and x⁶/5040 of sin(x)/x, x = θ/2 ≤ 0.05.
            prop_assert!((ours - exact).norm() < 4e-11, "{}", (ours - exact).norm());
        }

        #[test]
        fn small_rotation_turns_by_the_vector(v in proptest::array::uniform3(-0.05f64..0.05)) {
            let v = Vector3::from(v);
            let exact = UnitQuaternion::from_scaled_axis(v);
            // Compared by components: an angle from acos would not resolve 10⁻¹⁰ rad.
            let d = (small_rotation(&v).into_inner() - exact.into_inner()).norm();
            prop_assert!(d < 4e-11, "{d}");
        }

        #[test]
        fn small_rotation_stops_at_a_tenth_of_a_radian(v in proptest::array::uniform3(-1e3f64..1e3)) {
            let v = Vector3::from(v);
            prop_assume!(v.norm() > 0.1);
            prop_assert!((small_rotation(&v).angle() - 0.1).abs() < 1e-9);
        }

        #[test]
        fn renormalising_is_normalising(
            q in proptest::array::uniform4(-1.0f64..1.0),
            off in -4e-6f64..4e-6,
        ) {
            let q = Quaternion::from(nalgebra::Vector4::from(q));
            prop_assume!(q.norm() > 0.1);
            // A unit quaternion a step moved off (Newton's step), and any quaternion.
            for q in [q.normalize() * (1.0 + off), q] {
                let r = renormalized(q);
                prop_assert!((r.norm() - 1.0).abs() < 1e-10, "{}", r.norm());
                prop_assert!((r.into_inner() - q.normalize()).norm() < 1e-10);
            }
        }
    }
}
