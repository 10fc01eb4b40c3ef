//! Attitude types shared by the compass (tilt compensation), the accelerometer (static tilt)
//! and the estimators.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// Pitch and roll of the body relative to the local level (Z-Y-X Euler convention).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Tilt {
    /// Pitch, radians, positive nose up.
    pub pitch_rad: f64,
    /// Roll, radians, positive right side down.
    pub roll_rad: f64,
}

/// Z-Y-X (yaw, pitch, roll) Euler angles of the body relative to NED.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct EulerZyx {
    /// Yaw (heading), radians, clockwise from north seen from above.
    pub yaw_rad: f64,
    /// Pitch, radians, positive nose up.
    pub pitch_rad: f64,
    /// Roll, radians, positive right side down.
    pub roll_rad: f64,
}

impl EulerZyx {
    /// The rotation body → NED: `R = Rz(yaw) · Ry(pitch) · Rx(roll)`.
    pub fn to_quaternion(&self) -> UnitQuaternion<f64> {
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.yaw_rad)
            * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), self.pitch_rad)
            * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), self.roll_rad)
    }

    /// The Euler angles of a body → NED rotation. Pitch is in [-π/2, π/2]; at ±π/2 yaw and
    /// roll are not separable and roll is reported as 0.
    pub fn from_quaternion(q: &UnitQuaternion<f64>) -> Self {
        let (roll, pitch, yaw) = q.euler_angles();
        Self {
            yaw_rad: yaw,
            pitch_rad: pitch,
            roll_rad: roll,
        }
    }

    /// The tilt part.
    pub fn tilt(&self) -> Tilt {
        Tilt {
            pitch_rad: self.pitch_rad,
            roll_rad: self.roll_rad,
        }
    }
}

/// The rotation that turns a body → NED attitude into a body → ENU one:
/// `q_enu = ned_to_enu() * q_ned`. ENU is (NED y, NED x, −NED z), a half turn about
/// (1, 1, 0)/√2; its inverse turns ENU attitudes (ROS REP-103, many benchmarks) into NED.
pub fn ned_to_enu() -> UnitQuaternion<f64> {
    let h = core::f64::consts::FRAC_1_SQRT_2;
    UnitQuaternion::from_quaternion(Quaternion::new(0.0, h, h, 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::angle_diff;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn euler_quaternion_round_trip(
            yaw in -3.1f64..3.1, pitch in -1.5f64..1.5, roll in -3.1f64..3.1,
        ) {
            let e = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll };
            let back = EulerZyx::from_quaternion(&e.to_quaternion());
            prop_assert!(angle_diff(back.yaw_rad, yaw).abs() < 1e-9);
            prop_assert!((back.pitch_rad - pitch).abs() < 1e-9);
            prop_assert!(angle_diff(back.roll_rad, roll).abs() < 1e-9);
        }

        #[test]
        fn positive_yaw_turns_forward_axis_east(yaw in 0.01f64..3.1) {
            // x forward rotated by a small positive yaw must gain an east (y) component.
            let q = EulerZyx { yaw_rad: yaw, pitch_rad: 0.0, roll_rad: 0.0 }.to_quaternion();
            let fwd = q * Vector3::x();
            prop_assert!(fwd.y > 0.0);
        }

        #[test]
        fn ned_to_enu_swaps_north_and_east_and_flips_down(
            yaw in -3.1f64..3.1, pitch in -1.5f64..1.5, roll in -3.1f64..3.1,
            v in prop::array::uniform3(-10.0f64..10.0),
        ) {
            let q_ned = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll }.to_quaternion();
            let v = Vector3::from(v);
            let ned = q_ned * v;
            let enu = (ned_to_enu() * q_ned) * v;
            prop_assert!((enu - Vector3::new(ned.y, ned.x, -ned.z)).norm() < 1e-9);
        }
    }
}
