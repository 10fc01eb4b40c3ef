//! The compass half of the one-turn calibration (EP 0640207 claims 4, 5, 10): the calibrator
//! and its saved state.

extern crate alloc;

use alloc::vec::Vec;
use core::f64::consts::TAU;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{
    Calibrator, CompassQuality, Error, Mag2Sample, Persistent, Progress, Pushed, Result, Solution,
    TimeStep, Validate, check_finite, check_finite2,
};

use crate::quality::{calibrated_coverage_2d, require_arc};
use crate::seed::direction_slots::{DirectionSlots, SLOTS};
use crate::seed::seed_quality::{seed_assessment, with_expected_field};

use super::config::TurnConfig;
use super::turn_extrema::{TurnEllipse, TurnExtrema, TurnExtremaState};

/// The compass half of the turn calibrator: centre and radii from the extrema of one or more
/// full turns (EP 0640207 claims 4, 5, 10). Push allocates nothing.
///
/// ```
/// use nalgebra::{Matrix2, Vector2};
/// use truenorth_calib::{TurnCompassCalibrator, TurnConfig};
/// use truenorth_compass::{HeadingTruth, MagnetometerModel2d};
/// use truenorth_core::{Calibrator, Mag2Sample, SensorModel};
///
/// let model = MagnetometerModel2d::new(Vector2::new(8.0, -3.0), Matrix2::new(1.2, 0.0, 0.0, 0.9), 0.0)?;
/// let mut cal = TurnCompassCalibrator::new(TurnConfig::default())?;
/// for i in 0..450 { // 450° of turn, 1° per sample, starting at heading 10°
///     let truth = HeadingTruth { heading_rad: (10.0 + i as f64).to_radians(), horizontal_field: 20.0 };
///     cal.push(&Mag2Sample { t_s: i as f64 * 0.1, mag: model.ideal(&truth)? })?;
/// }
/// assert!(cal.progress().ready);
/// let sol = cal.solve()?;
/// assert!((sol.params.hard_iron - Vector2::new(8.0, -3.0)).norm() < 0.1);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct TurnCompassCalibrator {
    config: TurnConfig,
    extrema: TurnExtrema<f64>,
    slots: DirectionSlots,
    clock: TimeStep,
}

impl Default for TurnCompassCalibrator {
    fn default() -> Self {
        Self::build(TurnConfig::default())
    }
}

impl TurnCompassCalibrator {
    /// A calibrator with the given configuration (validated).
    pub fn new(config: TurnConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::build(config))
    }

    fn build(config: TurnConfig) -> Self {
        Self {
            config,
            extrema: TurnExtrema::with_valid_config(config.extrema),
            slots: DirectionSlots::new(),
            clock: TimeStep::new(),
        }
    }

    /// The configuration in use.
    pub fn config(&self) -> &TurnConfig {
        &self.config
    }

    /// The extrema found so far (tagged with timestamps).
    pub fn extrema(&self) -> &TurnExtrema<f64> {
        &self.extrema
    }

    /// The acceptance tests of `solve`, shared with `progress`: the extrema of a full turn,
    /// then the arc of the calibrated readings.
    fn accepted(&self) -> Result<(TurnEllipse, [Vector2<f64>; SLOTS], usize)> {
        let fit = self.extrema.solve()?;
        let mut buf = [Vector2::zeros(); SLOTS];
        let n = self.slots.collect(&mut buf);
        require_arc(
            &calibrated_coverage_2d(&buf[..n], &fit.calibration()),
            0.0,
            self.config.min_arc_deg,
        )?;
        Ok((fit, buf, n))
    }
}

impl Calibrator for TurnCompassCalibrator {
    type Sample = Mag2Sample;
    type Params = CompassCalibration2d;
    type Quality = CompassQuality;

    /// Refuses non-finite readings and timestamps that are not finite or do not increase
    /// (the extrema must be found in time order); a refused sample changes nothing.
    fn push(&mut self, sample: &Mag2Sample) -> Result<Pushed> {
        check_finite2("magnetometer reading", &sample.mag)?;
        self.clock.dt_s(sample.t_s)?;
        let c = self.extrema.push_centred(&sample.mag, sample.t_s)?;
        self.slots.push(&sample.mag, &c);
        Ok(Pushed::Accepted)
    }

    /// `ready` runs the acceptance tests of [`Calibrator::solve`] (bounded: the kept
    /// extrema and at most 72 readings).
    fn progress(&self) -> Progress {
        let samples = self.extrema.samples();
        let (x0, x1) = self.extrema.x().range();
        let (y0, y1) = self.extrema.y().range();
        let radii = Vector2::new(0.5 * (x1 - x0), 0.5 * (y1 - y0));
        let turned = if samples > 1 && radii.x > 0.0 && radii.y > 0.0 {
            self.extrema
                .turned_rad(&self.extrema.provisional_centre(), &radii)
                .unwrap_or(0.0)
        } else {
            0.0
        };
        Progress {
            samples,
            coverage: (turned.abs() / TAU).min(1.0),
            ready: self.accepted().is_ok(),
        }
    }

    fn solve(&self) -> Result<Solution<CompassCalibration2d>> {
        let (fit, buf, n) = self.accepted()?;
        let a = seed_assessment(
            &buf[..n],
            &fit.calibration(),
            fit.field(),
            self.extrema.samples(),
        );
        let solution = Solution {
            params: fit.calibration(),
            quality: a.quality,
        };
        Ok(with_expected_field(solution, self.config.expected_field))
    }

    fn reset(&mut self) {
        self.extrema.reset();
        self.slots.clear();
        self.clock.reset();
    }
}

/// The saved state of a [`TurnCompassCalibrator`] ([`Persistent::State`]): configuration,
/// extremum trackers, the kept readings and the last timestamp.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TurnCompassCalibratorState {
    /// The configuration.
    pub config: TurnConfig,
    /// The extremum trackers (opaque).
    pub extrema: TurnExtremaState<f64>,
    /// The kept readings by direction slot (72 entries, `None` where empty).
    pub slots: Vec<Option<Vector2<f64>>>,
    /// The last accepted timestamp, seconds.
    pub last_t_s: Option<f64>,
}

impl Persistent for TurnCompassCalibrator {
    type State = TurnCompassCalibratorState;
    const SNAPSHOT_VERSION: u32 = 1;

    fn state(&self) -> TurnCompassCalibratorState {
        TurnCompassCalibratorState {
            config: self.config,
            extrema: self.extrema.saved(),
            slots: self.slots.to_vec(),
            last_t_s: self.clock.last_s(),
        }
    }

    fn from_state(state: TurnCompassCalibratorState) -> Result<Self> {
        let s = state;
        s.config.validate()?;
        let extrema = TurnExtrema::from_saved(s.extrema)?;
        if extrema.x().config() != &s.config.extrema || extrema.y().config() != &s.config.extrema {
            return Err(Error::InvalidSnapshot {
                reason: "the turn's extremum trackers were saved with another configuration",
            });
        }
        let slots = DirectionSlots::from_slice(&s.slots).ok_or(Error::InvalidSnapshot {
            reason: "the turn's direction slots must be 72 finite readings or empty",
        })?;
        let mut clock = TimeStep::new();
        if let Some(t) = s.last_t_s {
            check_finite("saved timestamp", t)?;
            clock.dt_s(t)?;
        }
        if (extrema.samples() > 0) != s.last_t_s.is_some() {
            return Err(Error::InvalidSnapshot {
                reason: "the turn's timestamp does not fit its sample count",
            });
        }
        Ok(Self {
            config: s.config,
            extrema,
            slots,
            clock,
        })
    }
}
