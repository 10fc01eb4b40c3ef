//! The calibration model of an inertial sensor, gyroscope or accelerometer:
//! `calibrated = misalignment · ((raw − offset) ./ gain)`.
//!
//! This is the inertial model of x-io Technologies' Fusion library
//! (`FusionCalibrationInertial`: misalignment × sensitivity × (uncalibrated − offset)),
//! with the sensitivity written as its reciprocal, the gain (raw per true, `1 + scale
//! error`), so that a per-axis calibration divides exactly as the sensor models multiply.
//! A sensor whose gain depends on the sign of the reading (a cheap gyro's often does) uses
//! [`axis_calibrated`] per axis.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::{Calibration, Error, Result, Validate, check_finite3, check_positive};

/// `calibrated = misalignment · ((raw − offset) ./ gain)` for a three-axis sensor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InertialCalibration {
    /// Raw output at zero input, raw unit.
    pub offset: Vector3<f64>,
    /// Gain per axis, raw unit per physical unit, positive.
    pub gain: Vector3<f64>,
    /// Cross-axis and alignment correction applied after the gains; `None` for axes taken
    /// as orthogonal and aligned (no matrix product, so per-axis results are exact).
    pub misalignment: Option<Matrix3<f64>>,
}

impl Default for InertialCalibration {
    /// Offset zero, gains one, no misalignment: the raw reading passes through.
    fn default() -> Self {
        Self {
            offset: Vector3::zeros(),
            gain: Vector3::repeat(1.0),
            misalignment: None,
        }
    }
}

impl InertialCalibration {
    /// A checked calibration (see [`Validate`]).
    pub fn new(
        offset: Vector3<f64>,
        gain: Vector3<f64>,
        misalignment: Option<Matrix3<f64>>,
    ) -> Result<Self> {
        let cal = Self {
            offset,
            gain,
            misalignment,
        };
        cal.validate()?;
        Ok(cal)
    }

    /// The calibrated reading, without checks (see [`Calibration::apply`]).
    #[inline]
    pub fn correct(&self, raw: &Vector3<f64>) -> Vector3<f64> {
        let scaled = (raw - self.offset).component_div(&self.gain);
        match &self.misalignment {
            Some(m) => m * scaled,
            None => scaled,
        }
    }
}

impl Validate for InertialCalibration {
    /// Offset finite, gains positive and finite, the misalignment finite and
    /// orientation-preserving (a negative determinant mirrors the axes).
    fn validate(&self) -> Result<()> {
        check_finite3("inertial calibration offset", &self.offset)?;
        for &g in self.gain.iter() {
            check_positive("inertial calibration gain", g)?;
        }
        if let Some(m) = &self.misalignment {
            for c in m.column_iter() {
                check_finite3("inertial calibration misalignment column", &c.into_owned())?;
            }
            if m.determinant() <= 0.0 {
                return Err(Error::Degenerate {
                    reason: "the misalignment matrix is singular or mirrors the axes (determinant not positive)",
                });
            }
        }
        Ok(())
    }
}

impl Calibration for InertialCalibration {
    type Raw = Vector3<f64>;
    type Physical = Vector3<f64>;

    /// [`InertialCalibration::correct`], or a typed error (non-finite reading, invalid
    /// calibration, a result too large to represent).
    fn apply(&self, raw: &Vector3<f64>) -> Result<Vector3<f64>> {
        check_finite3("raw inertial reading", raw)?;
        self.validate()?;
        let c = self.correct(raw);
        check_finite3("calibrated inertial reading (reading too large)", &c)?;
        Ok(c)
    }
}

/// One axis of the model, `(raw − offset) / gain`, with `gain_pos` when `raw − offset ≥ 0`
/// and `gain_neg` otherwise (equal for a sensor whose gain does not depend on the sign).
#[inline]
pub fn axis_calibrated(raw: f64, offset: f64, gain_pos: f64, gain_neg: f64) -> f64 {
    let centred = raw - offset;
    let gain = if centred >= 0.0 { gain_pos } else { gain_neg };
    centred / gain
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// `apply` inverts `raw = gain ⊙ (M⁻¹ c) + offset`.
        #[test]
        fn apply_inverts_the_model(
            o in proptest::array::uniform3(-1.0f64..1.0),
            g in proptest::array::uniform3(0.5f64..1.5),
            k in proptest::array::uniform9(-0.05f64..0.05),
            c in proptest::array::uniform3(-20.0f64..20.0),
        ) {
            let m = Matrix3::identity() + Matrix3::from_row_slice(&k);
            let cal = InertialCalibration::new(Vector3::from(o), Vector3::from(g), Some(m)).unwrap();
            let c = Vector3::from(c);
            let raw = (m.try_inverse().unwrap() * c).component_mul(&cal.gain) + cal.offset;
            prop_assert!((cal.apply(&raw).unwrap() - c).amax() < 1e-9 * (1.0 + c.amax()));
        }
    }

    #[test]
    fn bad_parameters_are_refused() {
        let mirror = InertialCalibration {
            misalignment: Some(Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0))),
            ..InertialCalibration::default()
        };
        assert!(mirror.validate().is_err());
        let flat = InertialCalibration {
            gain: Vector3::new(1.0, 0.0, 1.0),
            ..InertialCalibration::default()
        };
        assert!(flat.apply(&Vector3::zeros()).is_err());
        assert_eq!(axis_calibrated(3.0, 1.0, 2.0, 4.0), 1.0);
        assert_eq!(axis_calibrated(-3.0, 1.0, 2.0, 4.0), -1.0);
    }
}
