//! Tests of the shared quality report: coverage, bounds and the turning of the locus.

use super::bounds::{
    BOUND_DIRECTIONS_3D, MONOMIALS_2D, MONOMIALS_3D, bound_3d, direction_jacobian_3d,
    information_2d, information_3d, monomial_tuples_3d, monomials_2d,
};
use super::direction_bins::turns;
use super::*;
use core::f64::consts::TAU;
use nalgebra::{SMatrix, Vector2, Vector3};
use truenorth_compass::{CompassCalibration2d, CompassCalibration3d};
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
    let mut worst: f64 = 0.0;
    for k in 0..BOUND_DIRECTIONS_3D {
        let g = direction_jacobian_3d(k);
        worst = worst.max((g * chol.solve(&g.transpose())).trace());
    }
    let (sum_sq, n) = (0.5, 100);
    let expect = (BOUND_SIGMAS * (sum_sq / (n - 9) as f64).sqrt() * worst.sqrt()).to_degrees();
    let got = bound_3d(&info, sum_sq, n);
    assert!((got / expect - 1.0).abs() < 1e-12, "{got} vs {expect}");
}

/// The information matrices built from monomial sums equal `Σ φφᵀ` summed directly.
/// κ of `B²` is 0 for a circle, `(q² − 1)/(q² + 1)` for an axis ratio `q` (whatever the
/// axes' orientation), and unavailable for a non-finite matrix; in 3-D it takes the
/// outermost axes and ignores the middle one.
#[test]
fn anisotropy_reads_the_axis_ratio() {
    use nalgebra::{Matrix2, Matrix3, Rotation2};
    assert_eq!(anisotropy_2d(&Matrix2::identity()), Some(0.0));
    let r = Rotation2::new(0.7).into_inner();
    let b = r * Matrix2::new(2.0, 0.0, 0.0, 1.0) * r.transpose();
    let kappa = anisotropy_2d(&(b * b)).unwrap();
    assert!((kappa - 3.0 / 5.0).abs() < 1e-12, "{kappa}");
    assert_eq!(anisotropy_2d(&Matrix2::new(f64::NAN, 0.0, 0.0, 1.0)), None);
    let b_sq = Matrix3::from_diagonal(&Vector3::new(4.0, 9.0, 1.0));
    assert!((anisotropy_3d(&b_sq).unwrap() - 0.8).abs() < 1e-12);
    assert_eq!(anisotropy_3d(&Matrix3::identity()), Some(0.0));
    assert_eq!(anisotropy_3d(&(Matrix3::identity() * f64::INFINITY)), None);
}

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
    let q = assess_3d(&pts, &CompassCalibration3d::identity(), 3.0);
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

/// The turning of the raw locus ([`locus_turning_rad`]).
mod turning {
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
