//! One step of the odometer wheels under the current calibration estimate: heading change,
//! the rear-axle distance, and how both depend on the calibration states.
//!
//! Per step (US 4,788,645 eqs. 2/8, 3/14, computed by [`truenorth_odometer::OdometryStep`]):
//! the raw wheel increments are divided by their gains `1 ± δ/2`, their difference by
//! `1 + aV²`, and the result by the track — fixed for an unsteered axle, the effective track
//! `T_E(ΔD/AD)` from a look-up table for Ackermann-steered front wheels. What is the
//! estimator's own: the floors on the learned factors, the steered wheels' averaged
//! curvature and the rear-axle distance. Front wheels also travel further than the rear axle in a
//! turn: the front-axle midpoint runs on radius `√(R² + B²)` where the rear-axle centre runs
//! on `R`, so the rear-axle distance is `√(AD² − (B·Δθ)²)`.

use truenorth_core::{Error, Result, Validate, WheelReading};
use truenorth_odometer::{
    AckermannGeometry, EffectiveTrack, EffectiveTrackTable, OdometerWheels, OdometryStep,
    PatentAckermannTrack, WheelDistances, differential_gains,
};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Fastest wheel speed a sample may imply, m/s (360 km/h, beyond any road vehicle):
/// distances that jump further are a counter that wrapped or was reset, not motion.
pub const MAX_WHEEL_SPEED_MPS: f64 = 100.0;

/// Entries of the front-wheel effective-track table.
const TABLE_ENTRIES: usize = 64;

/// Share of the exact geometry's peak ratio that its table covers: the ratio turns back
/// past the peak, and near it the track changes too fast for a table (the peak lies
/// beyond any real car's lock, `truenorth-odometer`'s `ackermann_tests.rs`).
const EXACT_TABLE_SHARE: f64 = 0.97;

/// Which effective track of steered front wheels the odometry uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrackModel {
    /// The exact rigid-body geometry ([`AckermannGeometry`]).
    Exact,
    /// US 4,788,645's closed form, eq. 3/14 ([`PatentAckermannTrack`]), as the seed
    /// document has it.
    Patent,
}

/// Ackermann-steered front wheels: the effective track's table and the wheelbase.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Steered {
    table: EffectiveTrackTable<TABLE_ENTRIES>,
    wheelbase_m: f64,
    /// The path's curvature, averaged over the last few metres, 1/m: the front axle's
    /// extra travel is second order in it, so the pulses' noise in one step's turn would
    /// shorten every step on a straight (by 0.7 % with 4 cm pulses at 25 Hz); a car's
    /// curvature cannot change faster than its steering turns.
    curvature_per_m: f64,
}

/// Floor of the speed factor `1 + aV²`: a learned `a` that strays negative at speed must
/// not shrink the difference to nothing.
const MIN_SPEED_FACTOR: f64 = 0.5;

/// Floor of the track factor `1 + ε`.
const MIN_TRACK_SCALE: f64 = 0.5;

/// Distance over which the curvature of steered wheels is averaged, m.
const CURVATURE_SMOOTHING_M: f64 = 3.0;

/// What one step of the wheels gives.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WheelStep {
    /// Time since the previous wheel reading, s.
    pub dt_s: f64,
    /// Distance of the rear-axle centre, m (negative reversing).
    pub ds_m: f64,
    /// Heading change, rad, positive right.
    pub heading_change_rad: f64,
    /// How tight the turn is, as the ratio c = ΔD/AD of a steady turn (about T/R, signed):
    /// for steered wheels from the curvature averaged over the last metres (one step's
    /// pulses can show any ratio while creeping), within the vehicle's lock.
    pub ratio: f64,
    /// ∂(heading change)/∂δ, rad.
    pub d_heading_d_diff: f64,
    /// ∂(heading change)/∂a, rad·m²/s².
    pub d_heading_d_speed_coeff: f64,
    /// ∂(heading change)/∂ε, the track's relative error, rad.
    pub d_heading_d_track_scale: f64,
    /// Mean speed of the odometer wheels, m/s.
    pub speed_mps: f64,
    /// Each wheel's speed over the step as read (left, right), m/s.
    pub side_speeds_mps: [f64; 2],
    /// The effective track the heading change was computed with, m.
    pub effective_track_m: f64,
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

/// What a [`WheelOdometry`] has seen, as plain data ([`WheelOdometry::state`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WheelOdometryState {
    /// The last reading and its time, s.
    pub last: Option<(f64, WheelReading)>,
    /// The steered wheels' averaged curvature, 1/m (0 for wheels that are not steered).
    pub curvature_per_m: f64,
}

/// Cumulative wheel distances → [`WheelStep`]s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelOdometry {
    /// The straight-ahead track, m.
    track_m: f64,
    /// Present when the odometer wheels steer.
    steered: Option<Steered>,
    /// The last reading and its time.
    last: Option<(f64, WheelReading)>,
}

impl WheelOdometry {
    /// Odometry on `wheels`, with steered front wheels' track from `model` (over the whole
    /// range of the patent's formula, or up to near the exact geometry's peak ratio).
    pub fn new(wheels: OdometerWheels, model: TrackModel) -> Result<Self> {
        wheels.validate()?;
        let steered = match wheels {
            OdometerWheels::Front(p) => {
                let table = match model {
                    TrackModel::Patent => {
                        let formula = PatentAckermannTrack::from_params(&p)?;
                        EffectiveTrackTable::build(&formula, formula.max_ratio())?
                    }
                    TrackModel::Exact => {
                        let exact = AckermannGeometry::new(p)?;
                        EffectiveTrackTable::build(&exact, EXACT_TABLE_SHARE * exact.max_ratio())?
                    }
                };
                Some(Steered {
                    table,
                    wheelbase_m: p.wheelbase_m,
                    curvature_per_m: 0.0,
                })
            }
            _ => None,
        };
        Ok(Self {
            track_m: wheels.track_m(),
            steered,
            last: None,
        })
    }

    /// Forgets the last reading.
    pub fn reset(&mut self) {
        self.last = None;
        if let Some(s) = &mut self.steered {
            s.curvature_per_m = 0.0;
        }
    }

    /// What the odometry has seen: the last reading and the steered wheels' averaged
    /// curvature (the track table is rebuilt from the wheels' description).
    pub fn state(&self) -> WheelOdometryState {
        WheelOdometryState {
            last: self.last,
            curvature_per_m: self.steered.map_or(0.0, |s| s.curvature_per_m),
        }
    }

    /// The odometry for `wheels` under `model`, continuing from `state`. A curvature on
    /// wheels that are not steered is refused: this odometry could not have written it.
    pub fn with_state(
        wheels: OdometerWheels,
        model: TrackModel,
        state: WheelOdometryState,
    ) -> Result<Self> {
        let mut w = Self::new(wheels, model)?;
        match &mut w.steered {
            Some(s) => s.curvature_per_m = state.curvature_per_m,
            None if state.curvature_per_m != 0.0 => {
                return Err(Error::InvalidSnapshot {
                    reason: "a curvature saved for wheels that are not steered",
                });
            }
            None => {}
        }
        w.last = state.last;
        Ok(w)
    }

    /// The time of the last reading taken, if any.
    pub fn last_s(&self) -> Option<f64> {
        self.last.map(|(t, _)| t)
    }

    /// Refuses `reading` at `t_s` if, against the previous reading, it implies a wheel
    /// faster than [`MAX_WHEEL_SPEED_MPS`]. Changes nothing either way; a timestamp that
    /// does not increase is left to the caller's clock.
    pub fn check_speed(&self, t_s: f64, reading: &WheelReading) -> Result<()> {
        let Some((t0, w0)) = self.last else {
            return Ok(());
        };
        let dt = t_s - t0;
        let travel = (reading.dist_l_m - w0.dist_l_m)
            .abs()
            .max((reading.dist_r_m - w0.dist_r_m).abs());
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

    /// The step from the previous reading to `reading` at `t_s` (`None` for the first),
    /// under calibration `cal`. Inputs are finite and `t_s` later than the previous
    /// reading's (checked by the caller).
    pub fn step(
        &mut self,
        t_s: f64,
        reading: WheelReading,
        cal: &WheelCalibration,
    ) -> Option<WheelStep> {
        let WheelCalibration {
            diff,
            speed_coeff,
            track_scale,
        } = *cal;
        let (t0, w0) = self.last.replace((t_s, reading))?;
        let dt_s = t_s - t0;
        let (raw_l, raw_r) = (
            reading.dist_l_m - w0.dist_l_m,
            reading.dist_r_m - w0.dist_r_m,
        );
        let moved = raw_l != 0.0 || raw_r != 0.0;
        let (gain_l, gain_r) = differential_gains(diff);
        let wheels = WheelDistances {
            left_m: raw_l / gain_l,
            right_m: raw_r / gain_r,
        };
        let step = OdometryStep::new(&wheels, dt_s, speed_coeff, MIN_SPEED_FACTOR);
        let (mean, speed_mps) = (step.mean_m, step.speed_mps);
        let ratio = step.ratio();
        let track_m = match &self.steered {
            None => self.track_m,
            Some(s) => {
                // A step too short to resolve the turn (a pulse or two while creeping) can
                // show a ratio past the vehicle's lock; the tightest turn stands in for it.
                let c = ratio.abs().min(s.table.max_ratio());
                s.table.effective_track_m(c).unwrap_or(self.track_m)
            }
        };
        let scale = (1.0 + track_scale).max(MIN_TRACK_SCALE);
        let turn = step.turn(track_m, scale);
        let heading = turn.heading_change_rad;
        let (ds_m, ratio) = match &mut self.steered {
            None => (mean, ratio),
            Some(s) => {
                if mean != 0.0 {
                    let w = mean.abs() / (mean.abs() + CURVATURE_SMOOTHING_M);
                    s.curvature_per_m += w * (heading / mean - s.curvature_per_m);
                }
                let lateral = s.wheelbase_m * s.curvature_per_m * mean;
                let max = s.table.max_ratio();
                (
                    mean.signum() * (mean * mean - lateral * lateral).max(0.0).sqrt(),
                    (s.curvature_per_m * self.track_m).clamp(-max, max),
                )
            }
        };
        Some(WheelStep {
            dt_s,
            ds_m,
            heading_change_rad: heading,
            ratio,
            d_heading_d_diff: turn.d_heading_d_diff,
            d_heading_d_speed_coeff: turn.d_heading_d_speed_coeff,
            d_heading_d_track_scale: turn.d_heading_d_track_scale,
            speed_mps,
            side_speeds_mps: [raw_l / dt_s, raw_r / dt_s],
            effective_track_m: track_m * scale,
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

    fn at(l: f64, r: f64) -> WheelReading {
        WheelReading {
            dist_l_m: l,
            dist_r_m: r,
        }
    }

    fn rear() -> WheelOdometry {
        let mut w =
            WheelOdometry::new(OdometerWheels::Rear { track_m: 1.5 }, TrackModel::Exact).unwrap();
        assert!(w.step(0.0, at(0.0, 0.0), &NONE).is_none());
        w
    }

    #[test]
    fn rear_wheels_give_the_plain_formula_and_its_derivatives() {
        let s = rear().step(0.1, at(1.03, 0.97), &NONE).unwrap();
        assert!((s.heading_change_rad - 0.04).abs() < 1e-12);
        assert!((s.ds_m - 1.0).abs() < 1e-12);
        assert!((s.speed_mps - 10.0).abs() < 1e-12);
        assert!((s.dt_s - 0.1).abs() < 1e-15);
        assert!((s.ratio - 0.06).abs() < 1e-12);
        // Numerical derivatives agree with the analytic ones.
        let h = 1e-7;
        let turned = |cal: WheelCalibration| {
            rear()
                .step(0.1, at(1.03, 0.97), &cal)
                .unwrap()
                .heading_change_rad
        };
        let d = (turned(WheelCalibration { diff: h, ..NONE }) - s.heading_change_rad) / h;
        assert!((d - s.d_heading_d_diff).abs() < 1e-5);
        let d = (turned(WheelCalibration {
            speed_coeff: h,
            ..NONE
        }) - s.heading_change_rad)
            / h;
        assert!((d - s.d_heading_d_speed_coeff).abs() < 1e-4);
        let d = (turned(WheelCalibration {
            track_scale: h,
            ..NONE
        }) - s.heading_change_rad)
            / h;
        assert!((d - s.d_heading_d_track_scale).abs() < 1e-5);
    }

    #[test]
    fn front_wheels_shrink_the_track_and_the_distance_in_a_turn() {
        let car = AckermannParams {
            wheelbase_m: 2.7,
            track_m: 1.55,
            kingpin_offset_m: 0.1,
        };
        let geometry = AckermannGeometry::new(car).unwrap();
        // The distance takes the front wheels' mean path for the front axle's midpoint,
        // which runs on √(R² + B²); the contact points sit a kingpin offset off it, which
        // the midpoint rule misses by 0.1 % at 8 m and 0.4 % at a lock of 4.5 m.
        for (model, radius, tolerance, distance_tolerance) in [
            // The exact table, to its interpolation, down to a tight lock.
            (TrackModel::Exact, 8.0, 1e-4, 2e-3),
            (TrackModel::Exact, 4.5, 1e-3, 5e-3),
            // The patent's formula is within 0.1 % at 8 m (the crate's error table).
            (TrackModel::Patent, 8.0, 1e-3, 2e-3),
        ] {
            // Ten 2 m steps round the circle: the averaged curvature settles on it.
            let paths = geometry.wheel_paths_m(2.0, 1.0 / radius).unwrap();
            let mut w = WheelOdometry::new(OdometerWheels::Front(car), model).unwrap();
            w.step(0.0, at(0.0, 0.0), &NONE);
            let mut s = WheelStep::default();
            for k in 1..=10 {
                let k = f64::from(k);
                s = w
                    .step(0.2 * k, at(k * paths.left_m, k * paths.right_m), &NONE)
                    .unwrap();
            }
            let truth = 2.0 / radius;
            assert!(
                (s.heading_change_rad / truth - 1.0).abs() < tolerance,
                "{model:?} {radius}: {}",
                s.heading_change_rad
            );
            assert!(
                (s.ds_m / 2.0 - 1.0).abs() < distance_tolerance,
                "{}",
                s.ds_m
            );
            // A ratio past full lock is clamped, never NaN.
            let s = w
                .step(
                    3.0,
                    at(12.0 * paths.left_m + 0.06, 11.0 * paths.right_m),
                    &NONE,
                )
                .unwrap();
            assert!(s.heading_change_rad.is_finite() && s.ds_m.is_finite());
        }
    }

    #[test]
    fn a_counter_that_jumps_is_refused_against_the_wheels_own_last_reading() {
        let w = rear();
        assert!(w.check_speed(0.1, &at(5.0, 5.0)).is_ok());
        assert!(w.check_speed(0.1, &at(50.0, 50.0)).is_err());
        assert_eq!(w.last_s(), Some(0.0));
    }
}
