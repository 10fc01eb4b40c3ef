//! ROS REP-103 axes into the library's: body FLU (x forward, y left, z up) into FRD (x forward,
//! y right, z down), and attitudes relative to ENU into attitudes relative to NED. PX4 logs
//! are FRD / NED already and pass through unchanged.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use truenorth_core::ned_to_enu;

/// The rotation taking FRD body vectors to FLU ones (and back: it is its own inverse), a half
/// turn about the forward axis: `(x, y, z) → (x, −y, −z)`.
pub fn frd_to_flu() -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(0.0, 1.0, 0.0, 0.0))
}

/// A vector on FLU body axes (a ROS angular velocity, specific force or magnetic field) on
/// FRD body axes.
pub fn flu_vector_to_frd(v_flu: &Vector3<f64>) -> Vector3<f64> {
    frd_to_flu().inverse_transform_vector(v_flu)
}

/// A vector on FRD body axes on FLU body axes (the inverse of [`flu_vector_to_frd`]).
pub fn frd_vector_to_flu(v_frd: &Vector3<f64>) -> Vector3<f64> {
    frd_to_flu().transform_vector(v_frd)
}

/// A ROS attitude (body FLU → ENU, REP-103) as the library's (body FRD → NED):
/// `q_ned_frd = enu_to_ned · q_enu_flu · frd_to_flu`.
pub fn enu_flu_to_ned_frd(q_enu_flu: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
    ned_to_enu().inverse() * q_enu_flu * frd_to_flu()
}

/// The inverse of [`enu_flu_to_ned_frd`]: a body FRD → NED attitude as body FLU → ENU.
pub fn ned_frd_to_enu_flu(q_ned_frd: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
    ned_to_enu() * q_ned_frd * frd_to_flu().inverse()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::{EulerZyx, deg_to_rad};

    fn any_attitude() -> impl Strategy<Value = UnitQuaternion<f64>> {
        (-3.1f64..3.1, -1.5f64..1.5, -3.1f64..3.1).prop_map(|(y, p, r)| {
            EulerZyx {
                yaw_rad: y,
                pitch_rad: p,
                roll_rad: r,
            }
            .to_quaternion()
        })
    }

    proptest! {
        #[test]
        fn vectors_round_trip_and_flip_y_and_z(v in prop::array::uniform3(-1e3f64..1e3)) {
            let v = Vector3::from(v);
            let frd = flu_vector_to_frd(&v);
            prop_assert!((frd - Vector3::new(v.x, -v.y, -v.z)).norm() < 1e-9);
            prop_assert!((frd_vector_to_flu(&frd) - v).norm() < 1e-9);
        }

        #[test]
        fn attitudes_round_trip(q in any_attitude()) {
            let back = enu_flu_to_ned_frd(&ned_frd_to_enu_flu(&q));
            prop_assert!(back.angle_to(&q) < 1e-9);
        }

        /// The converted attitude maps a body vector to the same physical direction: the
        /// FLU vector through the ROS attitude, read in NED, equals the FRD vector through
        /// the converted attitude.
        #[test]
        fn converted_attitude_points_body_vectors_the_same_way(
            q_ros in any_attitude(), v in prop::array::uniform3(-10.0f64..10.0),
        ) {
            let v_flu = Vector3::from(v);
            let enu = q_ros * v_flu;
            let ned_expected = Vector3::new(enu.y, enu.x, -enu.z);
            let ned = enu_flu_to_ned_frd(&q_ros) * flu_vector_to_frd(&v_flu);
            prop_assert!((ned - ned_expected).norm() < 1e-9);
        }
    }

    /// A ROS robot facing north (its x axis along ENU y: yaw +90° in ENU) heads 0° in NED,
    /// and one facing east (ENU yaw 0) heads +90°.
    #[test]
    fn headings_of_known_ros_poses() {
        let north = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), deg_to_rad(90.0));
        let e = EulerZyx::from_quaternion(&enu_flu_to_ned_frd(&north));
        assert!(e.yaw_rad.abs() < 1e-12 && e.pitch_rad.abs() < 1e-12 && e.roll_rad.abs() < 1e-12);
        let east = UnitQuaternion::identity();
        let e = EulerZyx::from_quaternion(&enu_flu_to_ned_frd(&east));
        assert!((e.yaw_rad - deg_to_rad(90.0)).abs() < 1e-12);
    }
}
