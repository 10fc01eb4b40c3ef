//! The configuration of the [`crate::OnlineEllipsoidCalibrator`] and its validation.

use serde::{Deserialize, Serialize};

use crate::quality::FitLimits;
use truenorth_core::{Result, Validate, check_positive, check_range};

use crate::fits::ellipsoid::config::MIN_POINTS_3D;
use crate::online::conic::OnlineConfig;
use crate::quality::{self, MIN_SPHERE_COVERAGE};

/// Configuration of [`crate::OnlineEllipsoidCalibrator`]. The refusal limits are those of
/// [`crate::EllipsoidConfig`], with the same defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OnlineEllipsoidConfig {
    /// Share of the sphere's direction cells, 0..=1 ([`MIN_SPHERE_COVERAGE`]), below which
    /// a fit that fails (a hyperboloid, a flat or collapsed quadric) is explained as too
    /// little of the sphere seen. It refuses nothing on its own: whether the orientations
    /// determine the calibration is judged by their dilution, as the batch fit's.
    pub min_coverage: f64,
    /// Fewest readings a solution is accepted from, MIN_POINTS_3D..=10⁶ (50). More than the
    /// fit's minimum ([`MIN_POINTS_3D`]): a refresh runs unattended, and with few residuals
    /// beyond the parameters the noise, and so the heading-error bound, is estimated from
    /// so few residuals that a chance fit of a short arc can pass every other check.
    pub min_samples: u32,
    /// Readings between the starts of two refreshes of the estimate, 1..=10⁶ (64), or a
    /// 64th of the readings the sums weigh if that is more (from 4,096 readings on; see
    /// the `conic` module). A refresh runs over the next 20 pushes, one stage
    /// each.
    pub refresh_interval_samples: u32,
    /// Half-life of a reading's weight, in readings, 50..=10⁹ (`None`: never forget).
    /// Readings older than four half-lives no longer count towards coverage.
    pub forgetting_half_life_samples: Option<f64>,
    /// The refusal limits shared by the least-squares fits (flat in JSON).
    #[serde(flatten)]
    pub limits: FitLimits,
    /// Largest per-reading noise (relative to the field) times the orientations' dilution
    /// accepted, > 0 ([`quality::MAX_NOISE_DILUTION`]: beyond it the fit's own error figures
    /// no longer hold; see [`quality::require_linear`]).
    pub max_noise_dilution: f64,
    /// The expected total field, input unit, > 0, reported as
    /// [`truenorth_core::CompassQuality::field_ratio_to_expected`] (`None`).
    pub expected_field: Option<f64>,
}

impl Default for OnlineEllipsoidConfig {
    fn default() -> Self {
        Self {
            min_coverage: MIN_SPHERE_COVERAGE,
            min_samples: 50,
            refresh_interval_samples: 64,
            forgetting_half_life_samples: None,
            limits: FitLimits::default(),
            max_noise_dilution: quality::MAX_NOISE_DILUTION,
            expected_field: None,
        }
    }
}

impl Validate for OnlineEllipsoidConfig {
    fn validate(&self) -> Result<()> {
        check_range("online ellipsoid min_coverage", self.min_coverage, 0.0, 1.0)?;
        check_range(
            "online ellipsoid min_samples",
            self.min_samples as f64,
            MIN_POINTS_3D as f64,
            1e6,
        )?;
        check_range(
            "online ellipsoid refresh_interval_samples",
            self.refresh_interval_samples as f64,
            1.0,
            1e6,
        )?;
        if let Some(h) = self.forgetting_half_life_samples {
            check_range(
                "online ellipsoid forgetting_half_life_samples",
                h,
                50.0,
                1e9,
            )?;
        }
        self.limits.validate()?;
        check_positive(
            "online ellipsoid max_noise_dilution",
            self.max_noise_dilution,
        )?;
        if let Some(f) = self.expected_field {
            check_positive("online ellipsoid expected_field", f)?;
        }
        Ok(())
    }
}

impl OnlineConfig for OnlineEllipsoidConfig {
    fn min_samples(&self) -> u32 {
        self.min_samples
    }

    fn refresh_interval_samples(&self) -> u32 {
        self.refresh_interval_samples
    }

    fn forgetting_half_life_samples(&self) -> Option<f64> {
        self.forgetting_half_life_samples
    }
}
