//! The configuration of the [`crate::OnlineEllipseCalibrator`] and its validation.

use serde::{Deserialize, Serialize};

use crate::quality::FitLimits;
use truenorth_core::{Result, Validate, check_positive, check_range};

use crate::fits::ellipse::config::MIN_POINTS_2D;
use crate::online::conic::OnlineConfig;
use crate::quality::MIN_ARC_DEG;

/// Configuration of [`crate::OnlineEllipseCalibrator`]. The refusal limits are those of
/// [`crate::EllipseConfig`], with the same defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OnlineEllipseConfig {
    /// Shortest arc of heading accepted, degrees, 0..=360 ([`MIN_ARC_DEG`], 200).
    pub min_arc_deg: f64,
    /// Fewest readings a solution is accepted from, MIN_POINTS_2D..=10⁶ (30). More than the
    /// fit's minimum ([`MIN_POINTS_2D`]): a refresh runs unattended, and with few residuals
    /// beyond the parameters the noise, and so the heading-error bound, is estimated from
    /// so few residuals that a chance fit of a short arc can pass every other check.
    pub min_samples: u32,
    /// Readings between the starts of two refreshes of the estimate, 1..=10⁶ (32), or a
    /// 64th of the readings the sums weigh if that is more (from 2,048 readings on; see
    /// the `conic` module). A refresh runs over the next five pushes, one stage
    /// each.
    pub refresh_interval_samples: u32,
    /// Half-life of a reading's weight, in readings, 20..=10⁹ (`None`: never forget). With
    /// forgetting the calibration follows a slowly changing hard or soft iron; readings
    /// older than four half-lives no longer count towards coverage.
    pub forgetting_half_life_samples: Option<f64>,
    /// The refusal limits shared by the least-squares fits (flat in JSON).
    #[serde(flatten)]
    pub limits: FitLimits,
    /// The expected horizontal field, input unit (e.g. from the World Magnetic Model), > 0,
    /// reported as [`truenorth_core::CompassQuality::field_ratio_to_expected`] (`None`).
    pub expected_field: Option<f64>,
}

impl Default for OnlineEllipseConfig {
    fn default() -> Self {
        Self {
            min_arc_deg: MIN_ARC_DEG,
            min_samples: 30,
            refresh_interval_samples: 32,
            forgetting_half_life_samples: None,
            limits: FitLimits::default(),
            expected_field: None,
        }
    }
}

impl Validate for OnlineEllipseConfig {
    fn validate(&self) -> Result<()> {
        check_range("online ellipse min_arc_deg", self.min_arc_deg, 0.0, 360.0)?;
        check_range(
            "online ellipse min_samples",
            self.min_samples as f64,
            MIN_POINTS_2D as f64,
            1e6,
        )?;
        check_range(
            "online ellipse refresh_interval_samples",
            self.refresh_interval_samples as f64,
            1.0,
            1e6,
        )?;
        if let Some(h) = self.forgetting_half_life_samples {
            check_range("online ellipse forgetting_half_life_samples", h, 20.0, 1e9)?;
        }
        self.limits.validate()?;
        if let Some(f) = self.expected_field {
            check_positive("online ellipse expected_field", f)?;
        }
        Ok(())
    }
}

impl OnlineConfig for OnlineEllipseConfig {
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
