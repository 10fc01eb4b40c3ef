//! The configuration of EP 0640207: heading from the gyro, whose zero is
//! measured at rest and whose conversion constant comes from the compass extrema of the
//! drive's first full turn ([`truenorth_calib::TurnCalibrator`]); the compass calibrated from
//! the same extrema pulls the heading through a fixed-gain complementary filter
//! ([`super::seed_blend`]); the wheels give distance and rest only. Until the first turn is
//! complete the heading is relative to the start.

use serde::{Deserialize, Serialize};
use truenorth_calib::{TurnCalibration, TurnCalibrator, TurnConfig, TurnSample};
use truenorth_core::{
    Calibrator, HeadingEstimator, MagneticHeading, NavEstimate, Result, TimeStep, Validate,
    VehicleSample,
};
use truenorth_gyro::YawIncrement;
use truenorth_odometer::OdometerWheels;

use super::seed_blend::{SeedBlend, SeedBlendConfig};
use super::wheel_odometry::{TrackModel, WheelCalibration, WheelOdometry};

/// Samples between two checks of whether the turn calibration can be solved.
const SOLVE_EVERY: u32 = 10;

/// Configuration of [`SeedGyroCompass`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SeedGyroCompassConfig {
    /// The odometer wheels (distance and rest only).
    pub wheels: OdometerWheels,
    /// The compass blend (default time constant 60 s: the gyro is good for minutes).
    pub blend: SeedBlendConfig,
    /// The turn calibrator.
    pub turn: TurnConfig,
}

impl Default for SeedGyroCompassConfig {
    fn default() -> Self {
        Self {
            wheels: OdometerWheels::Rear { track_m: 1.55 },
            blend: SeedBlendConfig {
                tau_s: 60.0,
                ..SeedBlendConfig::default()
            },
            turn: TurnConfig::default(),
        }
    }
}

impl Validate for SeedGyroCompassConfig {
    fn validate(&self) -> Result<()> {
        self.wheels.validate()?;
        self.blend.validate()?;
        self.turn.validate()
    }
}

/// The gyro-and-compass estimator of EP 0640207. See the module documentation.
#[derive(Debug, Clone)]
pub struct SeedGyroCompass {
    pub(super) config: SeedGyroCompassConfig,
    pub(super) wheels: WheelOdometry,
    pub(super) blend: SeedBlend,
    pub(super) turn: Option<TurnCalibrator>,
    pub(super) calibration: Option<(TurnCalibration, f64)>,
    /// Zero reading: the calibration's, then each standstill's mean (claims 8-9).
    pub(super) zero_rps: f64,
    pub(super) rest_sum: f64,
    pub(super) rest_n: u32,
    /// The last gyro reading and its time.
    pub(super) last_gyro: Option<(f64, f64)>,
    /// The wheels stand still.
    pub(super) at_rest: bool,
    pub(super) since_solve: u32,
    pub(super) clock: TimeStep,
    pub(super) est: NavEstimate,
}

impl SeedGyroCompass {
    /// An estimator that knows nothing yet.
    pub fn new(config: SeedGyroCompassConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            config,
            wheels: WheelOdometry::new(config.wheels, TrackModel::Patent)?,
            blend: SeedBlend::new(config.blend)?,
            turn: Some(TurnCalibrator::new(config.turn)?),
            calibration: None,
            zero_rps: 0.0,
            rest_sum: 0.0,
            rest_n: 0,
            last_gyro: None,
            at_rest: false,
            since_solve: 0,
            clock: TimeStep::new(),
            est: NavEstimate::at_start(f64::NAN, MagneticHeading::new(0.0), f64::INFINITY),
        })
    }

    /// The turn calibration, once the first full turn has been driven.
    pub fn calibration(&self) -> Option<&TurnCalibration> {
        self.calibration.as_ref().map(|(c, _)| c)
    }

    /// Offers a compass reading, with the latest gyro reading, to the turn calibration.
    fn learn_turn(&mut self, sample: &VehicleSample) {
        let (Some(turn), Some((_, gyr)), Some(mag)) = (&mut self.turn, self.last_gyro, sample.mag)
        else {
            return;
        };
        if turn
            .push(&TurnSample {
                t_s: sample.t_s,
                gyr_z_rps: gyr,
                mag,
            })
            .is_err()
        {
            return;
        }
        self.since_solve += 1;
        if self.since_solve < SOLVE_EVERY {
            return;
        }
        self.since_solve = 0;
        if let Ok(s) = turn.solve() {
            self.zero_rps = s.params.gyro.zero_rps;
            self.calibration = Some((s.params, s.quality.compass.field_magnitude));
            self.turn = None;
        }
    }
}

impl HeadingEstimator for SeedGyroCompass {
    /// Takes one row, whatever readings it carries: the gyro turns the heading between its
    /// readings, the wheels carry the track and say when the vehicle stands still. A
    /// non-finite value or a timestamp that does not increase is a typed error and changes
    /// nothing.
    fn update(&mut self, sample: &VehicleSample) -> Result<NavEstimate> {
        sample.validate()?;
        if let Some(w) = &sample.wheels {
            self.wheels.check_speed(sample.t_s, w)?;
        }
        self.clock.dt_s(sample.t_s)?;
        let (zero, gain) = self.calibration.map_or((self.zero_rps, 1.0), |(c, _)| {
            (c.gyro.zero_rps, c.gyro.gain_pos)
        });
        let mut gap = false;
        if let Some(r) = sample.gyr_z_rps {
            if let Some((t0, p)) = self.last_gyro
                && !self.at_rest
            {
                // A step longer than the turn calibrator bridges is not integrated: the turn
                // made across it is unknown (a rate held over an hour, or over 1e308 s, is
                // no heading), and the compass, once calibrated, pulls the heading back.
                let dt_s = sample.t_s - t0;
                gap = dt_s > self.config.turn.max_gap_s;
                if !gap {
                    self.blend
                        .turn(YawIncrement::new(p, r, dt_s).corrected_rad(zero, gain));
                }
            }
            self.last_gyro = Some((sample.t_s, r));
            // The zero reading is taken again at every standstill (claims 8-9).
            match (self.at_rest, &mut self.calibration) {
                (true, Some((c, _))) => {
                    self.rest_sum += r;
                    self.rest_n += 1;
                    c.gyro.zero_rps = self.rest_sum / f64::from(self.rest_n);
                }
                _ => {
                    self.rest_sum = 0.0;
                    self.rest_n = 0;
                }
            }
        }
        if let Some(w) = sample.wheels
            && let Some(step) = self
                .wheels
                .step(sample.t_s, w, &WheelCalibration::default())
        {
            self.at_rest = self.blend.travel(step.ds_m, step.dt_s, step.moved);
            self.est.speed_mps = step.speed_mps;
        }
        self.learn_turn(sample);
        let mut used = false;
        if let (Some(mag), Some((c, field))) = (sample.mag, self.calibration) {
            used = self
                .blend
                .compass_vector(sample.t_s, c.compass.correct(&mag), field)
                .is_some();
        }
        self.blend.write_estimate(&mut self.est, sample.t_s);
        let e = &mut self.est;
        e.status.compass_calibrated = self.calibration.is_some();
        e.status.compass_used = used;
        e.status.at_rest = self.at_rest;
        e.status.position_known = self.wheels.last_s().is_some();
        e.status.gap = gap;
        Ok(*e)
    }

    fn estimate(&self) -> NavEstimate {
        self.est
    }

    fn reset(&mut self) {
        if let Ok(fresh) = Self::new(self.config) {
            *self = fresh;
        }
    }
}
