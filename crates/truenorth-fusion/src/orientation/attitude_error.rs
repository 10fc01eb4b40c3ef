//! The error between an attitude estimate and a reference, split as the BROAD benchmark
//! splits it (Laidig, Caruso, Cereatti & Seel, *Data* 6(7):72, 2021, and its
//! `broad_utils.py`): the error quaternion in the reference frame `e = q_est ⊗ q_ref⁻¹`;
//! its whole angle `2 acos|e_w|`; its heading part, the rotation about the vertical in a
//! swing–twist split, `2 atan|e_z/e_w|`; and its inclination part `2 acos √(e_w² + e_z²)`.

use nalgebra::UnitQuaternion;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Total, heading and inclination error angles, radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeError {
    /// The whole error angle.
    pub total_rad: f64,
    /// The rotation about the reference frame's vertical.
    pub heading_rad: f64,
    /// The rest: the error of the estimated vertical.
    pub inclination_rad: f64,
}

impl AttitudeError {
    /// The error of `estimate` against `reference` (both body → reference frame, whose
    /// third axis is vertical: NED or ENU).
    pub fn between(estimate: &UnitQuaternion<f64>, reference: &UnitQuaternion<f64>) -> Self {
        let e = (estimate * reference.inverse()).into_inner();
        Self {
            total_rad: 2.0 * e.w.abs().clamp(0.0, 1.0).acos(),
            heading_rad: 2.0 * (e.k / e.w).abs().atan(),
            inclination_rad: 2.0 * (e.w * e.w + e.k * e.k).sqrt().clamp(0.0, 1.0).acos(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    proptest! {
        /// A rotation about the vertical is all heading, one about a horizontal axis all
        /// inclination, for any reference; the total is the error's angle either way.
        #[test]
        fn splits_heading_and_inclination(
            angle in 0.001f64..3.0, azimuth in -3.1f64..3.1,
            r in proptest::array::uniform3(-3.0f64..3.0),
        ) {
            let reference = UnitQuaternion::from_scaled_axis(Vector3::from(r));
            let yaw = UnitQuaternion::from_scaled_axis(Vector3::z() * angle);
            let tilt = UnitQuaternion::from_scaled_axis(Vector3::new(azimuth.cos(), azimuth.sin(), 0.0) * angle);
            let h = AttitudeError::between(&(yaw * reference), &reference);
            let i = AttitudeError::between(&(tilt * reference), &reference);
            prop_assert!((h.heading_rad - angle).abs() < 1e-7 && h.inclination_rad < 1e-6);
            prop_assert!((i.inclination_rad - angle).abs() < 1e-7 && i.heading_rad < 1e-7);
            prop_assert!((h.total_rad - angle).abs() < 1e-7 && (i.total_rad - angle).abs() < 1e-7);
        }
    }
}
