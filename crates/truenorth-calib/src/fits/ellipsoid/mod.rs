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
//! 3. Direct fit ([`fit_ellipsoid_direct`]): minimise the algebraic distance of the quadric
//!    `ax² + by² + cz² + 2fyz + 2gxz + 2hxy + 2px + 2qy + 2rz + d` subject to
//!    `4J − I² = 1` (Li & Griffiths 2004, eq. 5, with their `k = 4`), where
//!    `I = a + b + c` and `J = ab + bc + ca − f² − g² − h²`. The constraint makes the
//!    answer an ellipsoid; it is exact for ellipsoids whose shortest axis is at least half
//!    the longest (any plausible soft iron), and the refinement removes what bias remains.
//!    The linear terms are eliminated as in Halíř & Flusser (1998) and the 6×6 problem is
//!    solved as a symmetric eigenproblem (see the `linalg` module).
//! 4. Refuse when the best quadric without the constraint is not an ellipsoid (hyperboloid)
//!    or the ellipsoid is flatter than [`EllipsoidConfig::max_axis_ratio`].
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
#![allow(clippy::neg_cmp_op_on_partial_ord)]

extern crate alloc;

use alloc::vec::Vec;

use nalgebra::{Matrix3, Matrix4, SMatrix, SVector, Vector3, Vector6};
use serde::{Deserialize, Serialize};
use truenorth_compass::CompassCalibration3d;
use truenorth_core::{
    Calibrator, CompassQuality, Error, Mag3Sample, Progress, Pushed, Result, Solution, Validate,
    check_finite, check_finite3, check_positive, check_range,
};

use crate::fits::lm::{self, NormalAccumulator, NormalEquations};
use crate::fits::normalise::Normaliser;
use crate::numerics::blocks::{BLOCK, blocks, dot_block};
use crate::numerics::linalg::{constrained_min6, sym_eigen3, sym_eigen6, sym_sqrt3};
use crate::quality::{self, Uncertainty};

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// How much looser the determination test is before the fit, about the bounding-box centre
/// and without a soft iron, than after it (see `fit_unchecked`): a judgement, covering soft
/// irons up to the axis ratio 1.23 of the real full-sphere recording and centres placed by
/// 24 shots (`tests/few_shot.rs` accepts every simulated protocol).
const PRE_FIT_SLACK: f64 = 4.0;

/// What to record when the orientations do not determine an ellipsoid.
pub(crate) const ORIENTATION_HINT: &str = "add readings in other orientations (turns about a second and a third axis, or shots pointing and rolled in new directions)";

/// The fewest readings a 3-D least-squares fit accepts: nine determine an ellipsoid, one
/// more leaves a residual to judge it by.
pub const MIN_POINTS_3D: usize = 10;

/// Configuration of the least-squares ellipsoid fit (defaults in brackets).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EllipsoidConfig {
    /// Refine the direct fit geometrically (`true`).
    pub refine: bool,
    /// Most Levenberg–Marquardt steps before refusing with [`Error::NoConvergence`], 1..=10⁶
    /// (100).
    pub max_iterations: usize,
    /// Largest ratio of longest to shortest semi-axis accepted, ≥ 1 (10).
    pub max_axis_ratio: f64,
    /// Largest residual RMS, relative to the fitted field, accepted, > 0 (0.2): readings
    /// that stray further from the best ellipsoid are not a rotation in a constant field
    /// (a static sensor, a disturbed site, a badly tilting mount).
    pub max_residual_rel: f64,
    /// Largest direction-error bound of the calibration accepted
    /// ([`CompassQuality::heading_error_bound_deg`]), degrees, > 0 (10; see
    /// [`crate::quality`]): a calibration that uncertain is refused rather than returned.
    /// It also bounds the error that the geometry of the readings would let a per-reading
    /// error of [`quality::MODEL_ERROR_REL`] cause ([`quality::require_determined`]).
    pub max_heading_error_bound_deg: f64,
    /// Largest per-reading noise (relative to the field) times the orientations' dilution
    /// accepted, > 0 ([`quality::MAX_NOISE_DILUTION`]: beyond it the fit's own error figures
    /// no longer hold; see [`quality::require_linear`]).
    pub max_noise_dilution: f64,
    /// The expected total field, input unit (e.g. from the World Magnetic Model), > 0,
    /// reported as [`CompassQuality::field_ratio_to_expected`] (`None`).
    pub expected_field: Option<f64>,
}

impl Default for EllipsoidConfig {
    fn default() -> Self {
        Self {
            refine: true,
            max_iterations: 100,
            max_axis_ratio: 10.0,
            max_residual_rel: 0.2,
            max_heading_error_bound_deg: 10.0,
            max_noise_dilution: quality::MAX_NOISE_DILUTION,
            expected_field: None,
        }
    }
}

impl Validate for EllipsoidConfig {
    fn validate(&self) -> Result<()> {
        check_range(
            "ellipsoid max_iterations",
            self.max_iterations as f64,
            1.0,
            1e6,
        )?;
        check_range(
            "ellipsoid max_axis_ratio",
            self.max_axis_ratio,
            1.0,
            f64::MAX,
        )?;
        check_positive("ellipsoid max_residual_rel", self.max_residual_rel)?;
        check_positive(
            "ellipsoid max_heading_error_bound_deg",
            self.max_heading_error_bound_deg,
        )?;
        check_positive("ellipsoid max_noise_dilution", self.max_noise_dilution)?;
        if let Some(f) = self.expected_field {
            check_positive("ellipsoid expected_field", f)?;
        }
        Ok(())
    }
}

/// An ellipsoid `{ m : |B (m − c)| = 1 }`, `B` symmetric positive definite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipsoid {
    /// Centre `c`.
    pub centre: Vector3<f64>,
    /// Symmetric positive-definite `B`: maps the ellipsoid about its centre onto the unit
    /// sphere. Its eigenvalues are the reciprocal semi-axes.
    pub unit_map: Matrix3<f64>,
}

impl Ellipsoid {
    /// Semi-axes, largest first (in the unit of the points). `None` if `unit_map` is not
    /// positive definite.
    pub fn semi_axes(&self) -> Option<[f64; 3]> {
        let (l, _) = sym_eigen3(&self.unit_map)?;
        if l[0] > 0.0 {
            Some([1.0 / l[0], 1.0 / l[1], 1.0 / l[2]])
        } else {
            None
        }
    }

    /// The calibration that maps this ellipsoid onto a sphere, and that sphere's radius
    /// (the total field): `hard_iron = c`, `soft_iron = F·B`, `F = (det B)^{−1/3}`, so
    /// `det(soft_iron) = 1`.
    pub fn calibration(&self) -> (CompassCalibration3d, f64) {
        let field = self.unit_map.determinant().powf(-1.0 / 3.0);
        (
            CompassCalibration3d {
                hard_iron: self.centre,
                soft_iron: self.unit_map * field,
            },
            field,
        )
    }
}

/// The direct least-squares ellipsoid fit alone (steps 1–4 of the module documentation,
/// without the determination test): Li & Griffiths (2004) on normalised data.
pub fn fit_ellipsoid_direct(points: &[Vector3<f64>]) -> Result<Ellipsoid> {
    let (norm, e) = direct_normalised(points, f64::INFINITY)?;
    Ok(denormalise(&norm, &e))
}

fn direct_normalised(
    points: &[Vector3<f64>],
    max_axis_ratio: f64,
) -> Result<(Normaliser<3>, Ellipsoid)> {
    if points.len() < MIN_POINTS_3D {
        return Err(Error::TooFewPoints {
            got: points.len(),
            need: MIN_POINTS_3D,
        });
    }
    let norm = Normaliser::of_finite(points, "magnetometer reading")?;
    let (s, cov) = moments(points, &norm);
    let (l, _) = sym_eigen3(&cov).ok_or(Error::Degenerate {
        reason: "the readings could not be analysed",
    })?;
    if l[0] <= 1e-12 {
        return Err(Error::Degenerate {
            reason: "the readings lie in a plane (or on a line); tumble the sensor about more than one axis",
        });
    }
    let e = quadric_to_ellipsoid(&solve_direct(&s)?, max_axis_ratio)?;
    Ok((norm, e))
}

/// The terms of the quadric `(x², y², z², 2yz, 2xz, 2xy, 2x, 2y, 2z, 1)`: each is a constant
/// factor times a monomial of degree ≤ 2, given by its exponents of `(x, y, z)`.
const TERMS: [(f64, [u8; 3]); 10] = [
    (1.0, [2, 0, 0]),
    (1.0, [0, 2, 0]),
    (1.0, [0, 0, 2]),
    (2.0, [0, 1, 1]),
    (2.0, [1, 0, 1]),
    (2.0, [1, 1, 0]),
    (2.0, [1, 0, 0]),
    (2.0, [0, 1, 0]),
    (2.0, [0, 0, 1]),
    (1.0, [0, 0, 0]),
];

/// The exponents of `(x, y, z)` in the product of the monomials of terms `a` and `b`.
fn product_exponents(a: usize, b: usize) -> [u8; 3] {
    core::array::from_fn(|i| TERMS[a].1[i] + TERMS[b].1[i])
}

/// The distinct monomials of degree ≤ 4 in `(x, y, z)` (35 of them), each with a pair of
/// [`TERMS`] whose monomials multiply to it; in the order the pairs are first met going
/// through the upper triangle of the scatter matrix.
fn moment_pairs() -> ([[u8; 3]; 35], [(usize, usize); 35]) {
    let mut exps = [[0u8; 3]; 35];
    let mut pairs = [(0, 0); 35];
    let mut k = 0;
    for a in 0..TERMS.len() {
        for b in a..TERMS.len() {
            let e = product_exponents(a, b);
            if !exps[..k].contains(&e) {
                exps[k] = e;
                pairs[k] = (a, b);
                k += 1;
            }
        }
    }
    debug_assert_eq!(k, 35);
    (exps, pairs)
}

/// The 10×10 scatter matrix of `(x², y², z², 2yz, 2xz, 2xy, 2x, 2y, 2z, 1)` and the 3×3
/// covariance, in normalised coordinates.
fn moments(points: &[Vector3<f64>], norm: &Normaliser<3>) -> (SMatrix<f64, 10, 10>, Matrix3<f64>) {
    // The scatter matrix has 55 distinct entries but only 35 distinct values up to the
    // factors of 2 (the sums of the monomials of degree ≤ 4): sum those, a block of points
    // at a time (see `BLOCK`), and multiply the factors in afterwards (exactly: they are
    // powers of 2).
    let (exps, pairs) = moment_pairs();
    let mut sums = [0.0; 35];
    let inv = 1.0 / norm.scale;
    let c = norm.centre;
    let mut t = [[0.0; BLOCK]; 10];
    for ([x, y, z], len) in blocks(points) {
        for i in 0..BLOCK {
            // Rows past the end of the data are zeros, which add nothing.
            let live = i < len;
            let q = [(x[i] - c.x) * inv, (y[i] - c.y) * inv, (z[i] - c.z) * inv]
                .map(|v| if live { v } else { 0.0 });
            let [qx, qy, qz] = q;
            let m = [
                qx * qx,
                qy * qy,
                qz * qz,
                qy * qz,
                qx * qz,
                qx * qy,
                qx,
                qy,
                qz,
                if live { 1.0 } else { 0.0 },
            ];
            for (tk, mk) in t.iter_mut().zip(m) {
                tk[i] = mk;
            }
        }
        for (sk, &(a, b)) in sums.iter_mut().zip(&pairs) {
            *sk += dot_block(&t[a], &t[b]);
        }
    }
    let mut s = SMatrix::<f64, 10, 10>::zeros();
    for a in 0..TERMS.len() {
        for b in a..TERMS.len() {
            let e = product_exponents(a, b);
            let k = exps.iter().position(|&x| x == e).unwrap_or(0);
            let v = TERMS[a].0 * TERMS[b].0 * sums[k];
            s[(a, b)] = v;
            s[(b, a)] = v;
        }
    }
    let n = points.len() as f64;
    // Σ qqᵀ from the quadratic moments: s[(0,9)] = Σx², s[(5,9)] = 2Σxy, ...
    let cov = Matrix3::new(
        s[(0, 9)],
        0.5 * s[(5, 9)],
        0.5 * s[(4, 9)],
        0.5 * s[(5, 9)],
        s[(1, 9)],
        0.5 * s[(3, 9)],
        0.5 * s[(4, 9)],
        0.5 * s[(3, 9)],
        s[(2, 9)],
    ) / n;
    (s, cov)
}

/// The constraint `4J − I² = a₁ᵀ C₁ a₁` on `a₁ = (a, b, c, f, g, h)` (Li & Griffiths 2004,
/// eq. 7 with k = 4).
pub(crate) fn li_griffiths_constraint() -> SMatrix<f64, 6, 6> {
    let mut c = SMatrix::<f64, 6, 6>::zeros();
    for i in 0..3 {
        for j in 0..3 {
            c[(i, j)] = if i == j { -1.0 } else { 1.0 };
        }
        c[(3 + i, 3 + i)] = -4.0;
    }
    c
}

/// Reduced direct fit (see the module documentation). Returns the ten quadric coefficients
/// `(a, b, c, f, g, h, p, q, r, d)`.
pub(crate) fn solve_direct(s: &SMatrix<f64, 10, 10>) -> Result<SVector<f64, 10>> {
    let s1: SMatrix<f64, 6, 6> = s.fixed_view::<6, 6>(0, 0).into_owned();
    let s2: SMatrix<f64, 6, 4> = s.fixed_view::<6, 4>(0, 6).into_owned();
    let s3: Matrix4<f64> = s.fixed_view::<4, 4>(6, 6).into_owned();
    let s3_inv = s3.try_inverse().ok_or(Error::Degenerate {
        reason: "the readings lie in a plane (or on a line); tumble the sensor about more than one axis",
    })?;
    let t: SMatrix<f64, 4, 6> = -s3_inv * s2.transpose();
    let m = s1 + s2 * t;
    let m = (m + m.transpose()) * 0.5;
    // The best quadric without the ellipsoid constraint, normalised by the Frobenius norm
    // of its quadratic part (a rotation invariant): a hyperboloid means the data are not a
    // rotation in a constant field.
    let h = core::f64::consts::FRAC_1_SQRT_2;
    let d_inv = SMatrix::<f64, 6, 6>::from_diagonal(&Vector6::new(1.0, 1.0, 1.0, h, h, h));
    if let Some((_, v)) = sym_eigen6(&(d_inv * m * d_inv)) {
        let u = d_inv * v.column(0);
        if let Some((l, _)) = sym_eigen3(&quadratic_part(&u)) {
            let tol = 1e-9 * l.amax();
            if !(l[0] > tol || l[2] < -tol) {
                return Err(Error::NotAnEllipse {
                    detail: " (it is a hyperboloid or a cylinder)",
                });
            }
        }
    }
    let a1 = constrained_min6(&m, &li_griffiths_constraint()).ok_or(Error::Degenerate {
        reason: "too few distinct readings off a plane; tumble the sensor through more orientations",
    })?;
    let a2 = t * a1;
    let mut k = SVector::<f64, 10>::zeros();
    k.fixed_rows_mut::<6>(0).copy_from(&a1);
    k.fixed_rows_mut::<4>(6).copy_from(&a2);
    Ok(k)
}

/// The symmetric matrix `Q` of the quadratic part `xᵀQx` from `(a, b, c, f, g, h)`.
pub(crate) fn quadratic_part<S: nalgebra::Storage<f64, nalgebra::U6>>(
    a: &nalgebra::Vector<f64, nalgebra::U6, S>,
) -> Matrix3<f64> {
    Matrix3::new(a[0], a[5], a[4], a[5], a[1], a[3], a[4], a[3], a[2])
}

/// Centre and unit map of the quadric `xᵀQx + 2lᵀx + d = 0`: centre `−Q⁻¹l`,
/// `B = (Q/κ)^{1/2}` with `κ = cᵀQc − d`.
pub(crate) fn quadric_to_ellipsoid(k: &SVector<f64, 10>, max_axis_ratio: f64) -> Result<Ellipsoid> {
    let q = quadratic_part(&k.fixed_rows::<6>(0));
    let l = Vector3::new(k[6], k[7], k[8]);
    let q_inv = q.try_inverse().ok_or(Error::NotAnEllipse {
        detail: " (it is a cylinder or paraboloid)",
    })?;
    let centre = -(q_inv * l);
    let kappa = centre.dot(&(q * centre)) - k[9];
    let unit_map = sym_sqrt3(&(q / kappa)).ok_or(Error::NotAnEllipse {
        detail: " (it is a hyperboloid, or an empty or point ellipsoid)",
    })?;
    let e = Ellipsoid { centre, unit_map };
    check_axis_ratio(&e, max_axis_ratio)?;
    Ok(e)
}

fn check_axis_ratio(e: &Ellipsoid, max_axis_ratio: f64) -> Result<()> {
    match e.semi_axes() {
        Some([a, _, c]) if a / c <= max_axis_ratio => Ok(()),
        Some(_) => Err(Error::NotAnEllipse {
            detail: " (it is flatter than any plausible soft iron; see max_axis_ratio)",
        }),
        None => Err(Error::NotAnEllipse {
            detail: " (it is an empty or point ellipsoid)",
        }),
    }
}

fn denormalise(norm: &Normaliser<3>, e: &Ellipsoid) -> Ellipsoid {
    Ellipsoid {
        centre: norm.centre + e.centre * norm.scale,
        unit_map: e.unit_map / norm.scale,
    }
}

/// Index pairs of the six free entries of the symmetric `B`, in parameter order.
const PAIRS: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// Parameter vector of the refinement: `(c, B₁₁, B₁₂, B₁₃, B₂₂, B₂₃, B₃₃)`.
fn to_params(e: &Ellipsoid) -> SVector<f64, 9> {
    let mut p = SVector::<f64, 9>::zeros();
    p.fixed_rows_mut::<3>(0).copy_from(&e.centre);
    for (j, &(a, b)) in PAIRS.iter().enumerate() {
        p[3 + j] = e.unit_map[(a, b)];
    }
    p
}

fn from_params(p: &SVector<f64, 9>) -> Ellipsoid {
    let mut b = Matrix3::zeros();
    for (j, &(r, c)) in PAIRS.iter().enumerate() {
        b[(r, c)] = p[3 + j];
        b[(c, r)] = p[3 + j];
    }
    Ellipsoid {
        centre: Vector3::new(p[0], p[1], p[2]),
        unit_map: b,
    }
}

/// Residuals `r = |B v| − 1` (`v = q − c`) and their Jacobian, accumulated as normal
/// equations.
///
/// `r` depends on `B` only through `A = B²` (`|B v| = √(vᵀA v)`), so the pass over the
/// points differentiates with respect to `(c, A)`, which takes fewer products per point than
/// going through `B`: with `z = A v`, `ρ = √(vᵀz)`, `∂r/∂c = −z/ρ` and
/// `∂r/∂A_kl = v_k v_l/ρ` (`v_k²/(2ρ)` on the diagonal). The chain rule through `A = B²`, a
/// linear map of the parameter changes that is the same for every point, then gives the
/// normal equations in the refinement's parameters `(c, B)` (see [`square_jacobian`]).
fn radial_normal_equations(
    points: &[Vector3<f64>],
    norm: &Normaliser<3>,
    p: &SVector<f64, 9>,
) -> Option<NormalEquations<9>> {
    let e = from_params(p);
    let (c, b) = (e.centre, e.unit_map);
    let a = b * b;
    let a = (a + a.transpose()) * 0.5;
    let mu = norm.centre;
    let inv = 1.0 / norm.scale;
    let mut acc = NormalAccumulator::<9, 10>::new();
    // A block of points at a time (see `BLOCK`): first every point's gradient row and
    // residual, then the sums.
    for ([qx, qy, qz], len) in blocks(points) {
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
    }
    acc.finish()?.reparametrised(&square_jacobian(&b))
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
    config.validate()?;
    let mut sol = fit_unchecked(points, config)?;
    sol.quality = quality::with_expected_field(sol.quality, config.expected_field);
    Ok(sol)
}

fn fit_unchecked(
    points: &[Vector3<f64>],
    config: &EllipsoidConfig,
) -> Result<Solution<CompassCalibration3d>> {
    if points.len() >= MIN_POINTS_3D && points.iter().all(|p| p.iter().all(|x| x.is_finite())) {
        // Before fitting, seen from the bounding-box centre (the centre of any complete
        // ellipsoid) without a soft iron, so that a single-axis turn or a small patch of
        // orientations is refused for what it is rather than for a failed fit. Those
        // directions are distorted by the soft iron and by a centre a few shots place
        // roughly, which can raise the dilution a few times: the bound is taken
        // PRE_FIT_SLACK times looser here, and exactly after the fit.
        let centre = bbox_centre(points);
        let raw = CompassCalibration3d {
            hard_iron: centre,
            soft_iron: Matrix3::identity(),
        };
        // Only the dilution is judged here; the fit's own figures come after it.
        let pre = Uncertainty {
            dilution: quality::support_dilution_3d(points, &raw),
            ..Uncertainty::UNDETERMINED
        };
        quality::require_determined(
            &pre,
            3,
            PRE_FIT_SLACK * config.max_heading_error_bound_deg,
            ORIENTATION_HINT,
        )?;
    }
    let (norm, direct) = direct_normalised(points, config.max_axis_ratio)?;
    // The refinement only improves the direct fit. Where it does not converge, or ends
    // flatter than any plausible soft iron, the direct fit stands and is judged like any
    // other: noisy readings crowded into a few directions can make the relative residual
    // fall without end towards an ever larger ellipsoid (found by `tests/more_data.rs`: a
    // cap of orientations at 8 % noise with a long dwell).
    let e = if config.refine {
        refine(points, &norm, &direct, config).unwrap_or(direct)
    } else {
        direct
    };
    let (cal, field) = denormalise(&norm, &e).calibration();
    if !(field.is_finite() && field > 0.0 && cal.soft_iron.iter().all(|x| x.is_finite())) {
        return Err(Error::Degenerate {
            reason: "the fitted ellipsoid is not finite; check the input scale",
        });
    }
    let a = quality::assess_3d(points, &cal, field);
    let q = a.quality;
    quality::require_determined(
        &a.uncertainty,
        3,
        config.max_heading_error_bound_deg,
        ORIENTATION_HINT,
    )?;
    quality::require_linear(
        &a.uncertainty,
        q.heading_noise_rms_deg.to_radians(),
        config.max_noise_dilution,
    )?;
    // The condition number of the orientations seen is reported, not judged: a reading in a
    // new direction adds information, yet can raise the largest eigenvalue more than the
    // smallest; the dilution above is what says whether they determine the calibration.
    if !(q.fit.residual_rms_rel <= config.max_residual_rel) {
        return Err(Error::NotAnEllipse {
            detail: " (the readings stray from the best ellipsoid by more than max_residual_rel of the field)",
        });
    }
    // Widened to the Student-t quantile of σ's degrees of freedom, as the 2-D fit's.
    quality::require_certain(
        &q,
        q.fit.points as f64 - 9.0,
        config.max_heading_error_bound_deg,
    )?;
    Ok(Solution {
        params: cal,
        quality: q,
    })
}

/// Step 5 of the module documentation: the geometric refinement of the direct fit `direct`
/// (normalised coordinates).
fn refine(
    points: &[Vector3<f64>],
    norm: &Normaliser<3>,
    direct: &Ellipsoid,
    config: &EllipsoidConfig,
) -> Result<Ellipsoid> {
    let out = lm::minimise(
        "ellipsoid geometric refinement",
        to_params(direct),
        config.max_iterations,
        points.len(),
        |p| radial_normal_equations(points, norm, p),
    )?;
    let e = from_params(&out.params);
    let unit_map = sym_sqrt3(&(e.unit_map * e.unit_map)).ok_or(Error::Degenerate {
        reason: "the refined ellipsoid collapsed to a plane; tumble the sensor through more orientations",
    })?;
    let e = Ellipsoid {
        centre: e.centre,
        unit_map,
    };
    check_axis_ratio(&e, config.max_axis_ratio)?;
    Ok(e)
}

fn bbox_centre(points: &[Vector3<f64>]) -> Vector3<f64> {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    if points.is_empty() {
        Vector3::zeros()
    } else {
        (lo + hi) * 0.5
    }
}

/// Least-squares ellipsoid calibrator (batch): stores every reading pushed and fits them
/// all with [`fit_ellipsoid`] on `solve`.
///
/// [`Calibrator::progress`] runs the whole fit to decide `ready` (so that it agrees with
/// `solve` exactly): it costs as much as `solve`, O(n). Call it now and then, not per sample.
#[derive(Debug, Clone, Default)]
pub struct EllipsoidCalibrator {
    points: Vec<Vector3<f64>>,
    config: EllipsoidConfig,
}

impl EllipsoidCalibrator {
    /// A calibrator with the given configuration (validated).
    pub fn new(config: EllipsoidConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            points: Vec::new(),
            config,
        })
    }

    /// The readings stored so far.
    pub fn points(&self) -> &[Vector3<f64>] {
        &self.points
    }

    /// The configuration in use.
    pub fn config(&self) -> &EllipsoidConfig {
        &self.config
    }
}

impl Calibrator for EllipsoidCalibrator {
    type Sample = Mag3Sample;
    type Params = CompassCalibration3d;
    type Quality = CompassQuality;

    fn push(&mut self, sample: &Mag3Sample) -> Result<Pushed> {
        check_finite("timestamp t_s", sample.t_s)?;
        check_finite3("magnetometer reading", &sample.mag)?;
        self.points.push(sample.mag);
        Ok(Pushed::Accepted)
    }

    /// `ready` runs the fit (see the type's documentation); `coverage` is the information
    /// share of an evenly covered sphere ([`quality::Uncertainty::efficiency`]) of the
    /// directions seen from the centre of the readings' bounding box (an estimate before
    /// the fit).
    fn progress(&self) -> Progress {
        let centre = bbox_centre(&self.points);
        let raw = CompassCalibration3d {
            hard_iron: centre,
            soft_iron: Matrix3::identity(),
        };
        let field = quality::mean_corrected_norm_3d(&self.points, &raw);
        let coverage = quality::assess_3d(&self.points, &raw, field)
            .uncertainty
            .efficiency(3);
        Progress {
            samples: self.points.len(),
            coverage,
            ready: self.solve().is_ok(),
        }
    }

    fn solve(&self) -> Result<Solution<CompassCalibration3d>> {
        fit_ellipsoid(&self.points, &self.config)
    }

    fn reset(&mut self) {
        self.points.clear();
    }
}

#[cfg(test)]
mod tests;
