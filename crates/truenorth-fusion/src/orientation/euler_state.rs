//! The [`EulerDetectorState`]: everything the [`crate::EulerDetector`] carries from one
//! sample to the next, its parameters included, as plain data, so that a detector can be
//! saved and later continue exactly where it stopped.

use serde::{Deserialize, Serialize};
use truenorth_core::{
    AttitudeEstimate, Error, EulerZyx, Result, TimeStep, Validate, check_finite, check_range,
};
use truenorth_gyro::OscillationRemover;

use super::euler_config::EulerDetectorConfig;
use super::gyro_conditioner::GyroConditioner;
use super::moving_average::MovingAverage;
use super::quaternion_state::check_estimate;
use super::time_gap::GapMonitor;

/// What the [`crate::EulerDetector`] carries from one sample to the next (see the module
/// documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EulerDetectorState {
    /// The parameters.
    pub config: EulerDetectorConfig,
    /// The time of the last sample.
    pub clock: TimeStep,
    /// The steps taken and the gaps among them.
    pub gaps: GapMonitor,
    /// Each gyro axis's conditioning chain (x, y, z).
    pub conditioners: [GyroConditioner; 3],
    /// Each gyro axis's oscillation remover, when one is configured.
    pub oscillation_removers: Option<[OscillationRemover; 3]>,
    /// The attitude as Z-Y-X angles.
    pub angles: EulerZyx,
    /// The angles have been taken from a reading.
    pub initialised: bool,
    /// The previous static (roll, pitch, yaw), rad, or their moving averages, for the
    /// correction definer.
    pub previous_static: Option<[f64; 3]>,
    /// The definer's moving averages of the static (roll, pitch, yaw).
    pub averages: [MovingAverage; 3],
    /// The estimate after the last sample; `None` before the first.
    pub estimate: Option<AttitudeEstimate>,
}

impl EulerDetectorState {
    /// The state before any sample, for validated parameters.
    pub(crate) fn initial(config: EulerDetectorConfig) -> Result<Self> {
        let conditioner = GyroConditioner::new(&config.gyro)?;
        let oscillation_removers = match config.oscillation_remover {
            Some(o) => Some([OscillationRemover::new(o)?; 3]),
            None => None,
        };
        Ok(Self {
            config,
            clock: TimeStep::new(),
            gaps: GapMonitor::new(config.max_gap_s),
            conditioners: [conditioner; 3],
            oscillation_removers,
            angles: EulerZyx::default(),
            initialised: false,
            previous_static: None,
            averages: [MovingAverage::new(averaging_window(&config)); 3],
            estimate: None,
        })
    }
}

/// The number of samples the definer averages over (1: single samples).
fn averaging_window(config: &EulerDetectorConfig) -> usize {
    config.definer.moving_average.unwrap_or(1)
}

impl Validate for EulerDetectorState {
    /// Valid parameters; conditioners and removers of the kinds they select; angles finite
    /// and in range (pitch within ±90°); averages over the configured window; a finite
    /// estimate.
    fn validate(&self) -> Result<()> {
        use core::f64::consts::{FRAC_PI_2, PI};
        let cfg = &self.config;
        cfg.validate()?;
        if let Some(t) = self.clock.last_s() {
            check_finite("time of the last sample", t)?;
        }
        self.gaps.check(cfg.max_gap_s)?;
        if !self.conditioners.iter().all(|c| c.is_kind_of(&cfg.gyro))
            || self.oscillation_removers.is_some() != cfg.oscillation_remover.is_some()
        {
            return Err(Error::InvalidSnapshot {
                reason: "the gyro conditioning differs from the detector's parameters",
            });
        }
        let a = &self.angles;
        check_range("yaw_rad", a.yaw_rad, -PI, PI)?;
        check_range("pitch_rad", a.pitch_rad, -FRAC_PI_2, FRAC_PI_2)?;
        check_range("roll_rad", a.roll_rad, -PI, PI)?;
        for v in self.previous_static.iter().flatten() {
            check_finite("previous static angle", *v)?;
        }
        for m in &self.averages {
            m.check(averaging_window(cfg))?;
        }
        if let Some(e) = &self.estimate {
            check_estimate(e)?;
        }
        Ok(())
    }
}
