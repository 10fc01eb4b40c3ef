//! One step of the odometer wheels under the current calibration estimate: heading change,
//! the rear-axle distance, and how both depend on the calibration states.
//!
//! Per step (US 4,788,645 eqs. 2/8, 3/14): the raw wheel increments are divided by their
//! gains `1 ± δ/2`, their difference by `1 + aV²`, and the result by the track — fixed for
//! rear wheels, the effective track `T_E(ΔD/AD)` from the patent's look-up table for
//! Ackermann-steered front wheels. Front wheels also travel further than the rear axle in a
//! turn: the front-axle midpoint runs on radius `√(R² + B²)` where the rear-axle centre runs
//! on `R`, so the rear-axle distance is `√(AD² − (B·Δθ)²)`.

use truenorth_core::{Error, Result, Validate, VehicleSample};
use truenorth_odometer::{
    EffectiveTrack, EffectiveTrackTable, OdometerWheels, PatentAckermannTrack,
};

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Fastest wheel speed a sample may imply, m/s (360 km/h, beyond any road vehicle):
/// distances that jump further are a counter that wrapped or was reset, not motion.
pub const MAX_WHEEL_SPEED_MPS: f64 = 100.0;

/// Entries of the front-wheel effective-track table.
const TABLE_ENTRIES: usize = 64;

/// Ackermann-steered front wheels: the effective track's table and the wheelbase.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Steered {
    table: EffectiveTrackTable<TABLE_ENTRIES>,
    wheelbase_m: f64,
}

/// What one step of the wheels gives.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WheelStep {
    /// Distance of the rear-axle centre, m (negative reversing).
    pub ds_m: f64,
    /// Heading change, rad, positive right.
    pub heading_change_rad: f64,
    /// ∂(heading change)/∂δ, rad.
    pub d_heading_d_diff: f64,
    /// ∂(heading change)/∂a, rad·m²/s².
    pub d_heading_d_speed_coeff: f64,
    /// ∂(heading change)/∂ε, the track's relative error, rad.
    pub d_heading_d_track_scale: f64,
    /// Mean speed of the odometer wheels, m/s.
    pub speed_mps: f64,
    /// Whether either wheel's reading changed.
    pub moved: bool,
}

/// The wheel calibration states a step is computed with.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WheelCalibration {
    /// Differential scale δ: left gain `1 + δ/2`, right `1 − δ/2`.
    pub diff: f64,
    /// Speed coefficient `a`, s²/m².
    pub speed_coeff: f64,
    /// Relative error ε of the effective track.
    pub track_scale: f64,
}

/// Cumulative wheel distances → [`WheelStep`]s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelOdometry {
    /// The straight-ahead track, m.
    track_m: f64,
    /// Present when the odometer wheels steer.
    steered: Option<Steered>,
    last: Option<(f64, f64)>,
}

impl WheelOdometry {
    /// Odometry on `wheels`; the front-wheel table covers the patent formula's whole range.
    pub fn new(wheels: OdometerWheels) -> Result<Self> {
        wheels.validate()?;
        let (track_m, steered) = match wheels {
            OdometerWheels::Rear { track_m } => (track_m, None),
            OdometerWheels::Front(p) => {
                let formula = PatentAckermannTrack::from_params(&p)?;
                let steered = Steered {
                    table: EffectiveTrackTable::build(&formula, formula.max_ratio())?,
                    wheelbase_m: p.wheelbase_m,
                };
                (p.track_m, Some(steered))
            }
        };
        Ok(Self {
            track_m,
            steered,
            last: None,
        })
    }

    /// Forgets the last reading.
    pub fn reset(&mut self) {
        self.last = None;
    }

    /// Refuses `sample` if its distances, against the previous reading taken at `last_t_s`,
    /// imply a wheel faster than [`MAX_WHEEL_SPEED_MPS`]. Changes nothing either way; a
    /// timestamp that does not increase is left to the caller's clock.
    pub fn check_speed(&self, sample: &VehicleSample, last_t_s: Option<f64>) -> Result<()> {
        let (Some((l0, r0)), Some(t0)) = (self.last, last_t_s) else {
            return Ok(());
        };
        let dt = sample.t_s - t0;
        let travel = (sample.dist_l_m - l0)
            .abs()
            .max((sample.dist_r_m - r0).abs());
        if dt > 0.0 && travel > MAX_WHEEL_SPEED_MPS * dt {
            return Err(Error::OutOfRange {
                what: "wheel speed implied by the distances, m/s (a counter that wrapped or was reset: start a new drive there)",
                value: travel / dt,
                min: 0.0,
                max: MAX_WHEEL_SPEED_MPS,
            });
        }
        Ok(())
    }

    /// The step from the previous cumulative reading to this one (`None` for the first),
    /// with differential scale `diff`, speed coefficient `speed_coeff` and the track's
    /// relative error `track_scale`. Inputs are finite and `dt_s > 0` (checked by the
    /// caller).
    pub fn step(
        &mut self,
        dist_l_m: f64,
        dist_r_m: f64,
        dt_s: f64,
        cal: &WheelCalibration,
    ) -> Option<WheelStep> {
        let WheelCalibration {
            diff,
            speed_coeff,
            track_scale,
        } = *cal;
        let (l0, r0) = self.last.replace((dist_l_m, dist_r_m))?;
        let (raw_l, raw_r) = (dist_l_m - l0, dist_r_m - r0);
        let moved = raw_l != 0.0 || raw_r != 0.0;
        let l = raw_l / (1.0 + 0.5 * diff);
        let r = raw_r / (1.0 + -0.5 * diff);
        let mean = 0.5 * (l + r);
        let speed_mps = mean.abs() / dt_s;
        let factor = (1.0 + speed_coeff * speed_mps * speed_mps).max(0.5);
        let delta = (l - r) / factor;
        let track_m = match &self.steered {
            None => self.track_m,
            Some(s) => {
                // A step too short to resolve the turn (a pulse or two while creeping) can
                // show a ratio past the vehicle's lock; the tightest turn stands in for it.
                let ratio = if mean != 0.0 { delta / mean } else { 0.0 };
                let c = ratio.abs().min(s.table.max_ratio());
                s.table.effective_track_m(c).unwrap_or(self.track_m)
            }
        };
        let scale = (1.0 + track_scale).max(0.5);
        let heading = delta / (track_m * scale);
        let ds_m = match &self.steered {
            None => mean,
            Some(s) => {
                let lateral = s.wheelbase_m * heading;
                mean.signum() * (mean * mean - lateral * lateral).max(0.0).sqrt()
            }
        };
        Some(WheelStep {
            ds_m,
            heading_change_rad: heading,
            // u_l − u_r falls by the mean distance per unit δ (first order).
            d_heading_d_diff: -mean / (factor * track_m * scale),
            d_heading_d_speed_coeff: -heading * speed_mps * speed_mps / factor,
            d_heading_d_track_scale: -heading / scale,
            speed_mps,
            moved,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use truenorth_odometer::AckermannParams;

    const NONE: WheelCalibration = WheelCalibration {
        diff: 0.0,
        speed_coeff: 0.0,
        track_scale: 0.0,
    };

    #[test]
    fn rear_wheels_give_the_plain_formula_and_its_derivatives() {
        let mut w = WheelOdometry::new(OdometerWheels::Rear { track_m: 1.5 }).unwrap();
        assert!(w.step(0.0, 0.0, 0.1, &NONE).is_none());
        let s = w.step(1.03, 0.97, 0.1, &NONE).unwrap();
        assert!((s.heading_change_rad - 0.04).abs() < 1e-12);
        assert!((s.ds_m - 1.0).abs() < 1e-12);
        assert!((s.speed_mps - 10.0).abs() < 1e-12);
        // Numerical derivatives agree with the analytic ones.
        let h = 1e-7;
        let mut a = WheelOdometry::new(OdometerWheels::Rear { track_m: 1.5 }).unwrap();
        let mut b = a;
        a.step(0.0, 0.0, 0.1, &NONE);
        b.step(0.0, 0.0, 0.1, &NONE);
        let mut c = b;
        let up = a
            .step(1.03, 0.97, 0.1, &WheelCalibration { diff: h, ..NONE })
            .unwrap()
            .heading_change_rad;
        assert!(((up - s.heading_change_rad) / h - s.d_heading_d_diff).abs() < 1e-5);
        let up = b
            .step(
                1.03,
                0.97,
                0.1,
                &WheelCalibration {
                    speed_coeff: h,
                    ..NONE
                },
            )
            .unwrap()
            .heading_change_rad;
        assert!(((up - s.heading_change_rad) / h - s.d_heading_d_speed_coeff).abs() < 1e-4);
        let up = c
            .step(
                1.03,
                0.97,
                0.1,
                &WheelCalibration {
                    track_scale: h,
                    ..NONE
                },
            )
            .unwrap()
            .heading_change_rad;
        assert!(((up - s.heading_change_rad) / h - s.d_heading_d_track_scale).abs() < 1e-5);
    }

    #[test]
    fn front_wheels_shrink_the_track_and_the_distance_in_a_turn() {
        let car = AckermannParams {
            wheelbase_m: 2.7,
            track_m: 1.55,
            kingpin_offset_m: 0.1,
        };
        let geometry = truenorth_odometer::AckermannGeometry::new(car).unwrap();
        let radius = 8.0;
        let paths = geometry.wheel_paths_m(10.0, 1.0 / radius).unwrap();
        let mut w = WheelOdometry::new(OdometerWheels::Front(car)).unwrap();
        w.step(0.0, 0.0, 1.0, &NONE);
        let s = w.step(paths.left_m, paths.right_m, 1.0, &NONE).unwrap();
        // True heading change 10/8 rad; the patent's track is within 0.1 % at this radius.
        assert!(
            (s.heading_change_rad / 1.25 - 1.0).abs() < 1e-3,
            "{}",
            s.heading_change_rad
        );
        assert!((s.ds_m / 10.0 - 1.0).abs() < 2e-3, "{}", s.ds_m);
        // A ratio past full lock is clamped, never NaN.
        let s = w
            .step(paths.left_m + 0.06, paths.right_m, 1.0, &NONE)
            .unwrap();
        assert!(s.heading_change_rad.is_finite() && s.ds_m.is_finite());
    }
}
