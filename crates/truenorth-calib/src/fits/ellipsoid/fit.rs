//! Least-squares ellipsoid calibration of a three-axis magnetometer (hard iron plus a full
//! symmetric soft iron): a direct ellipsoid-specific algebraic fit (Li & Griffiths 2004)
//! refined by Levenberg–Marquardt on the geometric residual `|S (m − b)| − F`.
//!
//! Steps of [`fit_ellipsoid`]:
//! 1. Refuse too few points and degenerate sets (all equal, coplanar), and data whose
//!    orientations do not determine an ellipsoid (the information test of
//!    [`crate::quality::require_determined`], checked loosely about the bounding-box centre
//!    before the fit, and exactly about the fitted calibration after).
//! 2. Normalise (centroid, RMS radius; see the `normalise` module) for equivariance.
//! 3. Direct fit ([`fit_ellipsoid_direct`](crate::fit_ellipsoid_direct)): minimise the algebraic distance of the quadric
//!    `ax² + by² + cz² + 2fyz + 2gxz + 2hxy + 2px + 2qy + 2rz + d` subject to
//!    `4J − I² = 1` (Li & Griffiths 2004, eq. 5, with their `k = 4`), where
//!    `I = a + b + c` and `J = ab + bc + ca − f² − g² − h²`. The constraint makes the
//!    answer an ellipsoid; it is exact for ellipsoids whose shortest axis is at least half
//!    the longest (any plausible soft iron), and the refinement removes what bias remains.
//!    The linear terms are eliminated as in Halíř & Flusser (1998) and the 6×6 problem is
//!    solved as a symmetric eigenproblem (see the `linalg` module).
//! 4. Refuse when the best quadric without the constraint is not an ellipsoid (hyperboloid)
//!    or the ellipsoid is flatter than [`FitLimits::max_axis_ratio`](crate::quality::FitLimits::max_axis_ratio).
//! 5. Refinement: Levenberg–Marquardt over the centre `c` and a symmetric matrix `B` on
//!    `rᵢ = |B (mᵢ − c)| − 1`. With `S = F·B` this is `(|S (mᵢ − c)| − F)/F`, the geometric
//!    residual `|S(m − b)| − F` scaled by `1/F`. `F` grows with the ellipsoid, so this
//!    favours larger ones a little; where the readings do not hold it back (noisy readings
//!    crowded into a few directions) it may run away without converging, and then the
//!    direct fit stands.
//! 6. Calibration: `hard_iron = c`, `soft_iron = F·B` (`B` the symmetric positive-definite
//!    root, `F = (abc)^{1/3}` the geometric mean of the semi-axes, so `det(soft_iron) = 1`).
//! 7. Quality report (see [`crate::quality`]) and refusals on what the orientations
//!    determine, on the residual and on the heading bound.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

extern crate alloc;

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use truenorth_compass::CompassCalibration3d;
use truenorth_core::{Error, Result, Solution, Validate};

use crate::fits::lm::{self, NormalAccumulator, NormalEquations};
use crate::fits::normalise::Normaliser;
use crate::numerics::blocks::BLOCK;
use crate::numerics::linalg::sym_sqrt3;
use crate::numerics::readings::Readings;
use crate::numerics::segments::{RunFold, by_blocks, fold};
use crate::quality::{self, CompassUncertainty};

use crate::fits::ellipsoid::config::EllipsoidConfig;
use crate::fits::ellipsoid::config::MIN_POINTS_3D;
use crate::fits::ellipsoid::config::ORIENTATION_HINT;
use crate::fits::ellipsoid::config::PRE_FIT_SLACK;
use crate::fits::ellipsoid::direct::Ellipsoid;
use crate::fits::ellipsoid::direct::PAIRS;
use crate::fits::ellipsoid::direct::check_axis_ratio;
use crate::fits::ellipsoid::direct::denormalise;
use crate::fits::ellipsoid::direct::direct_normalised;
use crate::fits::ellipsoid::direct::from_params;
use crate::fits::ellipsoid::direct::to_params;
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Residuals `r = |B v| − 1` (`v = q − c`) and their Jacobian, accumulated as normal
/// equations.
///
/// `r` depends on `B` only through `A = B²` (`|B v| = √(vᵀA v)`), so the pass over the
/// points differentiates with respect to `(c, A)`, which takes fewer products per point than
/// going through `B`: with `z = A v`, `ρ = √(vᵀz)`, `∂r/∂c = −z/ρ` and
/// `∂r/∂A_kl = v_k v_l/ρ` (`v_k²/(2ρ)` on the diagonal). The chain rule through `A = B²`, a
/// linear map of the parameter changes that is the same for every point, then gives the
/// normal equations in the refinement's parameters `(c, B)` (see [`square_jacobian`]).
#[cfg(test)]
pub(crate) fn radial_normal_equations(
    points: &[Vector3<f64>],
    norm: &Normaliser<3>,
    p: &SVector<f64, 9>,
) -> Option<NormalEquations<9>> {
    // A slice replays without failing.
    radial_normal_equations_of(points, norm, p).unwrap_or(None)
}

/// `radial_normal_equations` (a test's reference) of readings replayed (see [`Readings`]); an error replaying
/// them is the `Err`.
fn radial_normal_equations_of<R: Readings<3> + ?Sized>(
    points: &R,
    norm: &Normaliser<3>,
    p: &SVector<f64, 9>,
) -> Result<Option<NormalEquations<9>>> {
    let e = from_params(p);
    let (c, b) = (e.centre, e.unit_map);
    let a = b * b;
    let a = (a + a.transpose()) * 0.5;
    let mu = norm.centre;
    let inv = 1.0 / norm.scale;
    // A block of points at a time (see `BLOCK`): first every point's gradient row and
    // residual, then the sums; segment by segment (see `fold`).
    let add = |acc: &mut NormalAccumulator<9, 10>, [qx, qy, qz]: &[[f64; BLOCK]; 3], len: usize| {
        let cols = &mut acc.cols;
        for i in 0..BLOCK {
            let v = [
                (qx[i] - mu.x) * inv - c.x,
                (qy[i] - mu.y) * inv - c.y,
                (qz[i] - mu.z) * inv - c.z,
            ];
            let z: [f64; 3] =
                core::array::from_fn(|k| a[(k, 0)] * v[0] + a[(k, 1)] * v[1] + a[(k, 2)] * v[2]);
            let rho = (v[0] * z[0] + v[1] * z[1] + v[2] * z[2]).sqrt();
            let inv_rho = 1.0 / rho;
            // A reading at the very centre has no defined direction; leave it out, and the
            // rows past the end of the data: a row of zeros adds nothing.
            let keep = rho > 1e-12 && i < len;
            for k in 0..3 {
                cols[k][i] = if keep { -z[k] * inv_rho } else { 0.0 };
            }
            for (k, &(r, s)) in PAIRS.iter().enumerate() {
                let d = if r == s {
                    0.5 * v[r] * v[r]
                } else {
                    v[r] * v[s]
                };
                cols[3 + k][i] = if keep { d * inv_rho } else { 0.0 };
            }
            cols[9][i] = if keep { rho - 1.0 } else { 0.0 };
        }
        acc.add_block();
    };
    let acc = fold(
        points,
        &RunFold {
            start: NormalAccumulator::<9, 10>::new,
            add: by_blocks(add),
            merge: |acc: &mut NormalAccumulator<9, 10>, later| acc.merge(&later),
        },
    )?;
    Ok(acc
        .finish()
        .and_then(|ne| ne.reparametrised(&square_jacobian(&b))))
}

/// `∂(c, A)/∂(c, B)` for `A = B²`, `B` symmetric, in the parameter order of [`to_params`]:
/// `dA = B dB + dB B`.
fn square_jacobian(b: &Matrix3<f64>) -> SMatrix<f64, 9, 9> {
    let mut m = SMatrix::<f64, 9, 9>::identity();
    for (j, &(r, s)) in PAIRS.iter().enumerate() {
        let mut e = Matrix3::zeros();
        e[(r, s)] = 1.0;
        e[(s, r)] = 1.0;
        let da = b * e + e * b;
        for (i, &(k, l)) in PAIRS.iter().enumerate() {
            m[(3 + i, 3 + j)] = da[(k, l)];
        }
    }
    m
}

/// The least-squares ellipsoid calibration of `points` (raw 3-axis readings of a sensor
/// tumbled through many orientations), with its quality report — or a typed refusal saying
/// why the data cannot support one (an invalid `config` is refused first). See the module
/// documentation for the steps.
pub fn fit_ellipsoid(
    points: &[Vector3<f64>],
    config: &EllipsoidConfig,
) -> Result<Solution<CompassCalibration3d>> {
    fit_ellipsoid_readings(points, config)
}

/// [`fit_ellipsoid`] of readings replayed from wherever they are kept (see [`Readings`]):
/// the same result, bit for bit, as of the same readings in one slice. An error replaying
/// them is returned as it is.
pub fn fit_ellipsoid_readings<R: Readings<3> + ?Sized>(
    points: &R,
    config: &EllipsoidConfig,
) -> Result<Solution<CompassCalibration3d>> {
    config.validate()?;
    let mut sol = fit_unchecked(points, config)?;
    sol.quality = quality::with_expected_field(sol.quality, config.expected_field);
    Ok(sol)
}

fn fit_unchecked<R: Readings<3> + ?Sized>(
    points: &R,
    config: &EllipsoidConfig,
) -> Result<Solution<CompassCalibration3d>> {
    // Whether every reading is finite, and the centre of their bounding box, in one pass.
    // Segment by segment (see `fold`): a conjunction, a minimum and a maximum merge
    // exactly.
    type Acc = (bool, Vector3<f64>, Vector3<f64>);
    let start = || {
        (
            true,
            Vector3::repeat(f64::INFINITY),
            -Vector3::repeat(f64::INFINITY),
        )
    };
    let (all_finite, lo, hi) = if points.len() >= MIN_POINTS_3D {
        fold(
            points,
            &RunFold {
                start,
                add: |(all_finite, lo, hi): &mut Acc, run: &[Vector3<f64>]| {
                    for p in run {
                        *all_finite &= p.iter().all(|x| x.is_finite());
                        *lo = lo.inf(p);
                        *hi = hi.sup(p);
                    }
                },
                merge: |(all_finite, lo, hi): &mut Acc, (f, l, h): Acc| {
                    *all_finite &= f;
                    *lo = lo.inf(&l);
                    *hi = hi.sup(&h);
                },
            },
        )?
    } else {
        start()
    };
    if points.len() >= MIN_POINTS_3D && all_finite {
        // Before fitting, seen from the bounding-box centre (the centre of any complete
        // ellipsoid) without a soft iron, so that a single-axis turn or a small patch of
        // orientations is refused for what it is rather than for a failed fit. Those
        // directions are distorted by the soft iron and by a centre a few shots place
        // roughly, which can raise the dilution a few times: the bound is taken
        // PRE_FIT_SLACK times looser here, and exactly after the fit.
        let raw = CompassCalibration3d {
            hard_iron: (lo + hi) * 0.5,
            soft_iron: Matrix3::identity(),
        };
        // Only the dilution is judged here; the fit's own figures come after it.
        let pre = CompassUncertainty {
            dilution: quality::support_dilution_3d(points, &raw)?,
            ..CompassUncertainty::UNDETERMINED
        };
        quality::require_determined(
            &pre,
            3,
            PRE_FIT_SLACK * config.limits.max_heading_error_bound_deg,
            ORIENTATION_HINT,
        )?;
    }
    let (norm, direct) = direct_normalised(points, config.limits.max_axis_ratio)?;
    // The refinement only improves the direct fit. Where it does not converge, or ends
    // flatter than any plausible soft iron, the direct fit stands and is judged like any
    // other: noisy readings crowded into a few directions can make the relative residual
    // fall without end towards an ever larger ellipsoid (found by `tests/more_data.rs`: a
    // cap of orientations at 8 % noise with a long dwell).
    let e = if config.refine {
        match refine(points, &norm, &direct, config) {
            Ok(e) => e,
            Err(Refusal::Replay(e)) => return Err(e),
            Err(Refusal::Fit) => direct,
        }
    } else {
        direct
    };
    let (cal, field) = denormalise(&norm, &e).calibration();
    if !(field.is_finite() && field > 0.0 && cal.soft_iron.iter().all(|x| x.is_finite())) {
        return Err(Error::Degenerate {
            reason: "the fitted ellipsoid is not finite; check the input scale",
        });
    }
    let (mut q, harmonics) = quality::assess_3d_with_harmonics_of(points, &cal, field)?;
    // The noise's second-order bias, which no number of readings removes, bounded as for the
    // direct fit (each plane section is an ellipse; see the batch ellipse's
    // `refinement_could_matter`); the refinement removes part of it (`tests/bias_bound.rs`).
    q.heading_error_systematic_deg =
        bias_bound_rad(harmonics, &cal, q.heading_noise_rms_deg.to_radians()).to_degrees();
    quality::require_determined(
        &q.uncertainty,
        3,
        config.limits.max_heading_error_bound_deg,
        ORIENTATION_HINT,
    )?;
    quality::require_linear(
        &q.uncertainty,
        q.heading_noise_rms_deg.to_radians(),
        config.max_noise_dilution,
    )?;
    // The condition number of the orientations seen is reported, not judged: a reading in a
    // new direction adds information, yet can raise the largest eigenvalue more than the
    // smallest; the dilution above is what says whether they determine the calibration.
    if !(q.fit.residual_rms_rel <= config.limits.max_residual_rel) {
        return Err(Error::NotAnEllipse {
            detail: " (the readings stray from the best ellipsoid by more than max_residual_rel of the field)",
        });
    }
    // Widened to the Student-t quantile of σ's degrees of freedom, as the 2-D fit's.
    quality::require_certain(
        &q,
        q.fit.points as f64 - 9.0,
        config.limits.max_heading_error_bound_deg,
    )?;
    Ok(Solution {
        params: cal,
        quality: q,
    })
}

/// The bound `4σ²(κ + h₁ + h₂)` radians on the field-direction error that the noise's
/// second-order bias leaves, for the calibration `cal` with per-reading noise `sigma`
/// (relative) and the harmonics `(h₁, h₂)` of its calibrated directions (see
/// [`quality::assess_3d_with_harmonics_of`]; `∞` without them): `κ` the anisotropy of the
/// soft iron's square.
fn bias_bound_rad(harmonics: Option<(f64, f64)>, cal: &CompassCalibration3d, sigma: f64) -> f64 {
    let Some((h1, h2)) = harmonics else {
        return f64::INFINITY;
    };
    let kappa = quality::anisotropy_3d(&(cal.soft_iron * cal.soft_iron.transpose())).unwrap_or(1.0);
    quality::direct_fit_bias_rad(sigma, kappa, h1, h2)
}

/// Why [`refine`] gave no ellipsoid: the refinement failed (the direct fit then stands), or
/// the readings could not be replayed (the whole fit fails).
enum Refusal {
    /// It did not converge, collapsed to a plane or ended flatter than any plausible soft iron.
    Fit,
    /// The readings could not be replayed.
    Replay(Error),
}

/// Step 5 of the module documentation: the geometric refinement of the direct fit `direct`
/// (normalised coordinates).
fn refine<R: Readings<3> + ?Sized>(
    points: &R,
    norm: &Normaliser<3>,
    direct: &Ellipsoid,
    config: &EllipsoidConfig,
) -> core::result::Result<Ellipsoid, Refusal> {
    let out = lm::minimise_replayed(
        "ellipsoid geometric refinement",
        to_params(direct),
        config.max_iterations,
        points.len(),
        |p| radial_normal_equations_of(points, norm, p),
    )
    .map_err(Refusal::Replay)?
    .map_err(|_| Refusal::Fit)?;
    let e = from_params(&out.params);
    let unit_map = sym_sqrt3(&(e.unit_map * e.unit_map)).ok_or(Refusal::Fit)?;
    let e = Ellipsoid {
        centre: e.centre,
        unit_map,
    };
    check_axis_ratio(&e, config.limits.max_axis_ratio).map_err(|_| Refusal::Fit)?;
    Ok(e)
}
