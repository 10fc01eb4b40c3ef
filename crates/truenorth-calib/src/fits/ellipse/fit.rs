//! Least-squares ellipse calibration of a two-axis compass: a direct, ellipse-specific
//! algebraic fit (Fitzgibbon, Pilu & Fisher 1999, in the numerically stable form of
//! Halíř & Flusser 1998) refined by Levenberg–Marquardt on the Sampson distance, turned into
//! a hard iron and a symmetric soft iron.
//!
//! Steps of [`fit_ellipse`]:
//! 1. Refuse too few points and degenerate sets (all equal, collinear).
//! 2. Normalise: centroid to the origin, RMS radius 1 (see the `normalise` module), so the
//!    fit is equivariant under rotation, translation and scaling of the input.
//! 3. Direct fit ([`fit_ellipse_direct`](crate::fit_ellipse_direct)): minimise the algebraic distance
//!    `Σ (a x² + b xy + c y² + d x + e y + f)²` subject to `4ac − b² = 1`.
//! 4. Refuse when the data are not an ellipse: the best conic without the ellipse
//!    constraint is a hyperbola or parabola, or the ellipse is flatter than
//!    [`FitLimits::max_axis_ratio`](crate::quality::FitLimits::max_axis_ratio).
//! 5. Geometric refinement: Levenberg–Marquardt on the Sampson distance
//!    `g(m) / |∇g(m)|` with `g(m) = |B (m − c)|² − 1` (Sampson 1982; a first-order
//!    approximation of the orthogonal distance, the maximum-likelihood residual for
//!    isotropic sensor noise), over the centre `c` and the symmetric matrix `B`.
//! 6. Calibration: `hard_iron = c`, `soft_iron = F·B` with `B` the symmetric positive
//!    definite square root (no arbitrary rotation) and `F = √(a·b)`, the geometric mean of
//!    the semi-axes, so that `det(soft_iron) = 1`: the soft iron preserves area and the
//!    fitted field is the radius of the circle with the ellipse's area.
//!    It runs only when it could change the answer: when the direct fit's own noise level,
//!    eccentricity and spread of readings say that one step could move the heading by more
//!    than a quarter of the direct fit's heading-error bound (see `refinement_could_matter`),
//!    or when the readings do not go all the way round.
//! 7. Quality report from the monomial sums the direct fit already formed (see
//!    [`crate::quality`]; one more pass over the readings for the coverage), and refusals
//!    on coverage (an arc shorter than [`EllipseConfig::min_arc_deg`] of calibrated
//!    heading), on the residual and on the heading bound. None of them depends on the order
//!    of the readings, and more readings consistent with the same calibration can only
//!    widen the arc and shrink the bound. The condition number of the headings seen (each
//!    0.5° once) is reported, not judged: a reading in a new direction adds information,
//!    yet can raise the largest eigenvalue more than the smallest.
//!
//! An ellipse fit cannot see a rotation of the soft iron (any rotation of the corrected
//! circle is another circle); choosing the symmetric root assumes the soft iron has none,
//! which holds for induced magnetisation (its matrix is symmetric) and leaves any mounting
//! rotation to be removed as a heading offset.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

extern crate alloc;

use nalgebra::{Matrix2, Matrix3, SMatrix, SVector, Vector2, Vector3};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{Error, Result, Solution, Validate};

use crate::fits::lm::{self, NormalAccumulator, NormalEquations};
use crate::fits::normalise::Normaliser;
use crate::numerics::blocks::BLOCK;
use crate::numerics::linalg::sym_sqrt2;
use crate::numerics::readings::{Readings, replay_points};
use crate::numerics::segments::{RunFold, by_blocks, fold};
use crate::quality::{self, Assessment2d, BOUND_SIGMAS, Moments2};

use crate::fits::ellipse::config::EllipseConfig;
use crate::fits::ellipse::config::MIN_POINTS_JUDGED_2D;
use crate::fits::ellipse::direct::Ellipse;
use crate::fits::ellipse::direct::check_axis_ratio;
use crate::fits::ellipse::direct::denormalise;
use crate::fits::ellipse::direct::direct_normalised;
use crate::fits::ellipse::direct::from_params;
use crate::fits::ellipse::direct::to_params;
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Sampson residuals and their analytic Jacobian, accumulated as normal equations.
///
/// With `v = q − c`, `w = B v`, `z = B w`, `s = |z|`: `g = |w|² − 1`, `|∇g| = 2s`, residual
/// `r = g / (2s)`. Both depend on `B` only through `A = B²` (`g = vᵀA v − 1`, `z = A v`),
/// so the pass over the points differentiates with respect to `(c, A)`, which takes fewer
/// products per point than differentiating through `B` directly:
/// `∂r/∂c = (−z + k·A z)/s` with `k = r/s` (as `∂s/∂c = −A z/s`), and
/// `∂r/∂A_E = (½ vᵀE v − k·zᵀE v)/s` for each symmetric basis matrix `E`. The chain rule
/// through `A = B²`, a linear map of the parameter changes that is the same for every point,
/// then gives the normal equations in the refinement's parameters `(c, B)` (see
/// [`square_jacobian`]).
pub(crate) fn sampson_normal_equations(
    points: &[Vector2<f64>],
    norm: &Normaliser<2>,
    p: &SVector<f64, 5>,
) -> Option<NormalEquations<5>> {
    // A slice replays without failing.
    sampson_normal_equations_of(points, norm, p).unwrap_or(None)
}

/// [`sampson_normal_equations`] of readings replayed (see [`Readings`]); an error replaying
/// them is the `Err`.
fn sampson_normal_equations_of<R: Readings<2> + ?Sized>(
    points: &R,
    norm: &Normaliser<2>,
    p: &SVector<f64, 5>,
) -> Result<Option<NormalEquations<5>>> {
    let (cx, cy) = (p[0], p[1]);
    let b = Matrix2::new(p[2], p[3], p[3], p[4]);
    let a = b * b;
    let (a11, a12, a22) = (a[(0, 0)], a[(0, 1)], a[(1, 1)]);
    let (mx, my) = (norm.centre.x, norm.centre.y);
    let inv = 1.0 / norm.scale;
    // A block of points at a time (see `BLOCK`): first every point's gradient row and
    // residual, then the sums; segment by segment (see `fold`).
    let add = |acc: &mut NormalAccumulator<5, 6>, [qx, qy]: &[[f64; BLOCK]; 2], len: usize| {
        let [j0, j1, j2, j3, j4, res] = &mut acc.cols;
        for i in 0..BLOCK {
            let vx = (qx[i] - mx) * inv - cx;
            let vy = (qy[i] - my) * inv - cy;
            let (zx, zy) = (a11 * vx + a12 * vy, a12 * vx + a22 * vy);
            let (azx, azy) = (a11 * zx + a12 * zy, a12 * zx + a22 * zy);
            let s = (zx * zx + zy * zy).sqrt();
            let inv_s = 1.0 / s;
            let r = (vx * zx + vy * zy - 1.0) * 0.5 * inv_s;
            let k = r * inv_s;
            // Symmetric basis: E11 → a_x b_x; E12 → a_x b_y + a_y b_x; E22 → a_y b_y.
            let e11 = vx * (0.5 * vx - k * zx);
            let e12 = vx * vy - k * (zx * vy + zy * vx);
            let e22 = vy * (0.5 * vy - k * zy);
            // A reading at the very centre has no defined distance; leave it out, and the
            // rows past the end of the data: a row of zeros adds nothing.
            let keep = s > 1e-12 && i < len;
            j0[i] = if keep { (-zx + azx * k) * inv_s } else { 0.0 };
            j1[i] = if keep { (-zy + azy * k) * inv_s } else { 0.0 };
            j2[i] = if keep { e11 * inv_s } else { 0.0 };
            j3[i] = if keep { e12 * inv_s } else { 0.0 };
            j4[i] = if keep { e22 * inv_s } else { 0.0 };
            res[i] = if keep { r } else { 0.0 };
        }
        acc.add_block();
    };
    let acc = fold(
        points,
        &RunFold {
            start: NormalAccumulator::<5, 6>::new,
            add: by_blocks(add),
            merge: |acc: &mut NormalAccumulator<5, 6>, later| acc.merge(&later),
        },
    )?;
    Ok(acc
        .finish()
        .and_then(|ne| ne.reparametrised(&square_jacobian(&b))))
}

/// `∂(c, A)/∂(c, B)` for `A = B²`, `B` symmetric, from the parameters
/// `(c_x, c_y, B₁₁, B₁₂, B₂₂)` to `(c_x, c_y, A₁₁, A₁₂, A₂₂)`: `dA = B dB + dB B`, column by
/// column for the symmetric basis matrices of `B`.
fn square_jacobian(b: &Matrix2<f64>) -> SMatrix<f64, 5, 5> {
    let mut m = SMatrix::<f64, 5, 5>::identity();
    let basis = [
        Matrix2::new(1.0, 0.0, 0.0, 0.0),
        Matrix2::new(0.0, 1.0, 1.0, 0.0),
        Matrix2::new(0.0, 0.0, 0.0, 1.0),
    ];
    for (j, e) in basis.iter().enumerate() {
        let da = b * e + e * b;
        m[(2, 2 + j)] = da[(0, 0)];
        m[(3, 2 + j)] = da[(0, 1)];
        m[(4, 2 + j)] = da[(1, 1)];
    }
    m
}

/// The least-squares ellipse calibration of `points` (raw `(mag_x, mag_y)` readings of a
/// level compass turning through at least [`EllipseConfig::min_arc_deg`]), with its
/// quality report — or a typed refusal saying why the data cannot support one (an invalid
/// `config` is refused first; fewer than ten readings are refused as too few to judge the
/// fit by). See the module documentation for the steps.
pub fn fit_ellipse(
    points: &[Vector2<f64>],
    config: &EllipseConfig,
) -> Result<Solution<CompassCalibration2d>> {
    fit_ellipse_readings(points, config)
}

/// [`fit_ellipse`] of readings replayed from wherever they are kept (see [`Readings`]): the
/// same result, bit for bit, as of the same readings in one slice. An error replaying them
/// is returned as it is.
pub fn fit_ellipse_readings<R: Readings<2> + ?Sized>(
    points: &R,
    config: &EllipseConfig,
) -> Result<Solution<CompassCalibration2d>> {
    config.validate()?;
    let mut sol = match fit_unchecked(points, config) {
        Ok(sol) => sol,
        Err(e) => return Err(explain_short_arc(points, config, e)?),
    };
    sol.quality = quality::with_expected_field(sol.quality, config.expected_field);
    Ok(sol)
}

/// A fit that failed on a short arc is better explained by the arc than by the symptom
/// (a hyperbola, a refinement that wanders along a flat valley): if the readings span
/// less than the minimum arc seen from their best-fitting circle, say so instead.
/// An error replaying the readings is returned as the `Err`.
fn explain_short_arc<R: Readings<2> + ?Sized>(
    points: &R,
    config: &EllipseConfig,
    e: Error,
) -> Result<Error> {
    if !matches!(
        e,
        Error::NotAnEllipse { .. } | Error::NoConvergence { .. } | Error::Degenerate { .. }
    ) {
        return Ok(e);
    }
    Ok(match circle_centre(points)? {
        Some(c) => {
            let cov = quality::coverage_of(points, &c)?;
            quality::require_arc(&cov, 0.0, config.min_arc_deg)
                .err()
                .unwrap_or(e)
        }
        None => e,
    })
}

/// Centre of the algebraic best-fitting circle `x² + y² + D x + E y + F = 0` (Kåsa 1976),
/// a linear least-squares problem that any three non-collinear points determine. Used only
/// to measure the arc when the ellipse fit fails.
/// An error replaying the readings is the `Err`; `Ok(None)` when there is no such circle.
fn circle_centre<R: Readings<2> + ?Sized>(points: &R) -> Result<Option<Vector2<f64>>> {
    let Ok(norm) = Normaliser::of_readings(points, "point")? else {
        return Ok(None);
    };
    let mut a = Matrix3::zeros();
    let mut rhs = Vector3::zeros();
    replay_points(points, |p| {
        let q = norm.apply(p);
        let row = Vector3::new(q.x, q.y, 1.0);
        a += row * row.transpose();
        rhs -= row * q.norm_squared();
    })?;
    let Some(chol) = a.cholesky() else {
        return Ok(None);
    };
    let sol = chol.solve(&rhs);
    let c = Vector2::new(-0.5 * sol[0], -0.5 * sol[1]);
    let c = norm.centre + c * norm.scale;
    Ok(c.iter().all(|x| x.is_finite()).then_some(c))
}

fn fit_unchecked<R: Readings<2> + ?Sized>(
    points: &R,
    config: &EllipseConfig,
) -> Result<Solution<CompassCalibration2d>> {
    let (norm, direct, moments) = direct_normalised(points, config.limits.max_axis_ratio)?;
    // Fewer than five residuals cannot judge a fit: the chance that noise alone makes the
    // residual standard deviation look ten times too small is P(χ²_ν < ν/100), 8 % for one
    // residual degree of freedom, 0.5 % for two, 3·10⁻⁸ for five. A short noisy arc fitted
    // by a small ellipse around itself is exactly such a fit.
    if points.len() < MIN_POINTS_JUDGED_2D {
        return Err(Error::TooFewPoints {
            got: points.len(),
            need: MIN_POINTS_JUDGED_2D,
        });
    }
    // The calibration of an ellipse (in normalised coordinates), refused when not finite,
    // and its report from the moments the direct fit already has, and one pass for the
    // coverage.
    let calibration = |e: &Ellipse| -> Result<(CompassCalibration2d, f64)> {
        let (cal, field) = denormalise(&norm, e).calibration();
        if !(field.is_finite() && field > 0.0 && cal.soft_iron.iter().all(|x| x.is_finite())) {
            return Err(Error::Degenerate {
                reason: "the fitted ellipse is not finite; check the input scale",
            });
        }
        Ok((cal, field))
    };
    let report = |e: &Ellipse, cal: &CompassCalibration2d, field: f64| -> Result<Assessment2d> {
        let directions = quality::calibrated_directions_2d(points, cal)?;
        Ok(quality::assess_2d_from_moments(
            &moments,
            points.len(),
            &e.centre,
            &e.unit_map,
            directions,
            field,
        ))
    };
    let (direct_cal, direct_field) = calibration(&direct)?;
    // Where the refinement runs whatever the direct fit's report says, that report would go
    // unread: its pass over the readings is skipped.
    let direct_report = if config.refine && surely_refined(&moments, points.len(), &direct) {
        None
    } else {
        Some(report(&direct, &direct_cal, direct_field)?)
    };
    let refined = match &direct_report {
        Some(a) => config.refine && refinement_could_matter(&moments, &direct, a),
        None => true,
    };
    let (cal, mut a, e) = match direct_report {
        Some(a) if !refined => (direct_cal, a, direct),
        _ => {
            let out = lm::minimise_replayed(
                "ellipse geometric refinement",
                to_params(&direct),
                config.max_iterations,
                points.len(),
                |p| sampson_normal_equations_of(points, &norm, p),
            )??;
            let e = from_params(&out.params);
            // |B v| depends on B only through B², so take the positive-definite root of B²
            // (the refinement may have flipped the sign of B).
            let unit_map = sym_sqrt2(&(e.unit_map * e.unit_map)).ok_or(Error::Degenerate {
                reason: "the refined ellipse collapsed to a line; record a fuller turn",
            })?;
            let e = Ellipse {
                centre: e.centre,
                unit_map,
            };
            check_axis_ratio(&e, config.limits.max_axis_ratio)?;
            let (cal, field) = calibration(&e)?;
            let a = report(&e, &cal, field)?;
            (cal, a, e)
        }
    };
    // Neither fit is free of the second-order bias of noisy readings, which no number of
    // readings removes: the bound derived for the direct fit (see `refinement_could_matter`)
    // holds for the refined one too, which removes part of the bias (`tests/bias_bound.rs`:
    // the refined fit's error is about 45 % of the bound at axis ratios 1.5–3 and noise of
    // 3–8 % of the field, and beyond its 3σ part alone).
    a.quality.heading_error_systematic_deg =
        bias_bound_rad(&moments, points.len(), &e, &a).to_degrees();
    quality::require_arc(
        &a.coverage,
        a.quality.heading_noise_rms_deg.to_radians(),
        config.min_arc_deg,
    )?;
    if !(a.quality.fit.residual_rms_rel <= config.limits.max_residual_rel) {
        return Err(Error::NotAnEllipse {
            detail: " (the readings stray from the best ellipse by more than max_residual_rel of the field)",
        });
    }
    // The refusal widens the bound to the Student-t quantile of its σ's degrees of freedom
    // (the report keeps the plain 3σ): a fit of a few readings estimates σ from one or two
    // residuals and can look certain by chance.
    quality::require_certain(
        &a.quality,
        a.quality.fit.points as f64 - 5.0,
        config.limits.max_heading_error_bound_deg,
    )?;
    Ok(Solution {
        params: cal,
        quality: a.quality,
    })
}

/// Largest heading shift of the geometric refinement, as a share of the direct fit's own
/// heading-error bound ([`CompassQuality::heading_error_3sigma_deg`](truenorth_core::CompassQuality::heading_error_3sigma_deg)), for which the
/// refinement is skipped: a quarter of the bound changes no heading by a statistically
/// meaningful amount.
const SKIPPED_STEP_SHARE_OF_BOUND: f64 = 0.25;

/// Largest `h₁ + h₂` (first and second harmonics of the directions, see
/// `refinement_could_matter`; 1 each for readings all in one direction, 0 for an even turn)
/// for which the direct fit may stand unrefined: a tenth of their range, where the
/// perturbation about an even turn still holds.
const MAX_UNEVENNESS_UNREFINED: f64 = 0.1;

/// Whether refining the direct fit `e` (normalised coordinates, moments `m`, report `a`)
/// could move the heading by more than [`SKIPPED_STEP_SHARE_OF_BOUND`] of its bound.
///
/// In the frame of the calibrated circle, `w = B (q − c)`, isotropic sensor noise becomes
/// anisotropic, with variances along the eigenvectors of `A = B²` in the ratio of its
/// eigenvalues `λ₁ ≥ λ₂`; write `κ = (λ₁ − λ₂)/(λ₁ + λ₂)` and `σ` for the mean relative
/// noise. The direct fit then differs from the geometric one in two ways:
///
/// * weighting: the algebraic residual `g = |w|² − 1 ≈ 2r` has a variance that varies round
///   the circle as `1 + κ cos 2θ`, which the direct fit ignores and the Sampson distance
///   corrects. Both are unbiased to first order; the weighted one has the smaller variance,
///   so their difference has the variance of the excess, `E[v]·E[1/v] − 1 ≈ κ²/2` of the
///   heading variance `s²` (`s` the 1σ heading error of the calibration);
/// * bias: to second order in the noise the algebraic fit of a unit circle whose points
///   have variances `σ₁², σ₂²` along the axes is the ellipse with semi-axis ratio
///   `1 + 4(σ₁² − σ₂²)` (the expected scatter matrix gains `σ²` terms; eliminating the
///   constant term and minimising under `4ac = 1` gives `a/c = √((1/8 + 2σ₂²)/(1/8 + 2σ₁²))`).
///   That leaves a two-cycle heading error of amplitude `2(σ₁² − σ₂²) = 4σ²κ` radians. An
///   uneven spread of the readings round the circle adds a bias of the same order; its
///   first and second harmonics `h₁ = |Σu|/n`, `h₂ = |Σ(u_x² − u_y², 2u_xu_y)|/n` enter with
///   the same factor, so `b = 4σ²(κ + h₁ + h₂)`.
///
/// The refinement is skipped when `√(b² + κ²s²/2) ≤ ¼ · 3s`. The bias term is a
/// perturbation about readings spread evenly round the circle; it is not trusted, and the
/// refinement always runs, when `h₁ + h₂` exceeds [`MAX_UNEVENNESS_UNREFINED`] (a partial
/// arc, where the algebraic fit is known to shrink towards the arc, or a turn and a bit).
/// Everything it needs comes from the moments and the report, without a pass over the
/// readings.
fn refinement_could_matter(m: &Moments2, e: &Ellipse, a: &Assessment2d) -> bool {
    let q = &a.quality;
    if surely_refined(m, q.fit.points, e) {
        return true;
    }
    let (h1, h2) = quality::direction_harmonics(m, q.fit.points, &e.centre, &e.unit_map);
    let sigma = q.heading_noise_rms_deg.to_radians();
    let s = (q.heading_error_3sigma_deg / BOUND_SIGMAS).to_radians();
    let Some(kappa) = quality::anisotropy_2d(&(e.unit_map * e.unit_map)) else {
        return true;
    };
    let bias = quality::direct_fit_bias_rad(sigma, kappa, h1, h2);
    let step = (bias * bias + 0.5 * kappa * kappa * s * s).sqrt();
    !(step <= SKIPPED_STEP_SHARE_OF_BOUND * BOUND_SIGMAS * s)
}

/// The bound `4σ²(κ + h₁ + h₂)` radians on the heading error that the second-order bias of
/// a fit of noisy readings leaves (see [`refinement_could_matter`]) for the ellipse `e`
/// with report `a`; `∞` where it cannot be computed.
fn bias_bound_rad(m: &Moments2, n: usize, e: &Ellipse, a: &Assessment2d) -> f64 {
    let (h1, h2) = quality::direction_harmonics(m, n, &e.centre, &e.unit_map);
    let sigma = a.quality.heading_noise_rms_deg.to_radians();
    quality::anisotropy_2d(&(e.unit_map * e.unit_map)).map_or(f64::INFINITY, |kappa| {
        quality::direct_fit_bias_rad(sigma, kappa, h1, h2)
    })
}

/// The part of [`refinement_could_matter`] that needs no report: whether the refinement runs
/// whatever the direct fit's bound, for `n` readings with moments `m` and the direct fit
/// `e` (too few readings to judge it, or readings spread too unevenly round the circle for
/// the perturbation argument).
fn surely_refined(m: &Moments2, n: usize, e: &Ellipse) -> bool {
    if n <= 5 {
        return true;
    }
    // Every quantity here is a rotation invariant of the readings (no heading bins), so
    // rotating the input never changes the choice.
    let (h1, h2) = quality::direction_harmonics(m, n, &e.centre, &e.unit_map);
    !(h1 + h2 <= MAX_UNEVENNESS_UNREFINED)
}
