//! The configuration of the merit-circle calibrator and its validation.

extern crate alloc;

use core::f64::consts::PI;

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_positive, check_range};

use crate::quality::MIN_ARC_DEG;

/// Data points kept to form triples.
pub const RING: usize = 8;

/// Configuration of the [`MeritCircleCalibrator`](crate::MeritCircleCalibrator) (defaults in brackets).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MeritCircleConfig {
    /// Turn about the current centre between data points, radians (30°).
    pub min_turn_rad: f64,
    /// A data point must be this many mean sample steps from the previous one (8).
    pub noise_multiple: f64,
    /// Before a centre exists, a data point must be this share of the spread of the readings
    /// from the previous one (0.25).
    pub spread_fraction: f64,
    /// Samples seen before the first data point, to estimate the step size (8).
    pub warmup_samples: usize,
    /// Triples whose centre amplifies point noise by more than this are skipped (10).
    pub max_amplification: f64,
    /// Cap on the accumulated weight, in best-triple units (200).
    pub weight_memory: f64,
    /// Centres needed before solving (3).
    pub min_centres: usize,
    /// Shortest arc of headings accepted, degrees ([`MERIT_CIRCLE_MIN_ARC_DEG`]).
    pub min_arc_deg: f64,
    /// The expected horizontal field, input unit (e.g. from the World Magnetic Model), > 0,
    /// reported as [`CompassQuality::field_ratio_to_expected`](truenorth_core::CompassQuality::field_ratio_to_expected) (`None`).
    pub expected_field: Option<f64>,
}

/// The merit circle's default shortest arc, degrees: 40° more than the workspace's
/// [`MIN_ARC_DEG`]. The arc is measured about the method's own centre, and on a short arc of
/// an elliptical locus a circle's centre is pulled towards the arc, which widens the arc seen
/// from it (a 180° arc of a 1.2-ratio ellipse with 1 % noise was seen as 205°).
pub const MERIT_CIRCLE_MIN_ARC_DEG: f64 = MIN_ARC_DEG + 40.0;

impl Default for MeritCircleConfig {
    fn default() -> Self {
        Self {
            min_turn_rad: 30f64.to_radians(),
            noise_multiple: 8.0,
            spread_fraction: 0.25,
            warmup_samples: 8,
            max_amplification: 10.0,
            weight_memory: 200.0,
            min_centres: 3,
            min_arc_deg: MERIT_CIRCLE_MIN_ARC_DEG,
            expected_field: None,
        }
    }
}

impl Validate for MeritCircleConfig {
    fn validate(&self) -> Result<()> {
        check_range("merit circle min_turn_rad", self.min_turn_rad, 0.0, PI)?;
        check_range("merit circle noise_multiple", self.noise_multiple, 0.0, 1e6)?;
        check_range(
            "merit circle spread_fraction",
            self.spread_fraction,
            0.0,
            2.0,
        )?;
        check_range(
            "merit circle max_amplification",
            self.max_amplification,
            0.82,
            1e9,
        )?;
        check_range(
            "merit circle weight_memory",
            self.weight_memory,
            1e-9,
            f64::MAX,
        )?;
        check_range(
            "merit circle min_centres",
            self.min_centres as f64,
            1.0,
            1e9,
        )?;
        check_range("merit circle min_arc_deg", self.min_arc_deg, 0.0, 360.0)?;
        if let Some(f) = self.expected_field {
            check_positive("merit circle expected_field", f)?;
        }
        Ok(())
    }
}
