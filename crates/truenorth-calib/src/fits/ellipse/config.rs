//! The configuration of the least-squares ellipse fit and its validation.

extern crate alloc;

use serde::{Deserialize, Serialize};

use crate::quality::FitLimits;
use truenorth_core::{Result, Validate, check_positive, check_range};

use crate::quality::MIN_ARC_DEG;

/// The fewest readings a 2-D least-squares fit accepts: five determine an ellipse, one
/// more leaves a residual to judge it by.
pub const MIN_POINTS_2D: usize = 6;

/// The fewest readings [`fit_ellipse`](crate::fit_ellipse) accepts a calibration from: five for the ellipse and
/// five residuals to judge it by (the direct fit alone, [`fit_ellipse_direct`](crate::fit_ellipse_direct), needs
/// [`MIN_POINTS_2D`]).
pub(crate) const MIN_POINTS_JUDGED_2D: usize = 10;

/// Configuration of the least-squares ellipse fit (defaults in brackets).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EllipseConfig {
    /// Refine the direct fit geometrically (Sampson distance) where that could change the
    /// answer (`true`; see the module documentation, step 5); `false` always keeps the
    /// algebraic fit.
    pub refine: bool,
    /// Most Levenberg–Marquardt steps before refusing with [`Error::NoConvergence`](truenorth_core::Error::NoConvergence), 1..=10⁶
    /// (100).
    pub max_iterations: usize,
    /// Shortest arc of heading accepted, degrees, 0..=360 ([`MIN_ARC_DEG`]).
    pub min_arc_deg: f64,
    /// The refusal limits shared by the least-squares fits (flat in JSON).
    #[serde(flatten)]
    pub limits: FitLimits,
    /// The expected horizontal field, input unit (e.g. from the World Magnetic Model), > 0,
    /// reported as [`CompassQuality::field_ratio_to_expected`](truenorth_core::CompassQuality::field_ratio_to_expected) (`None`).
    pub expected_field: Option<f64>,
}

impl Default for EllipseConfig {
    fn default() -> Self {
        Self {
            refine: true,
            max_iterations: 100,
            min_arc_deg: MIN_ARC_DEG,
            limits: FitLimits::default(),
            expected_field: None,
        }
    }
}

impl Validate for EllipseConfig {
    fn validate(&self) -> Result<()> {
        check_range(
            "ellipse max_iterations",
            self.max_iterations as f64,
            1.0,
            1e6,
        )?;
        check_range("ellipse min_arc_deg", self.min_arc_deg, 0.0, 360.0)?;
        self.limits.validate()?;
        if let Some(f) = self.expected_field {
            check_positive("ellipse expected_field", f)?;
        }
        Ok(())
    }
}
