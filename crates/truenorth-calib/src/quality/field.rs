//! The fitted field against an expected one, and the mean calibrated field for
//! calibrators that do not fit a radius.

use nalgebra::{Vector2, Vector3};
use truenorth_compass::{CompassCalibration2d, CompassCalibration3d};
use truenorth_core::{CompassQuality, Fixed};

/// Sets [`CompassQuality::field_ratio_to_expected`]: the fitted field over `expected_field` (e.g.
/// from the World Magnetic Model, in the input unit). Leaves it `None` when no positive
/// finite expectation is given.
pub fn with_expected_field(
    mut quality: CompassQuality,
    expected_field: Option<f64>,
) -> CompassQuality {
    quality.field_ratio_to_expected = expected_field
        .filter(|e| e.is_finite() && *e > 0.0)
        .map(|e| quality.field_magnitude / e);
    quality
}

/// How far the fitted field may stray from the expected one before [`field_mismatch`] warns:
/// ±15 %. The WMM's own uncertainty is about 1 %, so beyond this the site is disturbed, the
/// unit is wrong, or a 2-axis sensor is tilted (it then sees part of the vertical field).
pub const FIELD_RATIO_TOLERANCE: f64 = 0.15;

/// A fitted field that disagrees with the expected one (e.g. the World Magnetic Model's
/// field at the place and date, converted to the input unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldMismatch {
    /// The fitted field, input unit.
    pub fitted: f64,
    /// The expected field, input unit.
    pub expected: f64,
}

impl FieldMismatch {
    /// fitted / expected.
    pub fn ratio(&self) -> f64 {
        self.fitted / self.expected
    }
}

impl core::fmt::Display for FieldMismatch {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "the fitted field {} is {} x the expected {}: a magnetically disturbed site, a wrong unit, or a tilted 2-axis sensor",
            Fixed(self.fitted, 4),
            Fixed(self.ratio(), 2),
            Fixed(self.expected, 4)
        )
    }
}

/// A warning when the report's fitted field differs from `expected_field` by more than
/// [`FIELD_RATIO_TOLERANCE`]; `None` when it agrees or no positive finite expectation is given.
pub fn field_mismatch(quality: &CompassQuality, expected_field: f64) -> Option<FieldMismatch> {
    if !(expected_field.is_finite() && expected_field > 0.0) {
        return None;
    }
    let m = FieldMismatch {
        fitted: quality.field_magnitude,
        expected: expected_field,
    };
    // Written so that a NaN ratio (no fitted field) is a mismatch too.
    if (m.ratio() - 1.0).abs() <= FIELD_RATIO_TOLERANCE {
        None
    } else {
        Some(m)
    }
}

/// Mean radius of the calibrated readings, for calibrators that do not fit a radius.
/// Non-finite readings are skipped; 0 if none remain.
pub fn mean_corrected_norm_2d(points: &[Vector2<f64>], cal: &CompassCalibration2d) -> f64 {
    mean_norm(points.iter().map(|p| cal.correct(p).norm()))
}

/// Mean magnitude of the calibrated readings, for calibrators that do not fit a radius.
/// Non-finite readings are skipped; 0 if none remain.
pub fn mean_corrected_norm_3d(points: &[Vector3<f64>], cal: &CompassCalibration3d) -> f64 {
    mean_norm(points.iter().map(|p| cal.correct(p).norm()))
}

fn mean_norm(norms: impl Iterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for r in norms.filter(|r| r.is_finite()) {
        s += r;
        n += 1;
    }
    if n > 0 { s / n as f64 } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn warns_exactly_outside_the_tolerance(fitted in 0.0f64..100.0, expected in 1e-3f64..100.0) {
            let q = CompassQuality { field_magnitude: fitted, ..CompassQuality::default() };
            let ratio = fitted / expected;
            let warned = field_mismatch(&q, expected);
            prop_assert_eq!(warned.is_some(), (ratio - 1.0).abs() > FIELD_RATIO_TOLERANCE);
            if let Some(w) = warned {
                prop_assert!((w.ratio() - ratio).abs() < 1e-12);
            }
        }

        /// Any fitted field (an overflowed fit, a field of 1e300) gives a short warning.
        #[test]
        fn warning_reads_short(fitted in proptest::num::f64::ANY, expected in proptest::num::f64::ANY) {
            let text = FieldMismatch { fitted, expected }.to_string();
            prop_assert!(text.len() <= 600, "{}", text);
            let run = text.split(|c: char| !c.is_ascii_digit()).map(str::len).max();
            prop_assert!(run.unwrap_or(0) <= 20, "{}", text);
        }

        #[test]
        fn no_expectation_no_warning(
            fitted in proptest::num::f64::ANY,
            expected in prop_oneof![
                Just(f64::NAN),
                Just(f64::INFINITY),
                Just(f64::NEG_INFINITY),
                Just(0.0),
                -1e9f64..0.0,
            ],
        ) {
            let q = CompassQuality { field_magnitude: fitted, ..CompassQuality::default() };
            prop_assert!(field_mismatch(&q, expected).is_none());
        }
    }
}
