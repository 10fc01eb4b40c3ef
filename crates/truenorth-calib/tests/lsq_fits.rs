//! Property tests and measures of the least-squares ellipse and ellipsoid calibrations:
//! equivariance, model → calibrator round trips, refusals, no panics, and the heading error
//! against the noise floor.
//!
//! The forward model is the tiny one in `common/` (raw = hard + W·h + noise, W symmetric),
//! independent of the compass crate's model, so these tests check the fits against first
//! principles.

use std::f64::consts::{PI, TAU};

use nalgebra::{Rotation3, Vector2, Vector3};
use proptest::prelude::*;
use truenorth_calib::{
    EllipseCalibrator, EllipseConfig, EllipsoidCalibrator, EllipsoidConfig, fit_ellipse,
    fit_ellipse_direct, fit_ellipsoid, quality,
};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{Calibrator, Error, Mag2Sample, Mag3Sample, SplitMix64, angle_diff};

mod common;
use common::*;

fn points(turn: &[(f64, Vector2<f64>)]) -> Vec<Vector2<f64>> {
    turn.iter().map(|t| t.1).collect()
}

fn heading_rms_deg(cal: &CompassCalibration2d, turn: &[(f64, Vector2<f64>)]) -> f64 {
    let ss: f64 = turn
        .iter()
        .map(|(psi, raw)| angle_diff(cal.heading_rad(raw), *psi).powi(2))
        .sum();
    (ss / turn.len() as f64).sqrt().to_degrees()
}

/// The reference turn: full turn, hard iron 0.5 × field, soft-iron axis ratio 1.3 rotated
/// 30°, noise 1 % of the field (per axis). Heading RMS of the least-squares fit against the
/// noise floor (the true calibration applied to the same noisy samples).
#[test]
fn least_squares_heading_rms_is_at_the_noise_floor() {
    let field = 1.0;
    let hard = Vector2::new(
        0.5 * field * 40f64.to_radians().cos(),
        0.5 * field * 40f64.to_radians().sin(),
    );
    let m = Model2::new(hard, 1.3, 30f64.to_radians(), field);
    let (truth, _) = m.truth();
    let trials = 200;
    let n = 360;
    let (mut sum_fit, mut sum_floor, mut sum_direct, mut worst) = (0.0, 0.0, 0.0, 0.0_f64);
    let mut bounds = 0.0;
    for seed in 0..trials {
        let turn = m.turn(n, 0.0, 360.0, 0.01 * field, seed);
        let pts = points(&turn);
        let sol = fit_ellipse(&pts, &EllipseConfig::default()).unwrap();
        let direct = fit_ellipse_direct(&pts).unwrap().calibration().0;
        let fit = heading_rms_deg(&sol.params, &turn);
        let floor = heading_rms_deg(&truth, &turn);
        sum_fit += fit;
        sum_floor += floor;
        sum_direct += heading_rms_deg(&direct, &turn);
        worst = worst.max(fit / floor);
        bounds += sol.quality.heading_error_bound_deg();
    }
    let ratio = sum_fit / sum_floor;
    println!(
        "LS ellipse, {trials} trials of {n} points: heading RMS {:.4}° (direct fit only {:.4}°), noise floor {:.4}°, ratio {:.4} (worst trial {:.4}); mean predicted bound {:.3}°",
        sum_fit / trials as f64,
        sum_direct / trials as f64,
        sum_floor / trials as f64,
        ratio,
        worst,
        bounds / trials as f64
    );
    // The limits, from the method. A calibrated heading errs by the reading's own
    // tangential noise n (the floor) plus the calibration's error c(ψ), which comes from
    // the radial residuals and so is independent of n (orthogonal components of isotropic
    // noise). Per trial, RMS²_fit/RMS²_floor = 1 + mean(c²)/σ² + 2·mean(n·c)/σ², where
    // mean(c²)/σ² is G²/N times a χ² of the 4 parameters that move the heading (the
    // centre, and the soft iron less its scale) over 4 — G = 2 for readings evenly round the
    // circle — and the cross term has standard deviation G²/N.
    let g2_n = 4.0 / n as f64;
    // The mean over the trials: half the mean excess, with 3 standard deviations of its
    // average over the trials (√(2/(4·trials)) of the χ², 1/√trials of the cross term).
    let t = trials as f64;
    let mean_limit = 1.0 + 0.5 * g2_n * (1.0 + 3.0 * (2.0 / (4.0 * t)).sqrt() + 3.0 / t.sqrt());
    // The worst trial: the 1 − 1/(200·trials) points of both, so that none of the trials
    // exceeds them but with a chance of 1 in 200 (χ²₄ of 28.7; 4.4 standard deviations).
    let worst_limit = (1.0 + g2_n * (28.7 / 4.0 + 4.4)).sqrt();
    println!("limits: mean {mean_limit:.4}, worst trial {worst_limit:.4}");
    assert!(ratio <= mean_limit, "ratio {ratio} > {mean_limit}");
    assert!(worst <= worst_limit, "worst {worst} > {worst_limit}");
}

#[test]
fn half_circle_and_shorter_arcs_are_refused_fuller_ones_accepted() {
    let m = Model2::new(Vector2::new(0.5, 0.0), 1.3, 30f64.to_radians(), 1.0);
    for span in [30.0, 90.0, 120.0, 150.0, 170.0, 180.0] {
        for seed in 0..10 {
            let turn = m.turn(200, seed as f64 * 36.0, span, 0.01, seed);
            let r = fit_ellipse(&points(&turn), &EllipseConfig::default());
            assert!(
                matches!(r, Err(Error::InsufficientCoverage { .. })),
                "span {span}, seed {seed}: {r:?}"
            );
        }
    }
    for span in [240.0, 300.0, 360.0] {
        let turn = m.turn(200, 10.0, span, 0.01, 1);
        assert!(fit_ellipse(&points(&turn), &EllipseConfig::default()).is_ok());
    }
}

#[test]
fn calibrator_lifecycle() {
    let m = Model2::new(Vector2::new(3.0, -1.0), 1.2, 0.3, 20.0);
    let mut cal = EllipseCalibrator::new(EllipseConfig {
        expected_field: Some(25.0),
        ..EllipseConfig::default()
    })
    .unwrap();
    assert!(!cal.progress().ready);
    assert!(matches!(cal.solve(), Err(Error::TooFewPoints { .. })));
    let bad = Mag2Sample {
        t_s: 0.0,
        mag: Vector2::new(f64::NAN, 1.0),
    };
    assert!(matches!(cal.push(&bad), Err(Error::NonFinite { .. })));
    for (k, (_, mag)) in m.turn(100, 0.0, 180.0, 0.01, 4).into_iter().enumerate() {
        cal.push(&Mag2Sample { t_s: k as f64, mag }).unwrap();
    }
    assert_eq!(cal.progress().samples, 100);
    assert!(matches!(
        cal.solve(),
        Err(Error::InsufficientCoverage { .. })
    ));
    for (k, (_, mag)) in m.turn(100, 180.0, 180.0, 0.01, 5).into_iter().enumerate() {
        cal.push(&Mag2Sample {
            t_s: 100.0 + k as f64,
            mag,
        })
        .unwrap();
    }
    let p = cal.progress();
    // Two half turns of 100 readings each, 1.8° apart, fill every 10° bin; seen from the
    // bounding box's centre (progress's estimate) one bin may be missed: 35 of 36.
    assert!(p.ready && p.coverage > 0.95, "{p:?}");
    let sol = cal.solve().unwrap();
    let ratio = sol.quality.field_ratio_to_expected.unwrap();
    assert!((ratio - sol.quality.field_magnitude / 25.0).abs() < 1e-12);
    // The bound is 3σG/√N with σ = 0.01/20 (relative), G = 2, N = 200: 0.004°; 1° is the
    // verdict `good`'s limit, which a full turn of such readings must meet.
    assert!(sol.quality.fit.coverage > 0.95 && sol.quality.heading_error_bound_deg() < 1.0);
    cal.reset();
    assert_eq!(cal.progress().samples, 0);
}

#[test]
fn ellipsoid_calibrator_lifecycle_and_single_axis_refusal() {
    let rot = Rotation3::from_euler_angles(0.3, -0.2, 0.7);
    let w = soft3(&rot, 1.15, 0.9);
    let hard = Vector3::new(20.0, -35.0, 10.0);
    let mut cal = EllipsoidCalibrator::new(EllipsoidConfig {
        expected_field: Some(50.0),
        ..EllipsoidConfig::default()
    })
    .unwrap();
    for (k, mag) in sphere_turn(hard, &w, 48.0, 500, 0.5, 2)
        .into_iter()
        .enumerate()
    {
        cal.push(&Mag3Sample { t_s: k as f64, mag }).unwrap();
    }
    assert!(cal.progress().ready);
    let sol = cal.solve().unwrap();
    // Noise 0.5 per axis on a field of 48 (σ ≈ 1 %), 500 readings evenly over the sphere:
    // each hard-iron component has σ·F·√3/√N ≈ 0.04 (the even sphere's A/N block is I/3),
    // the field about σF/√N ≈ 0.02; 0.5 is over ten standard deviations of either.
    assert!((sol.params.hard_iron - hard).norm() < 0.5);
    assert!((sol.quality.field_magnitude - 48.0).abs() < 0.5);
    assert!(sol.quality.field_ratio_to_expected.is_some());
    // One turn about a single axis: a great circle, refused.
    let ring: Vec<_> = (0..360)
        .map(|k| {
            let a = (k as f64).to_radians();
            hard + w * Vector3::new(48.0 * a.cos(), 48.0 * a.sin(), 20.0)
        })
        .collect();
    let r = fit_ellipsoid(&ring, &EllipsoidConfig::default());
    assert!(r.is_err(), "{r:?}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, failure_persistence: None, ..ProptestConfig::default() })]

    /// fit(k·R·p + t) = (k·R·b + t, R·S·Rᵀ, k·F) for rotation R, translation t, scale k.
    #[test]
    fn ellipse_fit_is_equivariant(
        cx in -5.0f64..5.0, cy in -5.0f64..5.0, ratio in 1.0f64..1.8, angle in -PI..PI,
        n in 30usize..300, seed in 0u64..1000,
        phi in -PI..PI, tx in -100.0f64..100.0, ty in -100.0f64..100.0, log_k in -2.0f64..2.0,
    ) {
        let m = Model2::new(Vector2::new(cx, cy), ratio, angle, 2.0);
        let p = points(&m.turn(n, 0.0, 360.0, 0.02, seed));
        let (r, t, k) = (rot2(phi), Vector2::new(tx, ty), 10f64.powf(log_k));
        let q: Vec<_> = p.iter().map(|v| r * v * k + t).collect();
        let a = fit_ellipse(&p, &EllipseConfig::default()).unwrap();
        let b = fit_ellipse(&q, &EllipseConfig::default()).unwrap();
        // The fit normalises the readings (centroid, RMS radius), so the two fits do the
        // same arithmetic up to rounding of the inputs (≈ 10⁻¹⁶ relative) amplified by the
        // refinement's stopping test (a step of 10⁻¹² of the cost): 10⁻⁷ relative to the
        // field and the offset.
        let fa = a.quality.field_magnitude;
        let expect_hard = r * a.params.hard_iron * k + t;
        prop_assert!((b.params.hard_iron - expect_hard).norm() <= 1e-7 * (k * fa + t.norm()));
        prop_assert!((b.params.soft_iron - r * a.params.soft_iron * r.transpose()).norm() <= 1e-7);
        prop_assert!((b.quality.field_magnitude / (k * fa) - 1.0).abs() <= 1e-8);
        prop_assert!((b.quality.fit.residual_rms_rel - a.quality.fit.residual_rms_rel).abs() <= 1e-8);
    }

    #[test]
    fn ellipsoid_fit_is_equivariant(
        hx in -1.0f64..1.0, hy in -1.0f64..1.0, hz in -1.0f64..1.0,
        a1 in 0.85f64..1.2, a2 in 0.85f64..1.2, orient in any_rotation(),
        n in 60usize..400, seed in 0u64..1000,
        rot in any_rotation(), tx in -100.0f64..100.0, log_k in -2.0f64..2.0,
    ) {
        let w = soft3(&orient, a1, a2);
        let p = sphere_turn(Vector3::new(hx, hy, hz), &w, 1.0, n, 0.01, seed);
        let (r, t, k) = (rot.matrix(), Vector3::new(tx, -0.5 * tx, 0.3 * tx), 10f64.powf(log_k));
        let q: Vec<_> = p.iter().map(|v| r * v * k + t).collect();
        let a = fit_ellipsoid(&p, &EllipsoidConfig::default()).unwrap();
        let b = fit_ellipsoid(&q, &EllipsoidConfig::default()).unwrap();
        // As the 2-D fit's: the same arithmetic on normalised readings, to rounding.
        let fa = a.quality.field_magnitude;
        let expect_hard = r * a.params.hard_iron * k + t;
        prop_assert!((b.params.hard_iron - expect_hard).norm() <= 1e-7 * (k * fa + t.norm()));
        prop_assert!((b.params.soft_iron - r * a.params.soft_iron * r.transpose()).norm() <= 1e-7);
        prop_assert!((b.quality.field_magnitude / (k * fa) - 1.0).abs() <= 1e-8);
    }

    /// Model → calibrator round trip: the errors in hard iron (relative to the field), soft
    /// iron and field shrink in proportion to the noise, down to rounding when it is zero.
    #[test]
    fn ellipse_round_trip_error_shrinks_with_noise(
        hx in -2.0f64..2.0, hy in -2.0f64..2.0, ratio in 1.0f64..1.6, angle in -PI..PI,
        field in 0.1f64..100.0, seed in 0u64..1000,
    ) {
        let m = Model2::new(Vector2::new(hx, hy) * field, ratio, angle, field);
        let (truth, f_true) = m.truth();
        for rel_sigma in [1e-2, 1e-3, 1e-4, 1e-6, 0.0] {
            let turn = m.turn(180, 7.0, 360.0, rel_sigma * field, seed);
            let sol = fit_ellipse(&points(&turn), &EllipseConfig::default()).unwrap();
            // 180 readings evenly round the circle: each hard-iron component has σ·F·√(2/N)
            // = 0.11σF, each soft-iron entry about 0.15σ (the even circle's information per
            // reading), the field σF/√N; 2σ and 4σ are over ten standard deviations (a
            // soft iron of 1.6 : 1 widens them by up to 1.6), and 10⁻⁹ is rounding.
            let tol = rel_sigma + 1e-9;
            prop_assert!((sol.params.hard_iron - truth.hard_iron).norm() / f_true <= 2.0 * tol,
                "σ {rel_sigma}: hard {:?} vs {:?}", sol.params.hard_iron, truth.hard_iron);
            prop_assert!((sol.params.soft_iron - truth.soft_iron).norm() <= 4.0 * tol,
                "σ {rel_sigma}: soft {} vs {}", sol.params.soft_iron, truth.soft_iron);
            prop_assert!((sol.quality.field_magnitude / f_true - 1.0).abs() <= 2.0 * tol);
        }
    }

    #[test]
    fn ellipsoid_round_trip_error_shrinks_with_noise(
        hx in -2.0f64..2.0, hy in -2.0f64..2.0, hz in -2.0f64..2.0,
        a1 in 0.8f64..1.25, a2 in 0.8f64..1.25, orient in any_rotation(),
        field in 0.1f64..100.0, seed in 0u64..1000,
    ) {
        let w = soft3(&orient, a1, a2);
        let hard = Vector3::new(hx, hy, hz) * field;
        let s_true = w.try_inverse().unwrap();
        let f_true = field * w.determinant().cbrt();
        for rel_sigma in [1e-2, 1e-3, 1e-4, 1e-6, 0.0] {
            let p = sphere_turn(hard, &w, field, 300, rel_sigma * field, seed);
            let sol = fit_ellipsoid(&p, &EllipsoidConfig::default()).unwrap();
            // 300 readings evenly over the sphere: each hard-iron component has σF√3/√N =
            // 0.1σF, each soft-iron entry about 0.2σ; 2σ and 4σ are ten standard
            // deviations and more, 10⁻⁹ rounding.
            let tol = rel_sigma + 1e-9;
            prop_assert!((sol.params.hard_iron - hard).norm() / f_true <= 2.0 * tol);
            prop_assert!((sol.params.soft_iron - s_true / s_true.determinant().cbrt()).norm() <= 4.0 * tol);
            prop_assert!((sol.quality.field_magnitude / f_true - 1.0).abs() <= 2.0 * tol);
        }
    }

    /// No input makes the fits or calibrators panic: NaN, infinities, huge and tiny values,
    /// duplicates, collinear and coplanar points, any count.
    #[test]
    fn no_input_panics(
        raw in proptest::collection::vec(
            prop_oneof![
                4 => -1e3f64..1e3,
                1 => proptest::num::f64::ANY,
                1 => Just(f64::NAN),
                1 => Just(0.0),
                1 => Just(1e300),
                1 => Just(1e-300),
            ],
            0..120,
        ),
        mode in 0usize..4,
    ) {
        let pts2: Vec<Vector2<f64>> = match mode {
            // as drawn
            0 => raw.chunks(2).filter(|c| c.len() == 2).map(|c| Vector2::new(c[0], c[1])).collect(),
            // collinear
            1 => raw.iter().map(|&x| Vector2::new(x, 2.0 * x + 1.0)).collect(),
            // duplicates of a few points
            2 => raw.iter().map(|&x| Vector2::new((x % 3.0).round(), 1.0)).collect(),
            _ => raw.iter().map(|&x| Vector2::new(x.sin(), x.cos())).collect(),
        };
        let pts3: Vec<Vector3<f64>> = match mode {
            0 => raw.chunks(3).filter(|c| c.len() == 3).map(|c| Vector3::new(c[0], c[1], c[2])).collect(),
            1 => raw.iter().map(|&x| Vector3::new(x, x.sin(), 0.5)).collect(),
            2 => raw.iter().map(|&x| Vector3::new((x % 3.0).round(), 1.0, 2.0)).collect(),
            _ => raw.iter().map(|&x| Vector3::new(x.sin(), x.cos(), (2.0 * x).sin())).collect(),
        };
        for refine in [false, true] {
            if let Ok(s) = fit_ellipse(&pts2, &EllipseConfig { refine, ..Default::default() }) {
                prop_assert!(s.params.soft_iron.iter().all(|x| x.is_finite()));
            }
            if let Ok(s) = fit_ellipsoid(&pts3, &EllipsoidConfig { refine, ..Default::default() }) {
                prop_assert!(s.params.soft_iron.iter().all(|x| x.is_finite()));
            }
        }
        if let Ok(e) = fit_ellipse_direct(&pts2) {
            prop_assert!(e.centre.iter().chain(e.unit_map.iter()).all(|x| x.is_finite()));
        }
        // A push is refused exactly when the reading is not finite.
        let mut c2 = EllipseCalibrator::default();
        for p in &pts2 {
            let finite = p.iter().all(|x| x.is_finite());
            prop_assert_eq!(c2.push(&Mag2Sample { t_s: 0.0, mag: *p }).is_ok(), finite);
        }
        prop_assert_eq!(c2.progress().ready, c2.solve().is_ok());
        let mut c3 = EllipsoidCalibrator::default();
        for p in &pts3 {
            let finite = p.iter().all(|x| x.is_finite());
            prop_assert_eq!(c3.push(&Mag3Sample { t_s: 0.0, mag: *p }).is_ok(), finite);
        }
        prop_assert_eq!(c3.progress().ready, c3.solve().is_ok());
        let cov = quality::coverage(&pts2, &Vector2::zeros());
        prop_assert!((0.0..=1.0).contains(&cov.fraction));
        prop_assert!((0.0..=TAU).contains(&cov.largest_gap_rad));
        prop_assert!((0.0..=1.0).contains(&quality::sphere_coverage(&pts3, &Vector3::zeros())));
        // The report counts only the usable readings, and its numbers are never NaN.
        let q = quality::quality_2d(&pts2, &CompassCalibration2d::identity(), 1.0);
        prop_assert!(q.fit.points <= pts2.len());
        prop_assert!(!q.heading_error_3sigma_deg.is_nan() && !q.fit.condition.is_nan());
    }
}

proptest! {
    // More cases than the other properties: the refusals it checks fail on rare draws.
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, ..ProptestConfig::default() })]

    /// Any arc of half a turn or less (down to 1°, where a handful of noisy readings fit a
    /// small ellipse around themselves that they seem to cover completely), any noise up to
    /// 3 %, 6 to 400 readings, any hard and soft iron: refused, and the calibrator's `ready`
    /// says so too.
    #[test]
    fn short_arcs_are_always_refused(
        span in 1.0f64..=180.0, start in 0.0f64..360.0, noise in 0.0f64..0.03,
        hx in -1.0f64..1.0, ratio in 1.0f64..1.5, angle in -PI..PI, n in 6usize..400, seed in 0u64..1000,
    ) {
        let m = Model2::new(Vector2::new(hx, -hx), ratio, angle, 1.0);
        let mut turn = m.turn(n, start, span, noise, seed);
        // `turn` stops one step short of the span; include the end point.
        let mut rng = SplitMix64::new(seed + 1);
        let end = (start + span).to_radians();
        turn.push((end, m.raw(end, &mut rng, noise)));
        let r = fit_ellipse(&points(&turn), &EllipseConfig::default());
        prop_assert!(r.is_err(), "span {span}, noise {noise}, {} points: {r:?}", turn.len());
        let mut cal = EllipseCalibrator::default();
        for (k, (_, mag)) in turn.iter().enumerate() {
            cal.push(&Mag2Sample { t_s: k as f64, mag: *mag }).unwrap();
            if k + 1 >= 6 && (k + 1) % 7 == 6 {
                prop_assert!(!cal.progress().ready, "span {span}, noise {noise}: ready after {} readings", k + 1);
            }
        }
    }
}
