//! A reading of both sensors, and the joint calibration that turns one into a heading and a tilt.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_accel::{AccelTriadCalibration, static_tilt};
use truenorth_compass::{CompassCalibration3d, tilt_compensated_heading};
use truenorth_core::{
    Error, MagneticHeading, Result, Tilt, Validate, check_finite, check_finite3, check_positive,
};

/// One static (or slow) reading of both sensors, each in its own raw unit and axes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MagAccelSample {
    /// Time, s (not used by the fit; kept for the caller's records).
    pub t_s: f64,
    /// Raw magnetometer reading, any unit.
    pub mag: Vector3<f64>,
    /// Raw accelerometer reading, any unit, reading specific force (at rest: up).
    pub acc: Vector3<f64>,
}

/// The joint calibration: both sensors into the body frame (x the pointing axis when runs
/// found it, else the accelerometer's), and what it takes to turn two raw readings into a
/// heading and a tilt.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MagAccelCalibration {
    /// The magnetometer's own calibration (symmetric soft iron): a sphere of radius
    /// `field`, in the magnetometer's axes.
    pub mag: CompassCalibration3d,
    /// Rotation from the magnetometer's calibrated axes into the body axes.
    pub mag_to_body: Matrix3<f64>,
    /// The accelerometer: raw → specific force in body axes, m/s².
    pub accel: AccelTriadCalibration,
    /// Total field, magnetometer unit.
    pub field: f64,
    /// Gravity in the accelerometer's raw unit (1 for g, 9.81 for m/s²).
    pub gravity: f64,
    /// Inclination of the field below the horizontal, radians, as measured (positive
    /// down, for an accelerometer reading specific force).
    pub dip_rad: f64,
}

impl MagAccelCalibration {
    /// The field in body axes, magnetometer unit.
    pub fn field_body(&self, raw_mag: &Vector3<f64>) -> Vector3<f64> {
        self.mag_to_body * self.mag.correct(raw_mag)
    }

    /// The specific force in body axes, m/s².
    pub fn specific_force(&self, raw_acc: &Vector3<f64>) -> Vector3<f64> {
        self.accel.correct(raw_acc)
    }

    /// Tilt-compensated heading of the body x axis and the tilt, from one reading of each
    /// sensor (valid at rest or in slow motion, when the accelerometer senses gravity).
    /// A typed error for non-finite readings or parameters, or a free-falling accelerometer.
    pub fn attitude(
        &self,
        raw_mag: &Vector3<f64>,
        raw_acc: &Vector3<f64>,
    ) -> Result<(MagneticHeading, Tilt)> {
        check_finite3("magnetometer reading", raw_mag)?;
        check_finite3("accelerometer reading", raw_acc)?;
        let tilt = static_tilt(&self.specific_force(raw_acc))?;
        let h = self.field_body(raw_mag);
        check_finite3("calibrated field", &h)?;
        Ok((
            MagneticHeading::new(tilt_compensated_heading(&h, &tilt)),
            tilt,
        ))
    }
}

impl Validate for MagAccelCalibration {
    /// Finite; both matrices orientation-preserving and well conditioned; `mag_to_body` a
    /// rotation.
    fn validate(&self) -> Result<()> {
        check_finite3("hard iron", &self.mag.hard_iron)?;
        let soft = self.mag.soft_iron;
        if !(soft.iter().all(|x| x.is_finite()) && soft.determinant() > 0.0) {
            return Err(Error::Degenerate {
                reason: "the soft-iron matrix is not finite, singular or reflecting; recalibrate",
            });
        }
        self.accel.validate()?;
        let r = self.mag_to_body;
        if !(r.iter().all(|x| x.is_finite())
            && (r.transpose() * r - Matrix3::identity()).amax() < 1e-6
            && r.determinant() > 0.0)
        {
            return Err(Error::Degenerate {
                reason: "mag_to_body is not a rotation (orthonormal, determinant +1); recalibrate",
            });
        }
        check_positive("field", self.field)?;
        check_positive("gravity", self.gravity)?;
        check_finite("dip", self.dip_rad)?;
        Ok(())
    }
}
