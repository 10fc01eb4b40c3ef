//! Every figure in a refusal is true for the input it names: on random recordings of every
//! kind (arcs of any span, turns about one axis, caps of orientations, few readings, noise
//! up to 8 %), each refusal of the least-squares ellipse and ellipsoid fits and of the turn
//! calibrator is checked against the same figure recomputed here, independently of the
//! library's own arithmetic:
//!
//! * a count of readings, counted;
//! * an arc, from the readings' directions about the calibration the fit arrives at without
//!   the refusal (or about the circle fitted to them, when the fit itself fails), sorted
//!   here by `atan2`, less the noise allowance at its ends — and against the arc the
//!   simulation actually turned;
//! * a dilution, rebuilt here from its definition (each direction cell's readings weighed as
//!   one, the information matrix, the worst direction);
//! * a noise, from the residuals recomputed here; a bound, from its Student-t widening;
//! * the angle a turn turned, against the simulation's.

mod common;

use common::*;
use nalgebra::{Matrix3, SMatrix, SVector, Vector2, Vector3};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use truenorth_calib::quality::FitLimits;
use truenorth_calib::quality::{ARC_END_NOISE_SIGMAS, MODEL_ERROR_REL};
use truenorth_calib::{
    EllipseConfig, EllipsoidConfig, MIN_POINTS_3D, TurnCompassCalibrator, fit_ellipse,
    fit_ellipsoid,
};
use truenorth_compass::{CompassCalibration2d, CompassCalibration3d};
use truenorth_core::{Calibrator, Error, Mag2Sample, SplitMix64};

fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(29),
        ..ProptestConfig::default()
    }
}

/// Span, degrees, of the directions of `h` (2-D): 360° less the largest gap between them
/// in angle order.
fn span_deg(h: &[Vector2<f64>]) -> f64 {
    let mut a: Vec<f64> = h
        .iter()
        .filter(|v| v.norm() > 0.0)
        .map(|v| v.y.atan2(v.x))
        .collect();
    if a.is_empty() {
        return 0.0;
    }
    a.sort_by(f64::total_cmp);
    let mut gap = a[0] + std::f64::consts::TAU - a[a.len() - 1];
    for w in a.windows(2) {
        gap = gap.max(w[1] - w[0]);
    }
    (std::f64::consts::TAU - gap).to_degrees()
}

/// The centre of the least-squares circle `x² + y² + Dx + Ey + F = 0` (Kåsa 1976).
fn kasa_centre(p: &[Vector2<f64>]) -> Option<Vector2<f64>> {
    let mean = p.iter().sum::<Vector2<f64>>() / p.len() as f64;
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for q in p {
        let d = q - mean;
        let row = Vector3::new(d.x, d.y, 1.0);
        a += row * row.transpose();
        b -= row * d.norm_squared();
    }
    let s = a.try_inverse()? * b;
    Some(mean + Vector2::new(-0.5 * s[0], -0.5 * s[1]))
}

/// The RMS of `|cal(p)|/F − 1` over `(n − params)` degrees of freedom.
fn noise_2d(p: &[Vector2<f64>], cal: &CompassCalibration2d, field: f64, params: usize) -> f64 {
    let ss: f64 = p
        .iter()
        .map(|q| (cal.correct(q).norm() / field - 1.0).powi(2))
        .sum();
    (ss / (p.len() - params) as f64).sqrt()
}

fn noise_3d(p: &[Vector3<f64>], cal: &CompassCalibration3d, field: f64) -> f64 {
    let ss: f64 = p
        .iter()
        .map(|q| (cal.correct(q).norm() / field - 1.0).powi(2))
        .sum();
    (ss / (p.len() - 9) as f64).sqrt()
}

/// The equal-area cell of a direction: 8 bands uniform in `z`, 16 sectors of longitude.
fn cell(u: &Vector3<f64>) -> usize {
    let band = (((u.z + 1.0) * 4.0) as usize).min(7);
    let lon = u.y.atan2(u.x).rem_euclid(std::f64::consts::TAU);
    let sector = ((lon / std::f64::consts::TAU * 16.0) as usize).min(15);
    band * 16 + sector
}

/// The dilution of the directions `u`, from its definition: the information matrix
/// `Σ_cells mean(φφᵀ)` of `φ(u) = (−u, u_x², 2u_xu_y, 2u_xu_z, u_y², 2u_yu_z, u_z²)`, then
/// `√(K · max_u trace(G(u) A⁻¹ G(u)ᵀ))` over 256 directions of a Fibonacci lattice, `G(u)`
/// the Jacobian of the direction error `(I − uuᵀ)(E u − d)`; infinite when `A` is singular.
fn dilution(u: &[Vector3<f64>]) -> f64 {
    let mut sums = vec![(0usize, SMatrix::<f64, 9, 9>::zeros()); 128];
    for v in u {
        let phi = SVector::<f64, 9>::from([
            -v.x,
            -v.y,
            -v.z,
            v.x * v.x,
            2.0 * v.x * v.y,
            2.0 * v.x * v.z,
            v.y * v.y,
            2.0 * v.y * v.z,
            v.z * v.z,
        ]);
        let c = &mut sums[cell(v)];
        c.0 += 1;
        c.1 += phi * phi.transpose();
    }
    let cells = sums.iter().filter(|c| c.0 > 0).count();
    let a: SMatrix<f64, 9, 9> = sums
        .iter()
        .filter(|c| c.0 > 0)
        .map(|c| c.1 / c.0 as f64)
        .sum();
    let Some(inv) = a.try_inverse() else {
        return f64::INFINITY;
    };
    let golden = std::f64::consts::PI * (3.0 - 5.0f64.sqrt());
    let pairs = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
    let mut worst: f64 = 0.0;
    for k in 0..256 {
        let z = 1.0 - (2.0 * k as f64 + 1.0) / 256.0;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = (golden * k as f64).sin_cos();
        let w = Vector3::new(r * c, r * s, z);
        let proj = Matrix3::identity() - w * w.transpose();
        let mut g = SMatrix::<f64, 3, 9>::zeros();
        for i in 0..3 {
            g.set_column(i, &(-proj.column(i)));
        }
        for (j, &(p, q)) in pairs.iter().enumerate() {
            let mut e = Vector3::zeros();
            e[p] += w[q];
            if p != q {
                e[q] += w[p];
            }
            g.set_column(3 + j, &(proj * e));
        }
        worst = worst.max((g * inv * g.transpose()).trace());
    }
    let d = (cells as f64 * worst).sqrt();
    if d.is_finite() && a.cholesky().is_some() {
        d
    } else {
        f64::INFINITY
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a.is_infinite() && b.is_infinite()) || (a - b).abs() <= rel * a.abs().max(b.abs())
}

/// The Student-t widening of a 3σ bound from `dof` degrees of freedom, `t_ν/3` at the
/// two-sided 99.73 % point: between 1 and, for `ν ≥ 3`, the first terms of its expansion
/// about the normal with the next ones' growth allowed for, `1 + 2.5/ν + 10/ν² + 40/ν³`
/// (for `x = 3`, `t ≈ x + (x³ + x)/(4ν) + …`; the exact value is 3.07 at ν = 3, 1.83 at
/// 5, 1.36 at 10); at most 80 below (78.6 for one degree of freedom, 6.4 for two).
fn widening_is_plausible(w: f64, dof: f64) -> bool {
    let most = if dof >= 3.0 {
        1.0 + 2.5 / dof + 10.0 / (dof * dof) + 40.0 / (dof * dof * dof)
    } else {
        80.0
    };
    w >= 1.0 - 1e-12 && w <= most
}

/// No limit on the residual or the bound (the axis ratio keeps its default).
fn unlimited() -> FitLimits {
    FitLimits {
        max_residual_rel: f64::MAX,
        max_heading_error_bound_deg: f64::MAX,
        ..FitLimits::default()
    }
}

/// Checks a refusal of the 2-D fit of `pts`, whose true headings span `true_span` degrees
/// with per-axis noise `noise` (relative to the field).
fn check_2d(pts: &[Vector2<f64>], e: &Error, true_span: f64) -> Result<(), TestCaseError> {
    let relaxed = EllipseConfig {
        min_arc_deg: 0.0,
        limits: unlimited(),
        ..EllipseConfig::default()
    };
    match *e {
        Error::TooFewPoints { got, .. } => prop_assert_eq!(got, pts.len()),
        Error::InsufficientCoverage {
            covered_deg,
            noise_deg,
            need_deg,
        } => {
            prop_assert_eq!(need_deg, 200.0);
            // The span between the outermost directions, about the fit without the refusal
            // (with the allowance 2·3σ for the noise at its ends, σ recomputed here from the
            // residuals), or about the circle fitted to the readings when the fit itself
            // fails (no allowance). The directions are binned in 0.5° bins and the span
            // rounded down: within a degree and a half. The fit takes its noise from its
            // monomial sums, exact to first order in the residual σ, so the allowance is
            // right to about 2·3σ·2σ more.
            let about_fit = fit_ellipse(pts, &relaxed).ok().map(|s| {
                let h: Vec<Vector2<f64>> = pts.iter().map(|p| s.params.correct(p)).collect();
                let sigma = noise_2d(pts, &s.params, s.quality.field_magnitude, 5);
                let allowance = (2.0 * ARC_END_NOISE_SIGMAS * sigma).to_degrees();
                let tol = 1.5 + (2.0 * ARC_END_NOISE_SIGMAS * 2.0 * sigma * sigma).to_degrees();
                (span_deg(&h), allowance, tol)
            });
            let about_circle = kasa_centre(pts).map(|c| {
                let h: Vec<Vector2<f64>> = pts.iter().map(|p| p - c).collect();
                (span_deg(&h), 0.0, 1.5)
            });
            prop_assert!(
                [about_fit, about_circle]
                    .iter()
                    .flatten()
                    .any(|&(span, allowance, tol)| {
                        (covered_deg - span.floor()).abs() <= 1.5
                            && (noise_deg - allowance).abs() <= tol
                    }),
                "covered {covered_deg} less {noise_deg} vs fit {about_fit:?} ({:?}), circle {about_circle:?}",
                fit_ellipse(pts, &relaxed).err()
            );
            // And the span it names is the one the readings turned through, to within what
            // a fit of a short arc can distort: never understated by half or more.
            prop_assert!(
                covered_deg >= 0.5 * true_span.min(360.0) - 1.0,
                "covered {covered_deg}, turned {true_span}"
            );
        }
        Error::TooUncertain {
            bound_deg,
            points,
            noise_rel,
            ..
        } => {
            prop_assert_eq!(points, pts.len());
            let s = fit_ellipse(pts, &relaxed).unwrap();
            let sigma = noise_2d(pts, &s.params, s.quality.field_magnitude, 5);
            // The fit's report takes its residual from the fit's monomial sums, to first
            // order in the residual (see `quality::assess_2d_from_moments`: relative error
            // about the residual itself, which averages out over a full turn but not over
            // a few readings of an arc): within twice it.
            prop_assert!(
                close(noise_rel, sigma, 2.0 * sigma),
                "{noise_rel} vs {sigma}"
            );
            let w = bound_deg / s.quality.heading_error_bound_deg();
            prop_assert!(widening_is_plausible(w, points as f64 - 5.0), "{w}");
        }
        Error::NotAnEllipse { .. } | Error::Degenerate { .. } | Error::NoConvergence { .. } => {}
        ref other => prop_assert!(false, "unexpected refusal {other}"),
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(256))]

    /// Arcs of 1°–400°, 3–400 readings, noise up to 8 %: every refusal's figures.
    #[test]
    fn figures_of_2d_refusals_are_true(
        span in 1.0f64..400.0, start in 0.0f64..360.0, n in 3usize..400,
        noise in prop_oneof![Just(0.0), 0.0f64..0.08], hx in -0.6f64..0.6, hy in -0.6f64..0.6,
        ratio in 1.0f64..1.4, angle in -1.6f64..1.6, seed in 0u64..10_000,
    ) {
        let m = Model2::new(Vector2::new(hx, hy), ratio, angle, 1.0);
        let turn = m.turn(n, start, span, noise, seed);
        let pts: Vec<Vector2<f64>> = turn.iter().map(|t| t.1).collect();
        if let Err(e) = fit_ellipse(&pts, &EllipseConfig::default()) {
            check_2d(&pts, &e, span * (n - 1) as f64 / n as f64)?;
        }
        // The turn calibrator's figure: the angle turned, within the distance between the
        // last confirmed extremum and the true end (it reads the ends from its extrema's
        // neighbours; a quarter turn) of what the simulation turned.
        let mut turn_cal = TurnCompassCalibrator::default();
        for (k, (_, mag)) in turn.iter().enumerate() {
            turn_cal.push(&Mag2Sample { t_s: 0.05 * k as f64, mag: *mag }).unwrap();
        }
        if let Err(Error::IncompleteTurn { turned_deg, need_deg }) = turn_cal.solve() {
            prop_assert_eq!(need_deg, 360.0);
            prop_assert!(turned_deg <= span + 90.0, "turned {turned_deg} of {span}");
        }
    }
}

/// Checks a refusal of the 3-D fit of `pts`.
fn check_3d(pts: &[Vector3<f64>], e: &Error) -> Result<(), TestCaseError> {
    let relaxed = EllipsoidConfig {
        limits: unlimited(),
        max_noise_dilution: f64::MAX,
        ..EllipsoidConfig::default()
    };
    let fitted = || fit_ellipsoid(pts, &relaxed);
    // The directions about the fit without the refusal, and about the centre of the
    // readings' bounding box without a soft iron (the check made before fitting).
    let about_fit = || {
        fitted().ok().map(|s| {
            let u: Vec<Vector3<f64>> = pts
                .iter()
                .map(|p| s.params.correct(p).normalize())
                .collect();
            (s, dilution(&u))
        })
    };
    let about_box = || {
        let lo = pts
            .iter()
            .fold(Vector3::repeat(f64::INFINITY), |a, p| a.inf(p));
        let hi = pts
            .iter()
            .fold(Vector3::repeat(f64::NEG_INFINITY), |a, p| a.sup(p));
        let c = (lo + hi) * 0.5;
        let u: Vec<Vector3<f64>> = pts.iter().map(|p| (p - c).normalize()).collect();
        dilution(&u)
    };
    match *e {
        Error::TooFewPoints { got, need } => {
            prop_assert_eq!((got, need), (pts.len(), MIN_POINTS_3D));
        }
        Error::Undetermined {
            dilution: d,
            error_deg,
            model_error_rel,
            max_deg,
            ..
        } => {
            prop_assert_eq!(model_error_rel, MODEL_ERROR_REL);
            prop_assert!(close(error_deg, (d * MODEL_ERROR_REL).to_degrees(), 1e-12));
            prop_assert!(error_deg > max_deg);
            let fit = about_fit().map(|(_, g)| g);
            let boxed = about_box();
            // Inverting the information matrix loses about its condition number (≈ G²)
            // times the rounding of a double: near-singular supports agree less closely.
            let tol = 1e-6 + 1e-15 * d * d;
            prop_assert!(
                [fit, Some(boxed)]
                    .iter()
                    .flatten()
                    .any(|g| close(*g, d, tol)),
                "dilution {d} vs fit {fit:?}, box {boxed}"
            );
        }
        Error::TooNoisyForOrientations {
            noise_rel,
            dilution: d,
            product,
            max_product,
        } => {
            prop_assert!(close(product, noise_rel * d, 1e-12) && product > max_product);
            let (s, g) = about_fit().expect("the fit without the refusal");
            prop_assert!(close(d, g, 1e-6 + 1e-15 * d * d), "dilution {d} vs {g}");
            let sigma = noise_3d(pts, &s.params, s.quality.field_magnitude);
            prop_assert!(
                close(noise_rel, sigma, 1e-9),
                "noise {noise_rel} vs {sigma}"
            );
        }
        Error::TooUncertain {
            bound_deg,
            points,
            noise_rel,
            ..
        } => {
            prop_assert_eq!(points, pts.len());
            let s = fitted().unwrap();
            let sigma = noise_3d(pts, &s.params, s.quality.field_magnitude);
            prop_assert!(
                close(noise_rel, sigma, 1e-9),
                "noise {noise_rel} vs {sigma}"
            );
            let w = bound_deg / s.quality.heading_error_bound_deg();
            prop_assert!(widening_is_plausible(w, points as f64 - 9.0), "{w}");
        }
        Error::NotAnEllipse { .. } | Error::Degenerate { .. } | Error::NoConvergence { .. } => {}
        ref other => prop_assert!(false, "unexpected refusal {other}"),
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(96))]

    /// Turns about one axis (with a hand's wobble), caps of orientations, tumbles; 3–2000
    /// readings; noise up to 8 %: every refusal's figures.
    #[test]
    fn figures_of_3d_refusals_are_true(
        kind in 0usize..3, n in 3usize..2000, span in 30.0f64..360.0, wobble in 0.0f64..5.0,
        cap in 20.0f64..180.0, noise in prop_oneof![Just(0.0), 0.0f64..0.08], seed in 0u64..10_000,
    ) {
        let mut rng = SplitMix64::new(seed);
        let m = Model3::random(&mut rng, 50.0, 0.6, 0.15, noise);
        let att = match kind {
            0 => axis_turn_attitudes(&mut rng, n, span, wobble),
            1 => {
                let centre = uniform_rotation(&mut rng);
                (0..n)
                    .map(|_| loop {
                        let r = uniform_rotation(&mut rng);
                        if (r.inverse() * centre).angle() <= cap.to_radians() {
                            break r;
                        }
                    })
                    .collect()
            }
            _ => tumble_attitudes(&mut rng, n),
        };
        let pts: Vec<Vector3<f64>> = att.iter().map(|r| m.raw(r, &mut rng)).collect();
        if let Err(e) = fit_ellipsoid(&pts, &EllipsoidConfig::default()) {
            check_3d(&pts, &e)?;
        }
    }
}
