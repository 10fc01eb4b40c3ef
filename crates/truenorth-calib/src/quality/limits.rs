//! The refusal limits the least-squares fits share, batch and online, 2-D and 3-D: how flat
//! an ellipse (ellipsoid), how far the readings may stray from it, and how uncertain the
//! calibration may be before it is refused rather than returned.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_positive, check_range};

/// The refusal limits of a least-squares compass fit (defaults in brackets). Each fit's
/// configuration holds one, flattened into it when serialised.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FitLimits {
    /// Largest ratio of the semi-axes accepted, ≥ 1 (10): flatter ellipses (ellipsoids) are
    /// refused as not an ellipse — no plausible soft iron squashes the field that much.
    pub max_axis_ratio: f64,
    /// Largest residual RMS, relative to the fitted field, accepted, > 0 (0.2): readings
    /// that stray further from the best ellipse (ellipsoid) are not a rotation in a constant
    /// field (a static sensor, a disturbed site, a badly tilting mount).
    pub max_residual_rel: f64,
    /// Largest heading-error bound of the calibration accepted
    /// ([`CompassQuality::heading_error_bound_deg`](truenorth_core::CompassQuality::heading_error_bound_deg)),
    /// degrees, > 0 (10; see [`crate::quality`]): a calibration that uncertain is refused
    /// rather than returned.
    pub max_heading_error_bound_deg: f64,
}

impl Default for FitLimits {
    fn default() -> Self {
        Self {
            max_axis_ratio: 10.0,
            max_residual_rel: 0.2,
            max_heading_error_bound_deg: 10.0,
        }
    }
}

impl Validate for FitLimits {
    fn validate(&self) -> Result<()> {
        check_range("max_axis_ratio", self.max_axis_ratio, 1.0, f64::MAX)?;
        check_positive("max_residual_rel", self.max_residual_rel)?;
        check_positive(
            "max_heading_error_bound_deg",
            self.max_heading_error_bound_deg,
        )?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn limits_validate_exactly_when_each_is_in_its_range(
            ratio in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), -2.0f64..20.0],
            residual in prop_oneof![Just(f64::NAN), -1.0f64..1.0],
            bound in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), -5.0f64..50.0],
        ) {
            let limits = FitLimits {
                max_axis_ratio: ratio,
                max_residual_rel: residual,
                max_heading_error_bound_deg: bound,
            };
            let valid = (1.0..=f64::MAX).contains(&ratio)
                && residual > 0.0
                && residual.is_finite()
                && bound > 0.0
                && bound.is_finite();
            prop_assert_eq!(limits.validate().is_ok(), valid);
        }
    }

    #[test]
    fn limits_are_flat_in_json() {
        let text = serde_json::to_string(&FitLimits::default()).unwrap();
        assert_eq!(
            text,
            r#"{"max_axis_ratio":10.0,"max_residual_rel":0.2,"max_heading_error_bound_deg":10.0}"#
        );
    }
}
