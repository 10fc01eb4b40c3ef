//! Accelerometer calibration: per-axis bias and gain, raw reading → specific force: the
//! [`InertialCalibration`] model without misalignment, under the accelerometer's names.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use truenorth_core::{
    Calibration, InertialCalibration, Result, Validate, check_finite3, check_positive,
};

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
}

impl From<AccelCalibration> for InertialCalibration {
    /// Offset the bias, the same gains, no misalignment.
    fn from(c: AccelCalibration) -> Self {
        Self {
            offset: c.bias_mps2,
            gain: c.gain,
            misalignment: None,
        }
    }
}

impl Validate for AccelCalibration {
    /// The bias finite and every gain positive and finite. The fields are public (a
    /// calibration is loaded from disk), so [`Calibration::apply`] checks again.
    fn validate(&self) -> Result<()> {
        check_finite3("accel calibration bias_mps2", &self.bias_mps2)?;
        for &g in self.gain.iter() {
            check_positive("accel calibration gain", g)?;
        }
        Ok(())
    }
}

impl Calibration for AccelCalibration {
    type Raw = Vector3<f64>;
    type Physical = Vector3<f64>;

    /// `(raw − bias) ./ gain`, or a typed error (non-finite reading, invalid calibration, a
    /// result too large to represent).
    fn apply(&self, raw: &Vector3<f64>) -> Result<Vector3<f64>> {
        check_finite3("raw accelerometer reading", raw)?;
        self.validate()?;
        let f = InertialCalibration::from(*self).correct(raw);
        check_finite3("calibrated specific force (reading too large)", &f)?;
        Ok(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::Error;

    proptest! {
        /// `apply` inverts `raw = gain·f + bias` per axis.
        #[test]
        fn apply_inverts_gain_and_bias(
            b in proptest::array::uniform3(-1.0f64..1.0),
            g in proptest::array::uniform3(0.5f64..1.5),
            f in proptest::array::uniform3(-20.0f64..20.0),
        ) {
            let cal = AccelCalibration::new(Vector3::from(b), Vector3::from(g)).unwrap();
            let f = Vector3::from(f);
            let raw = f.component_mul(&cal.gain) + cal.bias_mps2;
            prop_assert!((cal.apply(&raw).unwrap() - f).amax() < 1e-12 * (1.0 + f.amax()));
        }

        /// No panic on any input; a non-finite reading or gain, or a non-positive gain, is a
        /// typed error.
        #[test]
        fn typed_errors_on_any_input(x in proptest::num::f64::ANY, g in proptest::num::f64::ANY) {
            let ok_gain = g.is_finite() && g > 0.0;
            let loaded = AccelCalibration { bias_mps2: Vector3::zeros(), gain: Vector3::new(1.0, g, 1.0) };
            prop_assert_eq!(loaded.validate().is_ok(), ok_gain);
            let r = AccelCalibration::default().apply(&Vector3::new(x, 0.0, -9.8));
            prop_assert_eq!(r.is_ok(), x.is_finite());
            if !x.is_finite() {
                let non_finite = matches!(r, Err(Error::NonFinite { .. }));
                prop_assert!(non_finite);
            }
            let r = loaded.apply(&Vector3::new(0.0, x, 0.0));
            let fits = (x / g).is_finite();
            prop_assert_eq!(r.is_ok(), ok_gain && x.is_finite() && fits);
        }
    }
}
