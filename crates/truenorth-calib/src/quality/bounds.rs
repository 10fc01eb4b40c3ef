//! Heading-error bounds: the information matrices of the 2-D and 3-D calibration models,
//! built from monomial sums, and the worst-direction bounds derived below.
//!
//! # Derivation
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

use core::f64::consts::TAU;

use nalgebra::{Matrix2, Matrix3, SMatrix, SVector, Vector3};

use crate::numerics::linalg::{sym_eigen2, sym_eigen3};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// How many standard deviations the heading-error bound spans.
pub const BOUND_SIGMAS: f64 = 3.0;

/// For an information matrix `A = L Lᵀ` of `P` parameters fitted to `n` points with residual
/// sum of squares `sum_sq`: `L⁻¹`, formed once so that every test direction costs one small
/// product instead of two triangular solves, and the residual standard deviation
/// `σ = √(sum_sq / (n − P))`. `None` when `n ≤ P` or `A` is not positive definite.
pub(super) fn whitened<const P: usize>(
    info: &SMatrix<f64, P, P>,
    sum_sq: f64,
    n: usize,
) -> Option<(SMatrix<f64, P, P>, f64)> {
    if n <= P {
        return None;
    }
    let l_inv = info
        .cholesky()?
        .l()
        .solve_lower_triangular(&SMatrix::<f64, P, P>::identity())?;
    Some((l_inv, (sum_sq / (n - P) as f64).sqrt()))
}

/// `max_u gᵀA⁻¹g = max_u ‖L⁻¹g‖²` over 72 headings, `g(u)` the heading error's gradient of
/// the module documentation: each heading costs one small matrix-vector product.
pub(super) fn worst_2d(l_inv: &SMatrix<f64, 5, 5>) -> f64 {
    let mut worst: f64 = 0.0;
    for k in 0..72 {
        let th = TAU * k as f64 / 72.0;
        let (s, c) = th.sin_cos();
        let (ux, uy, px, py) = (c, s, -s, c);
        let g = SVector::<f64, 5>::new(-px, -py, px * ux, px * uy + py * ux, py * uy);
        worst = worst.max((l_inv * g).norm_squared());
    }
    worst
}

/// `3 σ √worst` in degrees, infinite when not finite.
pub(super) fn bound_deg(sigma: f64, worst: f64) -> f64 {
    let b = (BOUND_SIGMAS * sigma * worst.sqrt()).to_degrees();
    if b.is_finite() { b } else { f64::INFINITY }
}

/// Per-reading noise, degrees: the residual standard deviation `√(sum_sq / (n − p))` of a
/// fit of `p` parameters (relative to the field, so radians of heading; see the module
/// documentation), or the plain RMS when there are no more points than parameters.
pub(super) fn noise_rms_deg(sum_sq: f64, n: usize, p: usize) -> f64 {
    let dof = if n > p { n - p } else { n.max(1) };
    (sum_sq / dof as f64).sqrt().to_degrees()
}

/// `φ(u) = (−u_x, −u_y, u_x², 2u_xu_y, u_y²)` of the module documentation of `quality`: the
/// radial residual's gradient in the 2-D error parameters at the unit direction `(x, y)`.
#[inline]
pub(crate) fn regressor_2d(x: f64, y: f64) -> SVector<f64, 5> {
    SVector::<f64, 5>::new(-x, -y, x * x, 2.0 * x * y, y * y)
}

/// The 3-D `φ(u) = (−u, u_x², 2u_xu_y, 2u_xu_z, u_y², 2u_yu_z, u_z²)` (centre, then the
/// symmetric soft-iron error row by row), as [`regressor_2d`].
#[inline]
pub(crate) fn regressor_3d(u: &Vector3<f64>) -> SVector<f64, 9> {
    SVector::<f64, 9>::from([
        -u.x,
        -u.y,
        -u.z,
        u.x * u.x,
        2.0 * u.x * u.y,
        2.0 * u.x * u.z,
        u.y * u.y,
        2.0 * u.y * u.z,
        u.z * u.z,
    ])
}

/// Number of distinct monomials of degree 2 to 4 in `(u_x, u_y)`.
pub(super) const MONOMIALS_2D: usize = 12;

/// The monomials of `(x, y)` that [`information_2d`] takes the sums of, in its order, one
/// product each: the reference the faster sums are tested against.
#[cfg(test)]
pub(super) fn monomials_2d(x: f64, y: f64) -> [f64; MONOMIALS_2D] {
    [
        x * x,
        x * y,
        y * y,
        x * x * x,
        x * x * y,
        x * y * y,
        y * y * y,
        x.powi(4),
        x.powi(3) * y,
        x * x * y * y,
        x * y.powi(3),
        y.powi(4),
    ]
}

/// The 2-D information matrix `A = Σ φ(u)φ(u)ᵀ`, `φ = (−u_x, −u_y, u_x², 2u_xu_y, u_y²)`,
/// from the sums over the points of the monomials it is made of, in the order
/// `(x², xy, y², x³, x²y, xy², y³, x⁴, x³y, x²y², xy³, y⁴)` of `u = (x, y)`.
///
/// Every entry of `φφᵀ` is a monomial of degree 2, 3 or 4 in `u` times a constant, and 12
/// distinct monomials fill its 15 distinct entries: summing those is the same matrix with
/// fewer products per point. NaN if a sum overflowed, which makes the condition and the
/// bound infinite.
pub(super) fn information_2d(m: &[f64; MONOMIALS_2D]) -> SMatrix<f64, 5, 5> {
    let [x2, xy, y2, x3, x2y, xy2, y3, x4, x3y, x2y2, xy3, y4] = *m;
    #[rustfmt::skip]
    let a = SMatrix::<f64, 5, 5>::from_row_slice(&[
        x2,         xy,         -x3,        -2.0 * x2y, -xy2,
        xy,         y2,         -x2y,       -2.0 * xy2, -y3,
        -x3,        -x2y,       x4,         2.0 * x3y,  x2y2,
        -2.0 * x2y, -2.0 * xy2, 2.0 * x3y,  4.0 * x2y2, 2.0 * xy3,
        -xy2,       -y3,        x2y2,       2.0 * xy3,  y4,
    ]);
    finite_or_nan(a)
}

/// Number of distinct monomials of degree 2 to 4 in `(u_x, u_y, u_z)`: 6 + 10 + 15.
pub(super) const MONOMIALS_3D: usize = 31;

/// The index pairs `(a, b)` of the quadratic terms `u_a u_b` of `φ` in the 3-D model, in
/// the parameter order `(e₁₁, e₁₂, e₁₃, e₂₂, e₂₃, e₃₃)` of the module documentation.
pub(super) const QUAD_3D: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// The monomials of degree 2, 3 and 4 in `u = (u₀, u₁, u₂)`, each once, as sorted index
/// tuples `(a, b)`, `(a, b, c)`, `(a, b, c, d)` (unused places zero) with their degree, in
/// lexicographic order within each degree: the order of the sums behind
/// [`information_3d`].
pub(super) fn monomial_tuples_3d() -> [([usize; 4], usize); MONOMIALS_3D] {
    let mut out = [([0; 4], 0); MONOMIALS_3D];
    let mut k = 0;
    for a in 0..3 {
        for b in a..3 {
            out[k] = ([a, b, 0, 0], 2);
            k += 1;
        }
    }
    for a in 0..3 {
        for b in a..3 {
            for c in b..3 {
                out[k] = ([a, b, c, 0], 3);
                k += 1;
            }
        }
    }
    for a in 0..3 {
        for b in a..3 {
            for c in b..3 {
                for d in c..3 {
                    out[k] = ([a, b, c, d], 4);
                    k += 1;
                }
            }
        }
    }
    out
}

/// For each monomial of [`monomial_tuples_3d`], two columns of the quality pass whose
/// product it is (columns 0–2: `u_a`; 3–8: `u_a u_b` in the order of [`QUAD_3D`]): degree 2
/// is `u_a · u_b`, degree 3 `(u_a u_b) · u_c`, degree 4 `(u_a u_b) · (u_c u_d)`.
pub(super) fn monomial_plan_3d() -> [(usize, usize); MONOMIALS_3D] {
    let quad = |a: usize, b: usize| 3 + QUAD_3D.iter().position(|&p| p == (a, b)).unwrap_or(0);
    monomial_tuples_3d().map(|(t, deg)| match deg {
        2 => (t[0], t[1]),
        3 => (quad(t[0], t[1]), t[2]),
        _ => (quad(t[0], t[1]), quad(t[2], t[3])),
    })
}

/// The 3-D information matrix `A = Σ φ(u)φ(u)ᵀ`,
/// `φ = (−u_x, −u_y, −u_z, u_x², 2u_xu_y, 2u_xu_z, u_y², 2u_yu_z, u_z²)`, from the sums of
/// the monomials of [`monomial_tuples_3d`]: 31 distinct monomials fill its 45 distinct
/// entries (see [`information_2d`]). NaN if a sum overflowed.
pub(super) fn information_3d(m: &[f64; MONOMIALS_3D]) -> SMatrix<f64, 9, 9> {
    // φ_i = factor_i · (the monomial with indices idx_i): −u_a for i < 3, then the
    // quadratic terms, with factor 1 on the diagonal pairs and 2 off it.
    let term = |i: usize| -> (f64, [usize; 2], usize) {
        if i < 3 {
            (-1.0, [i, 0], 1)
        } else {
            let (a, b) = QUAD_3D[i - 3];
            (if a == b { 1.0 } else { 2.0 }, [a, b], 2)
        }
    };
    let tuples = monomial_tuples_3d();
    let mut a = SMatrix::<f64, 9, 9>::zeros();
    for i in 0..9 {
        for j in i..9 {
            let (si, ii, ni) = term(i);
            let (sj, ij, nj) = term(j);
            let mut idx = [0usize; 4];
            idx[..ni].copy_from_slice(&ii[..ni]);
            idx[ni..ni + nj].copy_from_slice(&ij[..nj]);
            idx[..ni + nj].sort_unstable();
            let k = tuples
                .iter()
                .position(|&(t, deg)| deg == ni + nj && t[..deg] == idx[..deg])
                .unwrap_or(0);
            let v = si * sj * m[k];
            a[(i, j)] = v;
            a[(j, i)] = v;
        }
    }
    finite_or_nan(a)
}

/// `a`, or all NaN if any entry is not finite.
pub(super) fn finite_or_nan<const P: usize>(a: SMatrix<f64, P, P>) -> SMatrix<f64, P, P> {
    if a.iter().all(|x| x.is_finite()) {
        a
    } else {
        SMatrix::from_element(f64::NAN)
    }
}

/// Number of test directions (a Fibonacci lattice) over which the 3-D bound takes its worst.
pub(super) const BOUND_DIRECTIONS_3D: usize = 256;

/// `3 σ max_u √trace(G(u) A⁻¹ G(u)ᵀ)` in degrees, `G(u)` the 3×9 Jacobian of the direction
/// error `(I − uuᵀ)(E u − d)`; infinite when `A` is singular or `N ≤ 9`.
#[cfg(test)]
pub(super) fn bound_3d(info: &SMatrix<f64, 9, 9>, sum_sq: f64, n: usize) -> f64 {
    match whitened(info, sum_sq, n) {
        Some((l_inv, sigma)) => bound_deg(sigma, worst_3d(&l_inv)),
        None => f64::INFINITY,
    }
}

/// `max_u trace(G(u) A⁻¹ G(u)ᵀ) = max_u ‖L⁻¹ G(u)ᵀ‖²_F` over [`BOUND_DIRECTIONS_3D`]
/// directions: each costs one small matrix product.
pub(super) fn worst_3d(l_inv: &SMatrix<f64, 9, 9>) -> f64 {
    let mut worst: f64 = 0.0;
    for k in 0..BOUND_DIRECTIONS_3D {
        let g = direction_jacobian_3d(k);
        worst = worst.max((l_inv * g.transpose()).norm_squared());
    }
    worst
}

/// `G(u)` for the `k`-th of [`BOUND_DIRECTIONS_3D`] directions `u`, spread evenly over the
/// sphere (a Fibonacci lattice): how the calibrated direction of a reading along `u` moves
/// with the hard iron (first three columns) and the soft iron's six entries.
pub(super) fn direction_jacobian_3d(k: usize) -> SMatrix<f64, 3, 9> {
    let golden = core::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    let z = 1.0 - (2.0 * k as f64 + 1.0) / BOUND_DIRECTIONS_3D as f64;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (golden * k as f64).sin_cos();
    let u = Vector3::new(r * c, r * s, z);
    let proj = nalgebra::Matrix3::identity() - u * u.transpose();
    let mut g = SMatrix::<f64, 3, 9>::zeros();
    for kk in 0..3 {
        g.set_column(kk, &(-proj.column(kk)));
    }
    // E_kl u for (11, 12, 13, 22, 23, 33): the symmetric basis matrices applied to u.
    for (j, &(a, b)) in QUAD_3D.iter().enumerate() {
        let mut eu = Vector3::zeros();
        eu[a] += u[b];
        if a != b {
            eu[b] += u[a];
        }
        g.set_column(3 + j, &(proj * eu));
    }
    g
}

/// The Student-t widening of a 3σ bound whose σ comes from `dof` degrees of freedom (see
/// [`t_factor`], the Cornish–Fisher series), with the exact quantile for
/// one and two degrees of freedom, where the series falls far short (96 against 236 for
/// one): the two-sided 99.73 % point is `tan(π(p − ½))` for one and
/// `(2p − 1)/√(2p(1 − p))` for two, `p = Φ(3)` (Student 1908; e.g. Johnson, Kotz &
/// Balakrishnan, *Continuous Univariate Distributions* 2, §28.2).
pub(crate) fn t_factor_exact_small(dof: f64) -> f64 {
    // Φ(3), the normal distribution function at 3.
    const P: f64 = 0.998_650_101_968_369_9;
    if dof == 1.0 {
        (core::f64::consts::PI * (P - 0.5)).tan() / BOUND_SIGMAS
    } else if dof == 2.0 {
        (2.0 * P - 1.0) / (2.0 * P * (1.0 - P)).sqrt() / BOUND_SIGMAS
    } else {
        t_factor(dof)
    }
}

/// The factor by which a bound of `k = 3` standard deviations must grow when the standard
/// deviation is estimated from `dof` degrees of freedom, to keep its confidence: the
/// Student-t quantile of the normal 3σ level over 3, by the Cornish–Fisher expansion of
/// Abramowitz & Stegun (1964) 26.7.5 (within 1 % for `dof ≥ 5`, and short of the exact
/// quantile below, e.g. 96 against 236 for one degree of freedom). A fit of six readings
/// for five parameters estimates σ from one residual; without this factor such a fit can
/// look certain by chance.
fn t_factor(dof: f64) -> f64 {
    if dof.is_nan() || dof <= 0.0 {
        return f64::INFINITY;
    }
    let x = 3.0_f64;
    let (x2, x3) = (x * x, x * x * x);
    let (x5, x7, x9) = (x3 * x2, x3 * x2 * x2, x3 * x3 * x3);
    let g = [
        (x3 + x) / 4.0,
        (5.0 * x5 + 16.0 * x3 + 3.0 * x) / 96.0,
        (3.0 * x7 + 19.0 * x5 + 17.0 * x3 - 15.0 * x) / 384.0,
        (79.0 * x9 + 776.0 * x7 + 1482.0 * x5 - 1920.0 * x3 - 945.0 * x) / 92160.0,
    ];
    let mut t = x;
    let mut p = 1.0;
    for gk in g {
        p /= dof;
        t += gk * p;
    }
    t / x
}

/// A bound on the heading (3-D: field-direction) error, radians, that the second-order bias
/// of the direct (algebraic) fit leaves, which no number of readings removes:
/// `4σ²(κ + h₁ + h₂)`, with `σ` the per-reading noise (relative), `κ = (λ₁ − λ₂)/(λ₁ + λ₂)`
/// the anisotropy of `B²` (largest and smallest eigenvalues: [`anisotropy_2d`],
/// [`anisotropy_3d`]), and `h₁`, `h₂` the first and
/// second harmonics of the calibrated directions (1 each for readings all in one direction,
/// 0 for an even spread). The derivation is at the batch ellipse's
/// `refinement_could_matter`: isotropic sensor noise is anisotropic in the calibrated frame,
/// the algebraic fit of such points is an ellipse of axis ratio `1 + 4(σ₁² − σ₂²)`, a
/// two-cycle heading error of amplitude `4σ²κ`, and an uneven spread adds its harmonics
/// with the same factor. In 3-D each plane section is such an ellipse; the bound is held
/// against the error actually left by `tests/noisy_tumble.rs` (0.53° at 6 % noise, where the
/// 3σ part alone is 0.31°).
pub(crate) fn direct_fit_bias_rad(sigma: f64, kappa: f64, h1: f64, h2: f64) -> f64 {
    let b = 4.0 * sigma * sigma * (kappa + h1 + h2);
    if b.is_finite() { b } else { f64::INFINITY }
}

/// The anisotropy `κ = |λ₁ − λ₂| / (λ₁ + λ₂)` of the symmetric 2-D matrix `b_sq`, the square
/// `B²` of the map `B` that takes the fitted ellipse to the unit circle (`λ₁`, `λ₂` its
/// largest and smallest eigenvalues): 0 for a circle, towards 1 as the ellipse flattens (`B²` has the squared axis ratio as
/// the ratio of its eigenvalues). It is the `κ` of [`direct_fit_bias_rad`], whose
/// derivation is at the batch ellipse's `refinement_could_matter`. `None` where the
/// eigenvalues cannot be computed (a non-finite entry); a caller that must still bound
/// can take `κ = 1`, which no positive `B²` exceeds.
pub(crate) fn anisotropy_2d(b_sq: &Matrix2<f64>) -> Option<f64> {
    sym_eigen2(b_sq).map(|(l, _)| ((l[0] - l[1]) / (l[0] + l[1])).abs())
}

/// The anisotropy `κ = |λ₁ − λ₃| / (λ₁ + λ₃)` of the symmetric 3-D matrix `b_sq` (`B²`, or
/// `W Wᵀ` for a soft-iron matrix `W`), from its largest and smallest eigenvalues: as
/// [`anisotropy_2d`], for the ellipse in which the plane of those two axes cuts the
/// ellipsoid, the most anisotropic of its sections.
pub(crate) fn anisotropy_3d(b_sq: &Matrix3<f64>) -> Option<f64> {
    sym_eigen3(b_sq).map(|(l, _)| {
        let (hi, lo) = (l.max(), l.min());
        ((hi - lo) / (hi + lo)).abs()
    })
}
