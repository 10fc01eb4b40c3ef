//! The quality report of a seed calibration: the shared 2-D report of [`crate::quality`] plus
//! the heading error that a circle-shaped model leaves where the locus is an ellipse.
//!
//! [`crate::quality::assess_2d`] bounds the error of the calibration *parameters* that noise
//! causes. The merit-circle and turn methods cannot represent a rotated soft iron at all, so
//! part of their residual is not noise but a deterministic two-cycle error. To first order a
//! symmetric soft-iron error `E` gives the radial residual `uᵀE u` and the heading error
//! `u⊥ᵀE u`; their two-cycle parts, `½(e₁₁ − e₂₂) cos 2u + e₁₂ sin 2u` and
//! `−½(e₁₁ − e₂₂) sin 2u + e₁₂ cos 2u`, have the same amplitude. So the amplitude of the
//! two-cycle component of the relative radial residual, fitted by least squares, is the peak
//! heading error (radians) that the calibration leaves uncorrected: it is reported as
//! `heading_error_systematic_deg`. For a calibration that models the ellipse it is close to
//! zero (noise only). The per-reading noise is then estimated from what the two-cycle fit
//! leaves, so the systematic part is not counted as noise.

use nalgebra::{Matrix3, Vector2, Vector3};
use truenorth_compass::CompassCalibration2d;

use crate::quality::{Assessment2d, assess_2d};

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Amplitude of the two-cycle component of `|cal(p)|/field − 1` over the heading of
/// `cal(p)`: the peak heading error (radians) an unmodelled symmetric soft iron leaves.
/// 0 when fewer than 3 usable points.
#[cfg(test)]
pub(crate) fn two_cycle_amplitude(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
    field: f64,
) -> f64 {
    two_cycle_fit(points, cal, field).0
}

/// The two-cycle amplitude (see [`two_cycle_amplitude`]) and the residual standard
/// deviation left by the fit of `1, cos 2u, sin 2u` (relative to the field; `None` when
/// fewer than 4 usable points or a singular fit).
fn two_cycle_fit(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
    field: f64,
) -> (f64, Option<f64>) {
    let mut ata = Matrix3::<f64>::zeros();
    let mut atb = Vector3::<f64>::zeros();
    let mut btb = 0.0;
    let mut n = 0usize;
    for p in points {
        let h = cal.correct(p);
        let rho = h.norm();
        if !(rho > 0.0 && rho.is_finite()) {
            continue;
        }
        let (c, s) = (h.x / rho, h.y / rho);
        let row = Vector3::new(1.0, c * c - s * s, 2.0 * c * s);
        let r = rho / field - 1.0;
        ata += row * row.transpose();
        atb += row * r;
        btb += r * r;
        n += 1;
    }
    if n < 3 {
        return (0.0, None);
    }
    match ata.try_inverse() {
        Some(inv) => {
            let x = inv * atb;
            let a = x.y.hypot(x.z);
            // Residual sum of squares of the linear fit: bᵀb − xᵀAᵀb (normal equations).
            let rss = (btb - x.dot(&atb)).max(0.0);
            let sigma = (n > 3).then(|| (rss / (n - 3) as f64).sqrt());
            let sigma = sigma.filter(|s| s.is_finite());
            (if a.is_finite() { a } else { 0.0 }, sigma)
        }
        None => (0.0, None),
    }
}

/// [`assess_2d`] with the two-cycle term (in degrees) as the systematic heading error, the
/// per-reading noise taken from what the two-cycle fit leaves, and `points` set to the
/// number of samples the calibrator used.
pub(crate) fn seed_assessment(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
    field: f64,
    samples_used: usize,
) -> Assessment2d {
    let mut a = assess_2d(points, cal, field);
    let (amplitude, sigma) = two_cycle_fit(points, cal, field);
    a.quality.heading_error_systematic_deg = amplitude.to_degrees();
    if let Some(sigma) = sigma {
        a.quality.heading_noise_rms_deg = sigma.to_degrees();
    }
    a.quality.fit.points = samples_used;
    a
}

#[cfg(test)]
mod tests {
    use super::*;
    use truenorth_compass::{HeadingTruth, MagnetometerModel2d, soft_iron_from_axes};
    use truenorth_core::{SensorModel, angle_diff};

    #[test]
    fn two_cycle_amplitude_is_the_peak_heading_error_of_an_ignored_soft_iron() {
        let m = MagnetometerModel2d::new(
            Vector2::new(4.0, 1.0),
            soft_iron_from_axes(1.1, 1.0, 0.5),
            0.0,
        )
        .unwrap();
        let pts: Vec<_> = (0..360)
            .map(|d| {
                m.ideal(&HeadingTruth {
                    heading_rad: f64::from(d).to_radians(),
                    horizontal_field: 10.0,
                })
                .unwrap()
            })
            .collect();
        // Hard iron right, soft iron ignored.
        let cal = CompassCalibration2d {
            hard_iron: Vector2::new(4.0, 1.0),
            ..CompassCalibration2d::identity()
        };
        let field = crate::quality::mean_corrected_norm_2d(&pts, &cal);
        let amp = two_cycle_amplitude(&pts, &cal, field);
        let peak = (0..360)
            .map(|d| angle_diff(cal.heading_rad(&pts[d]), f64::from(d as u32).to_radians()).abs())
            .fold(0.0, f64::max);
        assert!((amp - peak).abs() < 0.1 * peak, "amp {amp} peak {peak}");
        // With the true calibration there is nothing left.
        let good = m.true_calibration();
        assert!(two_cycle_amplitude(&pts, &good, 10.0) < 1e-9);
    }
}
