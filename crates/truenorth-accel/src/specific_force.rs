//! What an accelerometer senses: specific force, the vehicle's acceleration minus gravity,
//! in body axes (Groves, "Principles of GNSS, Inertial, and Multisensor Integrated Navigation
//! Systems", 2nd ed., §2.4.7).
//!
//! NED has z down, so gravity is `g_ned = (0, 0, +g)` and `f_b = Rᵀ (a_ned − g_ned)`, with `R`
//! the body → NED rotation. A level sensor at rest reads `(0, 0, −g)`.

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_core::{Result, check_finite, check_finite3};

/// The true state an accelerometer senses.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AccelTruth {
    /// Attitude, body → NED (Hamilton, scalar first).
    pub attitude: UnitQuaternion<f64>,
    /// Acceleration of the sensor relative to the (non-rotating, flat) earth, NED, m/s².
    pub accel_ned_mps2: Vector3<f64>,
}

impl AccelTruth {
    /// At rest (no acceleration) with the given attitude.
    pub fn at_rest(attitude: UnitQuaternion<f64>) -> Self {
        Self {
            attitude,
            accel_ned_mps2: Vector3::zeros(),
        }
    }

    /// Checks that the quaternion and the acceleration are finite.
    pub fn validate(&self) -> Result<()> {
        let q = self.attitude.quaternion();
        for x in q.coords.iter() {
            check_finite("attitude quaternion", *x)?;
        }
        check_finite3("accel_ned_mps2", &self.accel_ned_mps2)
    }
}

/// Gravity in NED with z down, m/s².
pub fn gravity_ned_mps2(gravity_mps2: f64) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, gravity_mps2)
}

/// The specific force in body axes, `Rᵀ (a_ned − g_ned)`, m/s²: what an ideal
/// accelerometer reads. A typed error for a non-finite truth or gravity.
pub fn specific_force_body_mps2(truth: &AccelTruth, gravity_mps2: f64) -> Result<Vector3<f64>> {
    truth.validate()?;
    check_finite("gravity_mps2", gravity_mps2)?;
    let f = specific_force_unchecked(truth, gravity_mps2);
    check_finite3("specific force (inputs too large)", &f)?;
    Ok(f)
}

/// [`specific_force_body_mps2`] for inputs already checked.
pub(crate) fn specific_force_unchecked(truth: &AccelTruth, gravity_mps2: f64) -> Vector3<f64> {
    truth
        .attitude
        .inverse_transform_vector(&(truth.accel_ned_mps2 - gravity_ned_mps2(gravity_mps2)))
}
