//! The settings of the one-turn calibration, shared by its compass half and its gyro half.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_positive, check_range};

use crate::quality::MIN_ARC_DEG;
use crate::seed::extrema::ExtremaConfig;

/// Configuration of the [`TurnCompassCalibrator`](crate::TurnCompassCalibrator) (defaults in
/// brackets).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TurnConfig {
    /// Extremum detector thresholds ([`ExtremaConfig::default`]).
    pub extrema: ExtremaConfig,
    /// Shortest arc of calibrated headings accepted, degrees, 0..=360 ([`MIN_ARC_DEG`]; a
    /// full turn always passes).
    pub min_arc_deg: f64,
    /// Longest step between two samples, seconds, > 0, that the gyro half
    /// ([`crate::TurnCalibrator`]) integrates its rate across ([`DEFAULT_MAX_GAP_S`]); a
    /// longer one is refused with [`Error::TimeGap`](truenorth_core::Error::TimeGap). The
    /// compass half reads no time.
    pub max_gap_s: f64,
    /// The expected horizontal field, input unit (e.g. from the World Magnetic Model), > 0,
    /// reported as [`CompassQuality::field_ratio_to_expected`](truenorth_core::CompassQuality::field_ratio_to_expected) (`None`).
    pub expected_field: Option<f64>,
}

/// The default [`TurnConfig::max_gap_s`]: 1 s. The trapezoid rule is exact across a step
/// while the rate changes linearly, but a turn that starts or stops inside a step of `g`
/// seconds can hide up to `Δr·g/2` of heading (Δr the change of rate): 10° for a 1-s step
/// at the start of a 20°/s turn, a few per cent of the conversion constant from one
/// revolution. A judgement: every logger sampling at 1 Hz or faster passes, a dropout of
/// more than a second is refused rather than bridged.
pub const DEFAULT_MAX_GAP_S: f64 = 1.0;

impl Validate for TurnConfig {
    fn validate(&self) -> Result<()> {
        self.extrema.validate()?;
        check_range("turn min_arc_deg", self.min_arc_deg, 0.0, 360.0)?;
        check_positive("turn max_gap_s", self.max_gap_s)?;
        if let Some(f) = self.expected_field {
            check_positive("turn expected_field", f)?;
        }
        Ok(())
    }
}

impl Default for TurnConfig {
    fn default() -> Self {
        Self {
            extrema: ExtremaConfig::default(),
            min_arc_deg: MIN_ARC_DEG,
            max_gap_s: DEFAULT_MAX_GAP_S,
            expected_field: None,
        }
    }
}
