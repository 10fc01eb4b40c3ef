//! The direct least-squares ellipsoid fit (Li & Griffiths 2004) and the conversions between
//! the quadric, the ellipsoid and the refinement's parameters.

extern crate alloc;

use nalgebra::{Matrix3, Matrix4, SMatrix, SVector, Vector3, Vector6};
use truenorth_compass::CompassCalibration3d;
use truenorth_core::{Error, Result};

use crate::fits::normalise::Normaliser;
use crate::numerics::blocks::{BLOCK, dot_block};
use crate::numerics::linalg::{constrained_min6, sym_eigen3, sym_eigen6, sym_sqrt3};
use crate::numerics::readings::Readings;
use crate::numerics::segments::{RunFold, add_sums, by_blocks, fold};
// The quadric's terms `(x², y², z², 2yz, 2xz, 2xy, 2x, 2y, 2z, 1)`, the online fit's too.
use crate::numerics::monomial_layout::TERMS_3D as TERMS;

use crate::fits::ellipsoid::config::MIN_POINTS_3D;
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

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

pub(crate) fn direct_normalised<R: Readings<3> + ?Sized>(
    points: &R,
    max_axis_ratio: f64,
) -> Result<(Normaliser<3>, Ellipsoid)> {
    if points.len() < MIN_POINTS_3D {
        return Err(Error::TooFewPoints {
            got: points.len(),
            need: MIN_POINTS_3D,
        });
    }
    let norm = Normaliser::of_finite(points, "magnetometer reading")?;
    let (s, cov) = moments(points, &norm)?;
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
pub(crate) fn moments<R: Readings<3> + ?Sized>(
    points: &R,
    norm: &Normaliser<3>,
) -> Result<(SMatrix<f64, 10, 10>, Matrix3<f64>)> {
    // The scatter matrix has 55 distinct entries but only 35 distinct values up to the
    // factors of 2 (the sums of the monomials of degree ≤ 4): sum those, a block of points
    // at a time (see `BLOCK`), and multiply the factors in afterwards (exactly: they are
    // powers of 2).
    let (exps, pairs) = moment_pairs();
    let inv = 1.0 / norm.scale;
    let c = norm.centre;
    // Segment by segment (see `fold`); each accumulator carries its block of monomials.
    let add = |(sums, t): &mut ([f64; 35], [[f64; BLOCK]; 10]),
               [x, y, z]: &[[f64; BLOCK]; 3],
               len: usize| {
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
    };
    let (sums, _) = fold(
        points,
        &RunFold {
            start: || ([0.0; 35], [[0.0; BLOCK]; 10]),
            add: by_blocks(add),
            merge: |(sums, _): &mut ([f64; 35], [[f64; BLOCK]; 10]), (later, _)| {
                add_sums(sums, later);
            },
        },
    )?;
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
    let cov = second_moments(&s, points.len() as f64);
    Ok((s, cov))
}

/// `Σ qqᵀ / weight` from the scatter's quadratic moments in the constant term's column:
/// `s[(0,9)] = Σx²`, `s[(5,9)] = 2Σxy`, … (the off-diagonal terms carry a factor 2).
pub(crate) fn second_moments(s: &SMatrix<f64, 10, 10>, weight: f64) -> Matrix3<f64> {
    Matrix3::new(
        s[(0, 9)],
        0.5 * s[(5, 9)],
        0.5 * s[(4, 9)],
        0.5 * s[(5, 9)],
        s[(1, 9)],
        0.5 * s[(3, 9)],
        0.5 * s[(4, 9)],
        0.5 * s[(3, 9)],
        s[(2, 9)],
    ) / weight
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
    let reduced = reduce(s)?;
    constrained_quadric(&reduced)
}

/// The scatter with the linear terms eliminated (`m`) and the map back to them (`t`): the
/// first step of the direct fit, which the online calibrator runs as a stage of its own.
#[derive(Debug, Clone)]
pub(crate) struct Reduced {
    /// The 6 × 6 reduced scatter of the quadratic coefficients.
    pub(crate) m: SMatrix<f64, 6, 6>,
    /// Linear coefficients from quadratic ones: `a₂ = t a₁`.
    pub(crate) t: SMatrix<f64, 4, 6>,
}

/// Eliminates the linear terms of the scatter `s` and refuses data that no ellipsoid fits
/// (a plane, a hyperboloid).
pub(crate) fn reduce(s: &SMatrix<f64, 10, 10>) -> Result<Reduced> {
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
    Ok(Reduced { m, t })
}

/// The constrained minimum (Li & Griffiths 2004, eq. 7) of the reduced scatter, with the
/// linear terms restored: the ten quadric coefficients.
pub(crate) fn constrained_quadric(r: &Reduced) -> Result<SVector<f64, 10>> {
    let a1 = constrained_min6(&r.m, &li_griffiths_constraint()).ok_or(Error::Degenerate {
        reason: "too few distinct readings off a plane; tumble the sensor through more orientations",
    })?;
    let a2 = r.t * a1;
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

pub(crate) fn check_axis_ratio(e: &Ellipsoid, max_axis_ratio: f64) -> Result<()> {
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

pub(crate) fn denormalise(norm: &Normaliser<3>, e: &Ellipsoid) -> Ellipsoid {
    Ellipsoid {
        centre: norm.centre + e.centre * norm.scale,
        unit_map: e.unit_map / norm.scale,
    }
}

/// Index pairs of the six free entries of the symmetric `B`, in parameter order.
pub(crate) const PAIRS: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// Parameter vector of the refinement: `(c, B₁₁, B₁₂, B₁₃, B₂₂, B₂₃, B₃₃)`.
pub(crate) fn to_params(e: &Ellipsoid) -> SVector<f64, 9> {
    let mut p = SVector::<f64, 9>::zeros();
    p.fixed_rows_mut::<3>(0).copy_from(&e.centre);
    for (j, &(a, b)) in PAIRS.iter().enumerate() {
        p[3 + j] = e.unit_map[(a, b)];
    }
    p
}

pub(crate) fn from_params(p: &SVector<f64, 9>) -> Ellipsoid {
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
