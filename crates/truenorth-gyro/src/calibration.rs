//! Gyro calibration: zero (bias) and scale, raw rate → physical rate: one axis of
//! [`truenorth_core::InertialCalibration`] ([`axis_calibrated`]) with a gain for each
//! direction of turn.
//!
//! The zero is what the calibrators estimate at rest (EP 0640207 claim 8/9: average the output
//! while stationary) and the scale is the conversion constant of the full-turn method
//! (claim 1). A scale may differ for positive and negative rates, because a cheap gyro's gain
//! often does.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use truenorth_core::{
    Calibration, Result, Validate, axis_calibrated, check_finite, check_positive,
};

/// Zero and gain of one gyro axis: `rate = (raw − zero) / gain`, with `gain_pos` used when
/// `raw − zero ≥ 0` and `gain_neg` otherwise. Gains are dimensionless (raw rad/s per true
/// rad/s) and must be positive, so the sign of `raw − zero` is the sign of the true rate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GyroCalibration {
    /// Raw output at zero rate, rad/s.
    pub zero_rps: f64,
    /// Gain for positive rates (right turns for a yaw gyro).
    pub gain_pos: f64,
    /// Gain for negative rates (left turns for a yaw gyro).
    pub gain_neg: f64,
}

impl Default for GyroCalibration {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl GyroCalibration {
    /// Zero 0, gain 1: passes the raw rate through.
    pub const IDENTITY: Self = Self {
        zero_rps: 0.0,
        gain_pos: 1.0,
        gain_neg: 1.0,
    };

    /// One zero and one gain for both directions.
    pub fn new(zero_rps: f64, gain: f64) -> Result<Self> {
        Self::asymmetric(zero_rps, gain, gain)
    }

    /// Separate gains for positive and negative rates.
    pub fn asymmetric(zero_rps: f64, gain_pos: f64, gain_neg: f64) -> Result<Self> {
        let cal = Self {
            zero_rps,
            gain_pos,
            gain_neg,
        };
        cal.validate()?;
        Ok(cal)
    }

    /// `(raw − zero) / gain` for a valid calibration and a finite `raw_rps`.
    #[inline]
    fn apply_unchecked(&self, raw_rps: f64) -> f64 {
        axis_calibrated(raw_rps, self.zero_rps, self.gain_pos, self.gain_neg)
    }
}

impl Validate for GyroCalibration {
    /// The zero finite and both gains positive and finite. The fields are public (a
    /// calibration is loaded from disk), so [`Calibration::apply`] checks again.
    fn validate(&self) -> Result<()> {
        check_finite("gyro calibration zero_rps", self.zero_rps)?;
        check_positive("gyro calibration gain_pos", self.gain_pos)?;
        check_positive("gyro calibration gain_neg", self.gain_neg)?;
        Ok(())
    }
}

impl Calibration for GyroCalibration {
    type Raw = f64;
    type Physical = f64;

    /// `(raw − zero) / gain`, or a typed error if `raw` is not finite, the calibration is
    /// invalid, or the result overflows.
    fn apply(&self, raw: &f64) -> Result<f64> {
        check_finite("raw gyro rate", *raw)?;
        self.validate()?;
        check_finite(
            "calibrated gyro rate (reading too large)",
            self.apply_unchecked(*raw),
        )
    }
}

/// Calibration of a three-axis gyro: one [`GyroCalibration`] per axis (x, y, z).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Gyro3Calibration {
    /// Per-axis calibrations, x, y, z.
    pub axes: [GyroCalibration; 3],
}

impl Validate for Gyro3Calibration {
    /// Every axis valid (see [`GyroCalibration`]).
    fn validate(&self) -> Result<()> {
        self.axes.iter().try_for_each(Validate::validate)
    }
}

impl Calibration for Gyro3Calibration {
    type Raw = Vector3<f64>;
    type Physical = Vector3<f64>;

    /// Each axis through its own [`GyroCalibration`]; a typed error naming the first bad
    /// component.
    fn apply(&self, raw: &Vector3<f64>) -> Result<Vector3<f64>> {
        let [x, y, z] = &self.axes;
        Ok(Vector3::new(
            x.apply(&raw.x)?,
            y.apply(&raw.y)?,
            z.apply(&raw.z)?,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::Error;

    proptest! {
        #[test]
        fn apply_inverts_gain_and_zero(
            zero in -1.0f64..1.0, gp in 0.5f64..1.5, gn in 0.5f64..1.5, rate in -10.0f64..10.0,
        ) {
            let cal = GyroCalibration::asymmetric(zero, gp, gn).unwrap();
            let raw = if rate >= 0.0 { gp * rate } else { gn * rate } + zero;
            prop_assert!((cal.apply(&raw).unwrap() - rate).abs() < 1e-12 * (1.0 + rate.abs()));
        }

        #[test]
        fn never_panics(raw in proptest::num::f64::ANY, g in proptest::num::f64::ANY) {
            prop_assert_eq!(GyroCalibration::IDENTITY.apply(&raw).is_ok(), raw.is_finite());
            let ok = g.is_finite() && g > 0.0;
            prop_assert_eq!(GyroCalibration::new(0.0, g).is_ok(), ok);
            // A deserialised calibration with a bad gain is refused by apply, not divided by.
            let loaded = GyroCalibration { zero_rps: 0.0, gain_pos: g, gain_neg: g };
            let r = loaded.apply(&raw);
            // Refused exactly when something is invalid or the quotient overflows.
            let fits = (raw / g).is_finite();
            prop_assert_eq!(r.is_ok(), ok && raw.is_finite() && fits);
            if let Err(e) = r {
                let typed = matches!(e, Error::NonFinite { .. } | Error::OutOfRange { .. });
                prop_assert!(typed, "{e:?}");
            }
            let three = Gyro3Calibration { axes: [GyroCalibration::IDENTITY, loaded, GyroCalibration::IDENTITY] };
            prop_assert_eq!(three.apply(&Vector3::new(0.0, raw, 0.0)).is_ok(), ok && raw.is_finite() && fits);
        }
    }
}
