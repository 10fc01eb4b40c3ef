//! The configuration of the least-squares ellipsoid fit and its validation.

extern crate alloc;

use serde::{Deserialize, Serialize};

use crate::quality::FitLimits;
use truenorth_core::{Result, Validate, check_positive, check_range};

use crate::quality::{self};

/// How much looser the determination test is before the fit, about the bounding-box centre
/// and without a soft iron, than after it (see `fit_unchecked`): a judgement, covering soft
/// irons up to the axis ratio 1.23 of the real full-sphere recording and centres placed by
/// 24 shots (`tests/few_shot.rs` accepts every simulated protocol).
pub(crate) const PRE_FIT_SLACK: f64 = 4.0;

/// What to record when the orientations do not determine an ellipsoid.
pub(crate) const ORIENTATION_HINT: &str = "add readings in other orientations (turns about a second and a third axis, or shots pointing and rolled in new directions)";

/// The fewest readings a 3-D least-squares fit accepts: nine determine an ellipsoid, one
/// more leaves a residual to judge it by.
pub const MIN_POINTS_3D: usize = 10;

/// Configuration of the least-squares ellipsoid fit (defaults in brackets).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EllipsoidConfig {
    /// Refine the direct fit geometrically (`true`).
    pub refine: bool,
    /// Most Levenberg–Marquardt steps before refusing with [`Error::NoConvergence`](truenorth_core::Error::NoConvergence), 1..=10⁶
    /// (100).
    pub max_iterations: usize,
    /// The refusal limits shared by the least-squares fits (flat in JSON).
    #[serde(flatten)]
    pub limits: FitLimits,
    /// Largest per-reading noise (relative to the field) times the orientations' dilution
    /// accepted, > 0 ([`quality::MAX_NOISE_DILUTION`]: beyond it the fit's own error figures
    /// no longer hold; see [`quality::require_linear`]).
    pub max_noise_dilution: f64,
    /// The expected total field, input unit (e.g. from the World Magnetic Model), > 0,
    /// reported as [`CompassQuality::field_ratio_to_expected`](truenorth_core::CompassQuality::field_ratio_to_expected) (`None`).
    pub expected_field: Option<f64>,
}

impl Default for EllipsoidConfig {
    fn default() -> Self {
        Self {
            refine: true,
            max_iterations: 100,
            limits: FitLimits::default(),
            max_noise_dilution: quality::MAX_NOISE_DILUTION,
            expected_field: None,
        }
    }
}

impl Validate for EllipsoidConfig {
    fn validate(&self) -> Result<()> {
        check_range(
            "ellipsoid max_iterations",
            self.max_iterations as f64,
            1.0,
            1e6,
        )?;
        self.limits.validate()?;
        check_positive("ellipsoid max_noise_dilution", self.max_noise_dilution)?;
        if let Some(f) = self.expected_field {
            check_positive("ellipsoid expected_field", f)?;
        }
        Ok(())
    }
}
