//! The configuration of the joint magnetometer + accelerometer calibration and its validation.

use crate::fits::ellipsoid::config::EllipsoidConfig;
use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_positive, check_range};

/// The determination bound of the starting ellipsoid fits, degrees (see step 1 of the
/// module documentation): loose, since the joint fit is judged on its own.
pub const INITIAL_FIT_BOUND_DEG: f64 = 90.0;

/// The fewest readings accepted: 22 parameters, and each ellipsoid needs its own ten.
pub const MIN_MAG_ACCEL_READINGS: usize = 12;

/// Configuration of the joint fit (defaults in brackets).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MagAccelConfig {
    /// The ellipsoid fits of step 1, one per sensor (their defaults).
    pub ellipsoid: EllipsoidConfig,
    /// Most Levenberg–Marquardt steps of each joint refinement, 1..=10⁶ (1000: residual
    /// groups of very different weights — a magnetometer far quieter than its accelerometer
    /// — make a long curved valley that a recording of two turns and a long dwell took
    /// about 700 steps to descend, in `tests/more_data.rs`; a well-spread recording
    /// converges in a few dozen).
    pub max_iterations: usize,
    /// Look for runs of shots aimed at one target (`true`).
    pub find_runs: bool,
    /// Largest angle, degrees, between the pointing directions of a run's first and any
    /// later shot, in (0, 45] (10: a hand aims at a mark within a degree, and the pointing
    /// axis seen through the first alignment is off by the few degrees the runs are there
    /// to find).
    pub run_tolerance_deg: f64,
    /// Smallest roll, degrees, a run must span, in [10, 180] (90: less does not determine
    /// the pointing axis well).
    pub run_min_roll_deg: f64,
    /// Fewest shots in a run, ≥ 3 (3).
    pub run_min_shots: usize,
    /// Largest heading error bound of the result, degrees (3σ, propagated to the heading
    /// of the pointing axis), > 0 (10).
    pub max_heading_error_bound_deg: f64,
    /// The expected total field, magnetometer unit, > 0 (`None`).
    pub expected_field: Option<f64>,
}

impl Default for MagAccelConfig {
    fn default() -> Self {
        Self {
            ellipsoid: EllipsoidConfig::default(),
            max_iterations: 1000,
            find_runs: true,
            run_tolerance_deg: 10.0,
            run_min_roll_deg: 90.0,
            run_min_shots: 3,
            max_heading_error_bound_deg: 10.0,
            expected_field: None,
        }
    }
}

impl Validate for MagAccelConfig {
    fn validate(&self) -> Result<()> {
        self.ellipsoid.validate()?;
        check_range(
            "mag_accel max_iterations",
            self.max_iterations as f64,
            1.0,
            1e6,
        )?;
        check_range(
            "mag_accel run_tolerance_deg",
            self.run_tolerance_deg,
            1e-9,
            45.0,
        )?;
        check_range(
            "mag_accel run_min_roll_deg",
            self.run_min_roll_deg,
            10.0,
            180.0,
        )?;
        check_range(
            "mag_accel run_min_shots",
            self.run_min_shots as f64,
            3.0,
            1e9,
        )?;
        check_positive(
            "mag_accel max_heading_error_bound_deg",
            self.max_heading_error_bound_deg,
        )?;
        if let Some(f) = self.expected_field {
            check_positive("mag_accel expected_field", f)?;
        }
        Ok(())
    }
}
