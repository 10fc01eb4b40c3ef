//! Accelerometer calibration: per-axis bias and gain, raw reading → specific force.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use truenorth_core::{Calibration, Error, Result, check_finite3};

/// `f = (raw − bias) ./ gain`, per axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AccelCalibration {
    /// Bias per axis, m/s².
    pub bias_mps2: Vector3<f64>,
    /// Gain per axis (raw per true, `1 + scale error`), positive.
    pub gain: Vector3<f64>,
}

impl Default for AccelCalibration {
    fn default() -> Self {
        Self {
            bias_mps2: Vector3::zeros(),
            gain: Vector3::repeat(1.0),
        }
    }
}

impl AccelCalibration {
    /// A calibration with finite bias and positive finite gains.
    pub fn new(bias_mps2: Vector3<f64>, gain: Vector3<f64>) -> Result<Self> {
        let cal = Self { bias_mps2, gain };
        cal.validate()?;
        Ok(cal)
    }

    /// Checks the bias and gains (useful after loading from disk).
    pub fn validate(&self) -> Result<()> {
        check_finite3("accel calibration bias_mps2", &self.bias_mps2)?;
        check_finite3("accel calibration gain", &self.gain)?;
        for &g in self.gain.iter() {
            if g <= 0.0 {
                return Err(Error::OutOfRange {
                    what: "accel calibration gain",
                    value: g,
                    min: f64::MIN_POSITIVE,
                    max: f64::MAX,
                });
            }
        }
        Ok(())
    }

    /// The calibrated specific force, or a typed error (non-finite reading, invalid
    /// calibration).
    pub fn try_apply(&self, raw_mps2: &Vector3<f64>) -> Result<Vector3<f64>> {
        check_finite3("raw accelerometer reading", raw_mps2)?;
        self.validate()?;
        let f = self.apply(raw_mps2);
        check_finite3("calibrated specific force (reading too large)", &f)?;
        Ok(f)
    }
}

impl Calibration for AccelCalibration {
    type Raw = Vector3<f64>;
    type Physical = Vector3<f64>;

    /// `(raw − bias) ./ gain`; never panics (NaN in, NaN out). Use
    /// [`AccelCalibration::try_apply`] for a typed error instead.
    fn apply(&self, raw: &Vector3<f64>) -> Vector3<f64> {
        (raw - self.bias_mps2).component_div(&self.gain)
    }
}
