//! Quality measures shared by every compass calibrator: how much of the circle (or sphere)
//! the data cover, how far the calibrated readings stray from a circle (sphere), how well
//! the geometry determines the calibration, and how large a heading error that allows.
//!
//! Every calibrator in this crate fills its [`CompassQuality`](truenorth_core::CompassQuality) through [`assess_2d`] /
//! [`quality_2d`] (or [`quality_3d`]), so the numbers mean the same thing whichever method
//! produced them. The least-squares ellipse fit computes the same 2-D report from the
//! monomial sums of its direct fit instead of a second pass over the readings.
//!
//! The parts live in submodules: coverage (heading bins, sphere cells, the locus's turning),
//! bounds (information matrices and heading-error bounds), uncertainty (what the readings
//! determine: the dilution of the information matrix, the predicted parameter σ, and the
//! determination test that replaces a share of direction cells), verdict (good / usable /
//! poor), report (assembly of the [`CompassQuality`](truenorth_core::CompassQuality)) and
//! field (the fitted field against an expected one).
//!
//! # The three parts of the heading error
//!
//! * `heading_error_3sigma_deg` — three standard deviations of the heading error caused by
//!   the uncertainty of the fitted parameters, at the worst heading (derived below). It is
//!   the error the calibration adds to every later heading; it shrinks as `1/√N` with more
//!   readings. Per-reading noise is **not** in it.
//! * `heading_error_systematic_deg` — the deterministic heading error the method's model
//!   leaves even with perfect data: 0 for the least-squares ellipse and ellipsoid (their
//!   model represents any symmetric soft iron); for the seed methods that fit a circle or an
//!   axis-aligned ellipse, the peak of the two-cycle error of an unremoved rotated soft iron
//!   (see the `seed_quality` module).
//! * `heading_noise_rms_deg` — the RMS heading noise of one calibrated reading, estimated
//!   from the residuals that remain once the model (and, for the seed methods, the
//!   systematic two-cycle part) is taken out: for isotropic sensor noise of standard
//!   deviation `σ·F` per axis the radial residual and the heading error of one reading both
//!   have standard deviation `σ` (radians). Averaging readings reduces it; recalibrating
//!   does not.
//!
//! [`CompassQuality::heading_error_bound_deg`](truenorth_core::CompassQuality::heading_error_bound_deg) is the first two added: a bound on the error
//! of the calibration itself. A single reading's heading errs by that plus its own noise.
//!
//! # The heading-error bound (derivation)
//!
//! Write a calibrated reading as `h = F·u`, `u` a unit vector, `F` the field. Any 2-D
//! calibration differs from the truth, to first order, by a small centre error `F·d` and a
//! small symmetric matrix error `E` (the antisymmetric part of a soft-iron matrix is a pure
//! rotation that no circle or ellipse fit can see; it is assumed zero, which is why the fits
//! choose the symmetric square root). The estimate then maps a point on the true circle to
//! `(I + E)(h − F·d)`, so
//!
//! * its radial residual, relative to `F`, is `uᵀE u − uᵀd` = `φ(u)ᵀ p` with
//!   `p = (d_x, d_y, e₁₁, e₁₂, e₂₂)` and `φ(u) = (−u_x, −u_y, u_x², 2u_xu_y, u_y²)`;
//! * its angle (heading) error is `u⊥ᵀ(E u − d)` = `g(u)ᵀ p`, `u⊥` the unit vector 90°
//!   ahead of `u`.
//!
//! A least-squares calibration estimates `p` from the residuals of its `N` points; if those
//! are independent with standard deviation `σ` (relative to `F`), the estimate's covariance
//! is `σ²·A⁻¹` with the information matrix `A = Σᵢ φ(uᵢ)φ(uᵢ)ᵀ` (Gauss–Markov). The heading
//! error at direction `u` then has variance `σ²·g(u)ᵀA⁻¹g(u)`, and the bound reported as
//! `heading_error_3sigma_deg` is
//!
//! `bound = 3 · σ · max_u √(g(u)ᵀ A⁻¹ g(u))`   (3 σ at the worst heading, in degrees),
//!
//! with `σ² = Σ rᵢ² / (N − 5)` from the calibrated residuals `rᵢ = |hᵢ|/F − 1`. So it grows
//! with the residuals, shrinks as `1/√N` with the point count, and grows steeply as the
//! coverage shrinks (the directions `uᵢ` fill `A`). For `N` points spread evenly round the
//! circle `g(u)ᵀA⁻¹g(u) = 4/N` at every heading, so the bound is `3·2σ/√N` radians. It is the
//! error the calibration adds to every later heading; each reading's own noise adds about
//! `σ` radians (RMS) on top, reported apart as `heading_noise_rms_deg`. It does not include
//! model errors the residuals cannot reveal (a rotated soft iron, a tilted sensor, a field
//! that changes during the turn); the seed methods report the part of those their model is
//! known to leave as `heading_error_systematic_deg`.
//!
//! The `condition` reported is the condition number of `A` (largest over smallest
//! eigenvalue): 2 for a full, evenly covered circle, growing without bound as the arc
//! shortens. It is the condition of the linearised least-squares problem every 2-D
//! calibration solves, in coordinates normalised by the field, so it does not depend on
//! units or on where the hard iron is.
//!
//! The 3-D report is the same with `p = (d, e₁₁, e₁₂, e₁₃, e₂₂, e₂₃, e₃₃)` (9 parameters,
//! condition 2.5 for an evenly covered sphere), the angle error being the component of
//! `E u − d` perpendicular to `u` (the error of the field *direction*); the bound is the
//! worst over the whole sphere of `3 σ √(trace of its covariance)`. The heading of a level
//! compass errs by at most that divided by `cos(dip)`.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod bounds;
mod coverage;
mod field;
mod report;
mod support;
mod uncertainty;
mod verdict;

#[cfg(test)]
use bounds::{
    BOUND_DIRECTIONS_3D, MONOMIALS_2D, MONOMIALS_3D, QUAD_3D, bound_3d, information_2d,
    information_3d, monomial_tuples_3d, monomials_2d,
};
pub(crate) use bounds::{regressor_2d, regressor_3d};
#[cfg(test)]
use core::f64::consts::TAU;
pub use coverage::{
    ARC_END_NOISE_SIGMAS, Coverage, calibrated_coverage_2d, coverage, locus_turning_rad,
    require_arc, require_sphere_coverage, sphere_coverage,
};
pub(crate) use coverage::{calibrated_directions_2d, sphere_cell, turns};
pub use field::{
    FIELD_RATIO_TOLERANCE, FieldMismatch, field_mismatch, mean_corrected_norm_2d,
    mean_corrected_norm_3d, with_expected_field,
};
#[cfg(test)]
use nalgebra::{SMatrix, Vector2, Vector3};
pub use report::{Assessment2d, Assessment3d, assess_2d, assess_3d, quality_2d, quality_3d};
pub(crate) use report::{
    Moments2, SupportFigures, assess_2d_from_moments, direction_harmonics, support_dilution_3d,
};
pub(crate) use support::Support2d;
#[cfg(test)]
use truenorth_compass::{CompassCalibration2d, CompassCalibration3d};
#[cfg(test)]
use truenorth_core::CompassQuality;
pub use uncertainty::{
    DILUTION_EVEN_CIRCLE, DILUTION_EVEN_SPHERE, MAX_NOISE_DILUTION, MODEL_ERROR_REL, Uncertainty,
    require_certain, require_determined, require_linear,
};
pub use verdict::{Cause, GOOD_DEG, GOOD_NOISE_DEG, Grade, USABLE_DEG, Verdict};

/// Number of heading bins used for coverage (10° each).
pub const COVERAGE_BINS: usize = 36;

/// Number of fine bins (0.5° each) used to measure the largest empty arc.
pub(crate) const GAP_BINS: usize = 720;

/// Equal-area latitude bands of the direction cells on the sphere (uniform in `sin(lat)`,
/// so every band has the same area).
pub const SPHERE_BANDS: usize = 8;

/// Longitude sectors per band of the direction cells on the sphere.
pub const SPHERE_SECTORS: usize = 16;

/// Number of equal-area direction cells on the sphere (`SPHERE_BANDS × SPHERE_SECTORS`,
/// each about 320 square degrees, roughly 18° × 18° at the equator).
pub const SPHERE_CELLS: usize = SPHERE_BANDS * SPHERE_SECTORS;

/// The shortest arc of a turn, degrees, from which a 2-D calibration is accepted.
///
/// A half circle does not determine an ellipse (the missing half is extrapolated, and a
/// small noise at its ends moves the centre a lot), so every 2-D calibrator refuses spans up
/// to a little beyond 180°; the margin keeps a noisy half circle from slipping through.
pub const MIN_ARC_DEG: f64 = 200.0;

/// The share of the direction cells on the sphere ([`SPHERE_CELLS`]) below which the online
/// ellipsoid calibrator explains a failed fit as too little of the sphere seen (no
/// calibrator refuses a successful fit on it: whether the orientations determine a 3-D
/// calibration is judged by their dilution, see [`require_determined`]).
///
/// One turn about a single axis traces a great circle, which passes through about 20–25 %
/// of the cells and does not determine an ellipsoid; turns about two or more axes reach
/// well beyond this.
pub const MIN_SPHERE_COVERAGE: f64 = 0.3;

/// How many standard deviations the heading-error bound spans.
pub const BOUND_SIGMAS: f64 = 3.0;

#[cfg(test)]
mod tests {
    use super::*;
    extern crate alloc;
    use alloc::vec::Vec;
    use truenorth_core::{NoiseSource, SplitMix64};

    fn circle(n: usize, from_deg: f64, to_deg: f64, radius: f64) -> Vec<Vector2<f64>> {
        (0..n)
            .map(|k| {
                let a = (from_deg + (to_deg - from_deg) * k as f64 / (n - 1) as f64).to_radians();
                Vector2::new(radius * a.cos(), radius * a.sin())
            })
            .collect()
    }

    #[test]
    fn fast_turns_match_atan2() {
        let mut worst: f64 = 0.0;
        for k in 0..100_000 {
            let a = TAU * k as f64 / 100_000.0;
            for r in [1e-3, 1.0, 1e6] {
                let (y, x) = (r * a.sin(), r * a.cos());
                let exact = y.atan2(x).rem_euclid(TAU) / TAU;
                let mut d = (turns(y, x) - exact).abs();
                d = d.min(1.0 - d);
                worst = worst.max(d);
                assert!((0.0..1.0).contains(&turns(y, x)));
            }
        }
        assert!(worst * TAU < 1e-7, "{}", worst * TAU);
        assert_eq!(turns(0.0, 1.0), 0.0);
        assert_eq!(turns(-0.0, 1.0), 0.0);
        assert!((turns(1.0, 0.0) - 0.25).abs() < 1e-12);
        assert!((turns(0.0, -1.0) - 0.5).abs() < 1e-12);
        assert!((turns(-1.0, 0.0) - 0.75).abs() < 1e-12);
    }

    #[test]
    fn coverage_of_full_and_half_circle() {
        let full = circle(360, 0.0, 359.0, 1.0);
        let c = coverage(&full, &Vector2::zeros());
        assert_eq!(c.fraction, 1.0);
        assert!(c.span_rad().to_degrees() > 358.0);
        let half = circle(181, 0.0, 180.0, 1.0);
        let c = coverage(&half, &Vector2::zeros());
        let span = c.span_rad().to_degrees();
        assert!((179.0..=182.0).contains(&span), "{span}");
        assert!(require_arc(&c, 0.0, MIN_ARC_DEG).is_err());
        assert_eq!(coverage(&[], &Vector2::zeros()).fraction, 0.0);
    }

    #[test]
    fn perfect_circle_report() {
        let pts = circle(3601, 0.0, 360.0, 2.0);
        let q = quality_2d(&pts, &CompassCalibration2d::identity(), 2.0);
        assert_eq!(q.fit.coverage, 1.0);
        assert!(q.fit.residual_rms_rel < 1e-12);
        assert!((q.fit.condition - 2.0).abs() < 1e-2, "{}", q.fit.condition);
        assert!(q.heading_error_3sigma_deg < 1e-9);
        assert!(with_expected_field(q, Some(4.0)).field_ratio_to_expected == Some(0.5));
    }

    #[test]
    fn bound_matches_closed_form_for_even_coverage() {
        // σ = 1 % radial noise, N evenly spread: bound = 3 · 2σ/√N rad.
        let mut rng = SplitMix64::new(3);
        let n = 2000;
        let pts: Vec<_> = circle(n, 0.0, 360.0 * (n - 1) as f64 / n as f64, 1.0)
            .into_iter()
            .map(|p| p * (1.0 + rng.normal(0.01)))
            .collect();
        let q = quality_2d(&pts, &CompassCalibration2d::identity(), 1.0);
        let expect = (3.0 * 2.0 * 0.01 / (n as f64).sqrt()).to_degrees();
        assert!(
            (q.heading_error_3sigma_deg / expect - 1.0).abs() < 0.1,
            "{} vs {expect}",
            q.heading_error_3sigma_deg
        );
    }

    #[test]
    fn shorter_arcs_have_worse_condition_and_bound() {
        let mut rng = SplitMix64::new(5);
        let mut last = (0.0, 0.0);
        for span in [360.0, 270.0, 210.0] {
            let pts: Vec<_> = circle(500, 0.0, span, 1.0)
                .into_iter()
                .map(|p| p * (1.0 + rng.normal(0.01)))
                .collect();
            let q = quality_2d(&pts, &CompassCalibration2d::identity(), 1.0);
            assert!(q.fit.condition > last.0 && q.heading_error_3sigma_deg > last.1);
            last = (q.fit.condition, q.heading_error_3sigma_deg);
        }
    }

    /// The 3-D bound through `L⁻¹` equals the one from solving with `A` for each direction.
    #[test]
    fn bound_3d_matches_solving_with_the_information_matrix() {
        let mut rng = SplitMix64::new(13);
        let m = SMatrix::<f64, 9, 9>::from_fn(|_, _| rng.normal(1.0));
        let info = m * m.transpose() + SMatrix::<f64, 9, 9>::identity();
        let chol = info.cholesky().unwrap();
        let golden = core::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
        let mut worst: f64 = 0.0;
        for k in 0..BOUND_DIRECTIONS_3D {
            let z = 1.0 - (2.0 * k as f64 + 1.0) / BOUND_DIRECTIONS_3D as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let (s, c) = (golden * k as f64).sin_cos();
            let u = Vector3::new(r * c, r * s, z);
            let proj = nalgebra::Matrix3::identity() - u * u.transpose();
            let mut g = SMatrix::<f64, 3, 9>::zeros();
            for kk in 0..3 {
                g.set_column(kk, &(-proj.column(kk)));
            }
            for (j, &(a, b)) in QUAD_3D.iter().enumerate() {
                let mut eu = Vector3::zeros();
                eu[a] += u[b];
                if a != b {
                    eu[b] += u[a];
                }
                g.set_column(3 + j, &(proj * eu));
            }
            worst = worst.max((g * chol.solve(&g.transpose())).trace());
        }
        let (sum_sq, n) = (0.5, 100);
        let expect = (BOUND_SIGMAS * (sum_sq / (n - 9) as f64).sqrt() * worst.sqrt()).to_degrees();
        let got = bound_3d(&info, sum_sq, n);
        assert!((got / expect - 1.0).abs() < 1e-12, "{got} vs {expect}");
    }

    /// The information matrices built from monomial sums equal `Σ φφᵀ` summed directly.
    #[test]
    fn information_from_monomials_matches_outer_products() {
        let mut rng = SplitMix64::new(11);
        let dirs3: Vec<Vector3<f64>> = (0..37)
            .map(|_| {
                let v = Vector3::new(rng.normal(1.0), rng.normal(1.0), rng.normal(1.0));
                v / v.norm()
            })
            .collect();

        let mut direct2 = SMatrix::<f64, 5, 5>::zeros();
        let mut sums2 = [0.0; MONOMIALS_2D];
        for d in &dirs3 {
            let u = d.xy() / d.xy().norm();
            let phi = regressor_2d(u.x, u.y);
            direct2 += phi * phi.transpose();
            for (s, v) in sums2.iter_mut().zip(monomials_2d(u.x, u.y)) {
                *s += v;
            }
        }
        assert!((information_2d(&sums2) - direct2).amax() < 1e-12);

        let mut direct3 = SMatrix::<f64, 9, 9>::zeros();
        let mut sums3 = [0.0; MONOMIALS_3D];
        for u in &dirs3 {
            let phi = regressor_3d(u);
            direct3 += phi * phi.transpose();
            for (s, (idx, deg)) in sums3.iter_mut().zip(monomial_tuples_3d()) {
                *s += idx[..deg].iter().map(|&a| u[a]).product::<f64>();
            }
        }
        assert!((information_3d(&sums3) - direct3).amax() < 1e-12);
    }

    #[test]
    fn sphere_report() {
        // Fibonacci sphere: even coverage, condition 2.5.
        let n = 4000;
        let golden = core::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
        let pts: Vec<_> = (0..n)
            .map(|k| {
                let z = 1.0 - (2.0 * k as f64 + 1.0) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let (s, c) = (golden * k as f64).sin_cos();
                Vector3::new(r * c, r * s, z) * 3.0
            })
            .collect();
        let q = quality_3d(&pts, &CompassCalibration3d::identity(), 3.0);
        // The coverage is the efficiency of the support (each equal-area cell's readings
        // weighed as one), whose mass sits at the cells' mean directions instead of spread
        // evenly over them: 0.9990 measured here, so a judgement of 0.995.
        assert!(q.fit.coverage > 0.995, "{}", q.fit.coverage);
        assert!((q.fit.condition - 2.5).abs() < 0.01, "{}", q.fit.condition);
        assert!(q.fit.residual_rms_rel < 1e-12);
        assert_eq!(sphere_coverage(&pts, &Vector3::zeros()), 1.0);
        // A great circle fills few cells.
        let ring: Vec<_> = (0..360)
            .map(|k| {
                let a = (k as f64).to_radians();
                Vector3::new(a.cos(), 0.0, a.sin())
            })
            .collect();
        let f = sphere_coverage(&ring, &Vector3::zeros());
        assert!(f < MIN_SPHERE_COVERAGE, "{f}");
        assert!(require_sphere_coverage(f, MIN_SPHERE_COVERAGE).is_err());
    }
}

#[cfg(test)]
mod turning_tests {
    use super::*;
    use nalgebra::Matrix2;
    use proptest::prelude::*;

    fn ellipse_arc(span_deg: f64, start_deg: f64, m: &Matrix2<f64>, n: usize) -> Vec<Vector2<f64>> {
        (0..n)
            .map(|k| {
                let t = (start_deg + span_deg * k as f64 / (n - 1) as f64).to_radians();
                m * Vector2::new(t.cos(), t.sin()) + Vector2::new(3.0, -2.0)
            })
            .collect()
    }

    #[test]
    fn full_and_half_circles() {
        let m = Matrix2::identity();
        // One-degree chords: short by about a degree, never long.
        let full = locus_turning_rad(&ellipse_arc(360.0, 0.0, &m, 361), 0.0).to_degrees();
        assert!((358.5..=360.0).contains(&full), "{full}");
        let half = locus_turning_rad(&ellipse_arc(180.0, 10.0, &m, 181), 0.0).to_degrees();
        assert!((178.5..=180.0 + 1e-9).contains(&half), "{half}");
        assert_eq!(locus_turning_rad(&[Vector2::new(1.0, 1.0); 5], 0.0), 0.0);
    }

    proptest! {
        /// Over at most half an ellipse the chords turn by at most π, whatever the affine
        /// distortion.
        #[test]
        fn half_an_ellipse_or_less_never_reads_as_more(
            span in 20.0f64..180.0,
            start in 0.0f64..360.0,
            a in 0.5f64..2.0, b in 0.5f64..2.0, c in -0.5f64..0.5,
        ) {
            let m = Matrix2::new(a, c, c, b);
            prop_assume!(m.determinant() > 0.1);
            let t = locus_turning_rad(&ellipse_arc(span, start, &m, 200), 0.0).to_degrees();
            prop_assert!(t <= 180.0 + 1e-9, "span {span} turned {t}");
        }

        /// Skipping short chords keeps half an ellipse at most half, and loses at most two
        /// chords' turning on a full one.
        #[test]
        fn a_minimum_chord_keeps_the_laws(
            span in 20.0f64..180.0,
            start in 0.0f64..360.0,
            a in 0.7f64..1.5, b in 0.7f64..1.5, c in -0.3f64..0.3,
            min_chord in 0.0f64..0.3,
        ) {
            let m = Matrix2::new(a, c, c, b);
            prop_assume!(m.determinant() > 0.3);
            let t = locus_turning_rad(&ellipse_arc(span, start, &m, 300), min_chord).to_degrees();
            prop_assert!(t <= 180.0 + 1e-9, "span {span} turned {t}");
            // Skipping errs short, by at most the last chord's turning at each end: two chord
            // angles at the smallest radius of curvature, b²/a at the ends of the major axis.
            let e = m.symmetric_eigenvalues();
            let rho_min = e.min().powi(2) / e.max();
            let chord_deg = 2.0 * (min_chord / (2.0 * rho_min)).min(1.0).asin().to_degrees();
            let full = locus_turning_rad(&ellipse_arc(360.0, start, &m, 721), min_chord).to_degrees();
            prop_assert!(full >= 360.0 - 2.0 * chord_deg - 1.0, "a full turn read as {full} (chord {chord_deg}°)");
        }

        #[test]
        fn more_than_half_an_ellipse_reads_as_more_than_half(
            span in 190.0f64..359.0,
            start in 0.0f64..360.0,
            a in 0.5f64..2.0, b in 0.5f64..2.0, c in -0.5f64..0.5,
        ) {
            let m = Matrix2::new(a, c, c, b);
            prop_assume!(m.determinant() > 0.1);
            let t = locus_turning_rad(&ellipse_arc(span, start, &m, 400), 0.0).to_degrees();
            prop_assert!(t >= 180.0, "span {span} turned {t}");
        }

        #[test]
        fn any_input_is_finite(pts in proptest::collection::vec((proptest::num::f64::ANY, proptest::num::f64::ANY), 0..20)) {
            let v: Vec<Vector2<f64>> = pts.into_iter().map(|(x, y)| Vector2::new(x, y)).collect();
            let t = locus_turning_rad(&v, 0.0);
            prop_assert!(t.is_finite() && t >= 0.0);
        }
    }
}

#[cfg(test)]
mod field_mismatch_tests {
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
