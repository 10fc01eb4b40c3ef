//! Odometer calibration: raw wheel distances → true wheel path lengths.
//!
//! Inverts the two deterministic errors of [`crate::OdometerModel`]: each wheel's scale
//! (tyre radius, pulses per revolution), then the speed-dependent inflation of the difference
//! `(1 + aV²)` (US 4,788,645 eq. 2/8), which leaves the mean of the two wheels unchanged.

use serde::{Deserialize, Serialize};
use truenorth_core::{Calibration, Result, Validate, check_finite, check_positive};

use crate::WheelDistances;
use crate::differential::speed_factor;

/// What the calibration needs: one step's raw wheel distances and the mean speed of the two
/// odometer wheels over the step (`|AD| / dt`, as the odometer itself can measure it).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct OdometerRaw {
    /// Raw left-wheel distance over the step, m.
    pub dist_l_m: f64,
    /// Raw right-wheel distance over the step, m.
    pub dist_r_m: f64,
    /// Mean speed of the two odometer wheels, m/s.
    pub wheel_speed_mps: f64,
}

/// Per-wheel gains and the speed coefficient `a`.
///
/// `raw = gain · (mean ± half_difference·(1 + aV²))`, so the calibration divides by the gain,
/// then shrinks the difference by `1 + aV²`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OdometerCalibration {
    /// Raw metres per true metre, left wheel (1 + scale error).
    pub gain_l: f64,
    /// Raw metres per true metre, right wheel.
    pub gain_r: f64,
    /// The `a` of `1 + aV²`, s²/m².
    pub speed_coeff_s2_per_m2: f64,
}

impl Default for OdometerCalibration {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl OdometerCalibration {
    /// Gains 1, `a` = 0.
    pub const IDENTITY: Self = Self {
        gain_l: 1.0,
        gain_r: 1.0,
        speed_coeff_s2_per_m2: 0.0,
    };

    /// A calibration with positive finite gains and a finite `a`.
    pub fn new(gain_l: f64, gain_r: f64, speed_coeff_s2_per_m2: f64) -> Result<Self> {
        let cal = Self {
            gain_l,
            gain_r,
            speed_coeff_s2_per_m2,
        };
        cal.validate()?;
        Ok(cal)
    }

    /// Removes the scale errors only: the two wheels' distances in true metres, but with the
    /// speed-dependent difference still in (needed to estimate the speed itself).
    pub fn unscale(&self, dist_l_m: f64, dist_r_m: f64) -> Result<WheelDistances> {
        self.validate()?;
        let l = check_finite("left wheel distance", dist_l_m)?;
        let r = check_finite("right wheel distance", dist_r_m)?;
        Ok(WheelDistances {
            left_m: check_finite("unscaled left distance (too large)", l / self.gain_l)?,
            right_m: check_finite("unscaled right distance (too large)", r / self.gain_r)?,
        })
    }
}

impl Validate for OdometerCalibration {
    /// Both gains positive and finite, `a` finite. The fields are public (a calibration is
    /// loaded from disk), so [`Calibration::apply`] checks again.
    fn validate(&self) -> Result<()> {
        check_positive("odometer gain_l", self.gain_l)?;
        check_positive("odometer gain_r", self.gain_r)?;
        check_finite("speed coefficient a (s²/m²)", self.speed_coeff_s2_per_m2)?;
        Ok(())
    }
}

impl Calibration for OdometerCalibration {
    type Raw = OdometerRaw;
    type Physical = WheelDistances;

    /// The true wheel path lengths, or a typed error (non-finite input, invalid calibration,
    /// `1 + aV² ≤ 0`).
    fn apply(&self, raw: &OdometerRaw) -> Result<WheelDistances> {
        let u = self.unscale(raw.dist_l_m, raw.dist_r_m)?;
        let factor = speed_factor(self.speed_coeff_s2_per_m2, raw.wheel_speed_mps)?;
        let mean = 0.5 * (u.left_m + u.right_m);
        let half_diff = 0.5 * (u.left_m - u.right_m) / factor;
        Ok(WheelDistances {
            left_m: check_finite(
                "calibrated left distance (inputs too large)",
                mean + half_diff,
            )?,
            right_m: check_finite(
                "calibrated right distance (inputs too large)",
                mean - half_diff,
            )?,
        })
    }
}
