//! The attitude from one accelerometer (and magnetometer) reading, where the
//! [`crate::QuaternionFilter`] starts and restarts.

use nalgebra::{UnitQuaternion, Vector3};
use truenorth_core::Real;

/// The attitude whose NED up is the measured specific force and, with a magnetometer,
/// whose north is the horizontal part of the field (the TRIAD construction, Black 1964).
pub(crate) fn attitude_from<T: Real>(
    acc: &Vector3<T>,
    mag: Option<&Vector3<T>>,
) -> Option<UnitQuaternion<T>> {
    // Body-frame directions of NED down, and of north when a field is given. Scaling by
    // the largest component first keeps the norms finite for any finite reading.
    let unit = |v: &Vector3<T>| {
        let scale = v.amax();
        (scale > T::zero() && scale.is_finite())
            .then(|| (v / scale).try_normalize(T::of(1e-12)))
            .flatten()
    };
    let down = -unit(acc)?;
    let east_hint = mag
        .and_then(unit)
        .and_then(|m| down.cross(&m).try_normalize(T::of(1e-9)))
        .unwrap_or_else(|| {
            // No field: any heading; take the body x axis as north when it is not vertical.
            down.cross(&Vector3::x())
                .try_normalize(T::of(1e-9))
                .unwrap_or_else(|| down.cross(&Vector3::y()).normalize())
        });
    let north = east_hint.cross(&down);
    // Rows of the body → NED rotation are the NED axes in body coordinates.
    let r =
        nalgebra::Matrix3::from_rows(&[north.transpose(), east_hint.transpose(), down.transpose()]);
    Some(UnitQuaternion::from_matrix(&r))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::EulerZyx;

    fn field_ned() -> Vector3<f64> {
        Vector3::new(20.0, 0.0, 45.0)
    }

    proptest! {
        #[test]
        fn first_reading_gives_the_attitude(yaw in -3.1f64..3.1, pitch in -1.4f64..1.4, roll in -3.1f64..3.1) {
            let truth = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll }.to_quaternion();
            let acc = truth.inverse_transform_vector(&Vector3::new(0.0, 0.0, -9.81));
            let mag = truth.inverse_transform_vector(&field_ned());
            let q = attitude_from(&acc, Some(&mag)).unwrap();
            prop_assert!(q.angle_to(&truth) < 1e-9);
        }
    }
}
