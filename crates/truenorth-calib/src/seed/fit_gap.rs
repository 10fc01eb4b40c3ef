//! The share of a seed calibration's heading-error bound that the shared report cannot see.
//!
//! The shared report ([`crate::quality::assess_2d`]) bounds the heading error that noise
//! leaves in a *least-squares* fit of the kept readings: its 3σ part is the spread of such
//! a fit. The seed methods do not fit by least squares. The binned ellipse interpolates the
//! full set at the bin centres and takes the parameters from the R²-weighted sums of
//! EP 0634001 (claims 7–9), which weigh the noise of single readings differently and can
//! land further from the truth than the fit the report describes (on noisy turns of
//! elongated ellipses, twice as far), with radial residuals no larger. The merit circle
//! (US 5,297,063) fits a circle, so a soft iron is an error of its model that its report's
//! two-cycle term measures only to first order, and the centre it finds from triples of
//! data points can land further from the truth than a least-squares fit of the same
//! readings (without any soft iron, 9 of 270 noisy turns exceeded its bound without this
//! part, by up to a third; `tests/seed_bound.rs`). So the bound is
//! completed by the triangle inequality: the error of the seed estimate is at most the error
//! of the direct least-squares ellipse fit of the same readings — its 3σ part and its
//! second-order bias `4σ²(κ + h₁ + h₂)` ([`crate::quality::direct_fit_bias_rad`]) — plus
//! the largest heading difference between the two calibrations.

use nalgebra::Vector2;
use truenorth_compass::CompassCalibration2d;
use truenorth_core::angle_diff;

use crate::fits::ellipse::fit_ellipse_direct;
use crate::quality::{Assessment2d, anisotropy_2d, direct_fit_bias_rad};

/// The largest heading difference between `cal` and the direct least-squares ellipse fit of
/// `points`, over `points`, and that fit's second-order bias bound for a per-reading noise
/// of `sigma_rad`, radians: `(difference, bias)`. Both `∞` when the fit fails (the readings
/// do not determine an ellipse), so that the bound refuses. One pass over the readings for
/// the fit and one for the difference and the harmonics; allocates nothing.
pub(crate) fn fit_gap_rad(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
    sigma_rad: f64,
) -> (f64, f64) {
    let Ok(e) = fit_ellipse_direct(points) else {
        return (f64::INFINITY, f64::INFINITY);
    };
    let (lsq, _) = e.calibration();
    let (mut gap, mut k) = (0.0f64, 0usize);
    let (mut s1, mut s2) = (Vector2::zeros(), Vector2::zeros());
    for p in points {
        let d = angle_diff(cal.heading_rad(p), lsq.heading_rad(p)).abs();
        let u = lsq.correct(p);
        let r = u.norm();
        if !(d.is_finite() && r > 0.0 && r.is_finite()) {
            continue;
        }
        gap = gap.max(d);
        let u = u / r;
        s1 += u;
        s2 += Vector2::new(u.x * u.x - u.y * u.y, 2.0 * u.x * u.y);
        k += 1;
    }
    let kappa = anisotropy_2d(&(e.unit_map * e.unit_map));
    match (k, kappa) {
        (0, _) | (_, None) => (f64::INFINITY, f64::INFINITY),
        (k, Some(kappa)) => {
            let n = k as f64;
            let bias = direct_fit_bias_rad(sigma_rad, kappa, s1.norm() / n, s2.norm() / n);
            (gap, bias)
        }
    }
}

/// The report `a` of `cal` on its kept `points` with the bound completed (see the module
/// documentation): the systematic part becomes the larger of the two-cycle amplitude the
/// shared report found and the heading difference from the least-squares fit, plus that
/// fit's bias bound.
pub(crate) fn complete_bound(
    mut a: Assessment2d,
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
) -> Assessment2d {
    let q = &mut a.quality;
    let (gap, bias) = fit_gap_rad(points, cal, q.heading_noise_rms_deg.to_radians());
    q.heading_error_systematic_deg =
        q.heading_error_systematic_deg.max(gap.to_degrees()) + bias.to_degrees();
    a
}
