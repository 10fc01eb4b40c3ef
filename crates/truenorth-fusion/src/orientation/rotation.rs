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

/// The rotation by the rotation vector `v` for the small angles of one correction step:
/// `(1, v/2)` normalised, whose angle differs from |v| by |v|³/12 — under 10⁻¹⁰ rad for the
/// at most 10⁻³ rad a correction turns per sample — at a fraction of the cost of the exact
/// exponential's sine and cosine. A step is limited to 0.1 rad: only a reading far outside
/// any sensor's range asks for more, and it must not flip the attitude in one sample.
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
    let half = T::of(0.5);
    UnitQuaternion::new_normalize(Quaternion::new(
        T::one(),
        half * v.x,
        half * v.y,
        half * v.z,
    ))
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
        fn small_rotation_turns_by_the_vector(v in proptest::array::uniform3(-1e-3f64..1e-3)) {
            let v = Vector3::from(v);
            let exact = UnitQuaternion::from_scaled_axis(v);
            // Compared by components: an angle from acos would not resolve 10⁻¹⁰ rad.
            let d = (small_rotation(&v).into_inner() - exact.into_inner()).norm();
            // The angle of (1, v/2) normalised falls short of |v| by |v|³/12.
            prop_assert!(d < v.norm().powi(3) / 12.0 + 1e-15, "{d}");
        }
    }
}
