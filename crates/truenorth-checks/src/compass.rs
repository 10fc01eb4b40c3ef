//! The physical checks of a stored compass calibration, the same wherever one is read (a
//! calibration file for `heading` or `orientation`, the compass part of a drive's learned
//! state for `drive --calibration-in`): every number finite, the field positive, the soft
//! iron neither singular, nor a mirror image, nor so ill-conditioned that it squashes the
//! field onto a line, and the hard iron within what a magnetometer can read.

use truenorth_core::{Fixed, Readable};

/// The largest condition number (largest over smallest singular value) of a soft-iron
/// matrix accepted on load: 10, the largest axis ratio the ellipsoid fit accepts. A worse
/// one squashes the field onto a line and reads nearly constant headings.
pub const MAX_SOFT_IRON_CONDITION: f64 = 10.0;

/// The largest hard iron accepted, in radii of the raw readings' field ellipse (the field
/// over the soft iron's smallest singular value). A magnetometer's range is at most a few
/// hundred times the Earth's field (a typical phone part: 4900 µT against 25-65 µT), so an
/// offset beyond this many radii is no sensor's: it would read every heading the same.
pub const MAX_HARD_IRON_RADII: f64 = 100.0;

/// Checks a compass calibration `corrected = soft_iron · (raw − hard_iron)` of radius
/// `field`, given the soft iron's determinant and singular values; the reason when it is
/// not one a real compass could have.
pub fn check_compass(
    hard_iron: &[f64],
    det: f64,
    singular_values: &[f64],
    field: f64,
) -> Result<(), String> {
    if hard_iron.iter().any(|v| !v.is_finite()) {
        return Err("`hard_iron` must be finite numbers".into());
    }
    if !(field.is_finite() && field > 0.0) {
        return Err(format!("`field` is {field}, must be a positive number"));
    }
    check_soft_iron(det, singular_values)?;
    let smallest = singular_values
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let radius = field / smallest;
    let offset = hard_iron.iter().fold(0.0, |a: f64, v| a.hypot(*v));
    let within = offset <= MAX_HARD_IRON_RADII * radius;
    if !within {
        return Err(format!(
            "`hard_iron` is {} from the origin, {} times the raw field's radius {} (at most {MAX_HARD_IRON_RADII} for a real magnetometer): every heading would read the same; recalibrate",
            Readable(offset),
            Readable(offset / radius),
            Readable(radius)
        ));
    }
    Ok(())
}

/// Refuses a soft iron that is singular, reflecting or too ill-conditioned to give
/// trustworthy headings.
pub fn check_soft_iron(det: f64, singular_values: &[f64]) -> Result<(), String> {
    // A NaN fails every check instead of slipping through one.
    if det.is_nan() || det <= 0.0 {
        return Err(format!(
            "`soft_iron` has determinant {}: a singular matrix collapses every reading onto a line (constant headings) and a negative one mirrors them (the compass axes swapped or one negated); recalibrate",
            Readable(det)
        ));
    }
    let max = singular_values.iter().copied().fold(0.0, f64::max);
    let min = singular_values
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let condition = max / min;
    if condition.is_nan() || condition > MAX_SOFT_IRON_CONDITION {
        return Err(format!(
            "`soft_iron` has condition number {}, more than {MAX_SOFT_IRON_CONDITION}: it would squash the field nearly onto a line; recalibrate",
            Fixed(condition, 1)
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hard_iron_no_magnetometer_reads_is_refused() {
        assert!(check_compass(&[3.0, -2.0], 1.0, &[1.0, 1.0], 1.0).is_ok());
        let e = check_compass(&[1e308, 0.0], 1.0, &[1.0, 1.0], 1.0).unwrap_err();
        assert!(e.contains("hard_iron") && e.contains("1e308"), "{e}");
        assert!(check_compass(&[f64::NAN, 0.0], 1.0, &[1.0, 1.0], 1.0).is_err());
        assert!(check_compass(&[0.0, 0.0], -1.0, &[1.0, 1.0], 1.0).is_err());
        assert!(check_compass(&[0.0, 0.0], 1.0, &[1.0, 1.0], f64::NAN).is_err());
    }
}
