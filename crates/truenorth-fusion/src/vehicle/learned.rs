//! What the vehicle estimator has learned about its sensors, as plain data: saved when the
//! ignition goes off and given back at the next start (EP 0634001 claims 13-14 store the
//! compass's ellipse the same way), so a drive starts calibrated.

use serde::{Deserialize, Serialize};
use truenorth_compass::CompassCalibration2d;
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{
    CompassQuality, Error, Result, Validate, check_finite, check_positive, check_range,
};

use super::compass_monitor::CompassFix;
use super::nav_filter::{
    BIAS, DIM, GAIN_NEG, GAIN_POS, NavFilter, SPEED_COEFF, TRACK_SCALE, WHEEL_DIFF, WHEEL_LAG,
    WHEEL_SCALE,
};

/// Share of a state's prior standard deviation that it may drift between two drives.
const DRIFT_SHARE: f64 = 0.1;

/// The physical range of each learned state, as (low, high): what a stored calibration may
/// hold, and where a snapshot of the filter is kept — the filter can carry a state past its
/// bound between two projections onto it (a fix's correction moving the wheels' delay below
/// zero), and the snapshot is restored by a replay.
const BIAS_RANGE_RPS: (f64, f64) = (-1.75, 1.75);
const GAIN_RANGE: (f64, f64) = (-0.5, 0.5);
const WHEEL_DIFF_RANGE: (f64, f64) = (-0.5, 0.5);
const TRACK_SCALE_RANGE: (f64, f64) = (-0.5, 2.0);
const SPEED_COEFF_RANGE_S2_PER_M2: (f64, f64) = (0.0, 1e-2);
const WHEEL_SCALE_RANGE: (f64, f64) = (-0.5, 0.5);
const WHEEL_LAG_RANGE_S: (f64, f64) = (0.0, 2.0);

/// A learned value and its standard deviation (0: never learned, the prior stands; the
/// default).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Learned {
    /// The value.
    pub value: f64,
    /// Its standard deviation (> 0).
    pub sigma: f64,
}

impl Learned {
    /// State `i` of `filter`, kept within `(low, high)`.
    fn of(filter: &NavFilter, i: usize, (low, high): (f64, f64)) -> Self {
        Self {
            value: filter.x[i].clamp(low, high),
            sigma: filter.sigma(i),
        }
    }

    fn check(&self, what: &'static str) -> Result<()> {
        check_finite(what, self.value)?;
        check_range(what, self.sigma, 0.0, f64::MAX)?;
        Ok(())
    }
}

/// The compass calibration learned, with its quality report.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnedCompass {
    /// Hard and soft iron.
    pub calibration: CompassCalibration2d,
    /// The quality report of the fit.
    pub quality: CompassQuality,
}

/// Everything the vehicle estimator learns about its sensors. Units: rad/s for the gyro
/// bias, dimensionless for gains and scales, s²/m² for the speed coefficient.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleCalibration {
    /// The compass's hard and soft iron, if learned.
    pub compass: Option<LearnedCompass>,
    /// Gyro bias, rad/s (it wanders with temperature: restored with a wider sigma).
    pub gyro_bias_rps: Learned,
    /// Gyro gain error for right turns (gain `1 + this`).
    pub gyro_gain_error_right: Learned,
    /// Gyro gain error for left turns.
    pub gyro_gain_error_left: Learned,
    /// Differential wheel scale δ (left gain `1 + δ/2`, right `1 − δ/2`).
    pub wheel_diff: Learned,
    /// Relative error of the wheels' effective track.
    pub track_scale: Learned,
    /// Speed coefficient `a` of `1 + aV²` (US 4,788,645 eq. 8), s²/m².
    pub speed_coeff_s2_per_m2: Learned,
    /// The odometer's mean scale error k (distance = reading × (1 + k)), learned from
    /// satellite fixes. Absent from a file written before it was learned: never learned.
    #[serde(default)]
    pub wheel_scale: Learned,
    /// How far the wheels' readings trail the gyro's, s. Absent from a file written before
    /// it was learned: never learned.
    #[serde(default)]
    pub wheel_lag_s: Learned,
}

impl VehicleCalibration {
    /// The calibration states of `filter` and the compass calibration in use.
    pub fn from_filter(filter: &NavFilter, compass: Option<&CompassFix>) -> Self {
        Self {
            compass: compass.map(|f| LearnedCompass {
                calibration: f.calibration,
                quality: f.quality,
            }),
            gyro_bias_rps: Learned::of(filter, BIAS, BIAS_RANGE_RPS),
            gyro_gain_error_right: Learned::of(filter, GAIN_POS, GAIN_RANGE),
            gyro_gain_error_left: Learned::of(filter, GAIN_NEG, GAIN_RANGE),
            wheel_diff: Learned::of(filter, WHEEL_DIFF, WHEEL_DIFF_RANGE),
            track_scale: Learned::of(filter, TRACK_SCALE, TRACK_SCALE_RANGE),
            speed_coeff_s2_per_m2: Learned::of(filter, SPEED_COEFF, SPEED_COEFF_RANGE_S2_PER_M2),
            wheel_scale: Learned::of(filter, WHEEL_SCALE, WHEEL_SCALE_RANGE),
            wheel_lag_s: Learned::of(filter, WHEEL_LAG, WHEEL_LAG_RANGE_S),
        }
    }

    /// Writes the learned calibration states into `filter`, uncorrelated. Each sigma is
    /// widened by a tenth of its prior's, what a state may drift between drives (a MEMS
    /// gyro's turn-on bias repeatability, a tyre's pressure), and kept within the prior's:
    /// a state never learned comes back as it started, and a replay does not count the
    /// same readings' information twice. `prior_sigma` holds each state's prior standard
    /// deviation (0: not learned, left as the filter has it).
    pub fn to_filter(&self, filter: &mut NavFilter, prior_sigma: &[f64; DIM]) {
        for (i, l) in [
            (BIAS, self.gyro_bias_rps),
            (GAIN_POS, self.gyro_gain_error_right),
            (GAIN_NEG, self.gyro_gain_error_left),
            (WHEEL_DIFF, self.wheel_diff),
            (TRACK_SCALE, self.track_scale),
            (SPEED_COEFF, self.speed_coeff_s2_per_m2),
            (WHEEL_SCALE, self.wheel_scale),
            (WHEEL_LAG, self.wheel_lag_s),
        ] {
            let prior = prior_sigma[i];
            if l.sigma > 0.0 && prior > 0.0 {
                filter.x[i] = l.value;
                let drift = DRIFT_SHARE * prior;
                filter.reset_state(i, (l.sigma * l.sigma + drift * drift).sqrt().min(prior));
            }
        }
    }

    /// The compass calibration as the estimator uses it.
    pub fn compass_fix(&self) -> Option<CompassFix> {
        self.compass.map(|c| {
            CompassFix::from_solution(&truenorth_core::Solution {
                params: c.calibration,
                quality: c.quality,
            })
        })
    }
}

impl Validate for VehicleCalibration {
    /// Every value finite, every sigma non-negative; gains, the wheels' scale difference
    /// and their mean scale error within ±50 %, the wheels' delay 0–2 s, the effective track 0.5–3 times the physical one, the
    /// speed coefficient in 0–0.01 s²/m²; the compass's soft iron invertible, not a
    /// reflection, and the field positive.
    fn validate(&self) -> Result<()> {
        self.gyro_bias_rps.check("gyro_bias_rps")?;
        check_range(
            "gyro_bias_rps (a bias beyond 100 °/s is no gyro's)",
            self.gyro_bias_rps.value,
            BIAS_RANGE_RPS.0,
            BIAS_RANGE_RPS.1,
        )?;
        for (what, l, (lo, hi)) in [
            (
                "gyro_gain_error_right",
                self.gyro_gain_error_right,
                GAIN_RANGE,
            ),
            (
                "gyro_gain_error_left",
                self.gyro_gain_error_left,
                GAIN_RANGE,
            ),
            ("wheel_diff", self.wheel_diff, WHEEL_DIFF_RANGE),
            ("track_scale", self.track_scale, TRACK_SCALE_RANGE),
            (
                "speed_coeff_s2_per_m2",
                self.speed_coeff_s2_per_m2,
                SPEED_COEFF_RANGE_S2_PER_M2,
            ),
            ("wheel_scale", self.wheel_scale, WHEEL_SCALE_RANGE),
            ("wheel_lag_s", self.wheel_lag_s, WHEEL_LAG_RANGE_S),
        ] {
            l.check(what)?;
            check_range(what, l.value, lo, hi)?;
        }
        if let Some(c) = &self.compass {
            for v in c
                .calibration
                .hard_iron
                .iter()
                .chain(c.calibration.soft_iron.iter())
            {
                check_finite("compass calibration", *v)?;
            }
            check_positive("compass field_magnitude", c.quality.field_magnitude)?;
            let det = c.calibration.soft_iron.determinant();
            if det.abs() < f64::EPSILON {
                return Err(Error::Degenerate {
                    reason: "the stored compass soft iron is singular; recalibrate the compass",
                });
            }
            if det < 0.0 {
                return Err(Error::Degenerate {
                    reason: "the stored compass soft iron is a reflection (negative determinant), which no iron makes: the compass axes were swapped or one negated; recalibrate",
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A snapshot of a filter whose states stand past their physical bounds (the wheels'
    /// delay a hair below zero after a fix's correction, a speed coefficient below zero)
    /// is a calibration that validates, so a replay restoring it cannot fail: a drive with
    /// fixes 2 s late once stopped with "wheel_lag_s = -1.092e-4 is outside its valid range".
    #[test]
    fn a_snapshot_past_the_bounds_still_validates() {
        let mut x = [0.0; DIM];
        (x[WHEEL_LAG], x[SPEED_COEFF], x[GAIN_POS], x[BIAS]) = (-1.1e-4, -1e-9, 0.7, -3.0);
        let filter = NavFilter::new(x, [0.1; DIM]);
        let c = VehicleCalibration::from_filter(&filter, None);
        c.validate().unwrap();
        assert_eq!(c.wheel_lag_s.value, 0.0);
        assert_eq!(c.gyro_gain_error_right.value, GAIN_RANGE.1);
        assert_eq!(c.gyro_bias_rps.value, BIAS_RANGE_RPS.0);
    }
}
