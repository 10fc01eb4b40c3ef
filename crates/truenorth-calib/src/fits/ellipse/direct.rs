//! The direct least-squares ellipse fit (Fitzgibbon, Pilu & Fisher 1999, in the numerically
//! stable form of Halíř & Flusser 1998) and the conversions between the conic, the ellipse
//! and the refinement's parameters.

extern crate alloc;

use nalgebra::{Matrix2, Matrix3, SMatrix, SVector, Vector2, Vector3};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{Error, Result};

use crate::fits::normalise::Normaliser;
use crate::numerics::linalg::{constrained_min3, sym_eigen2, sym_eigen3, sym_sqrt2};
use crate::numerics::readings::Readings;
use crate::numerics::segments::{RunFold, add_sums, fold};
use crate::quality::Moments2;

use crate::fits::ellipse::config::MIN_POINTS_2D;
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// An ellipse `{ m : |B (m − c)| = 1 }`, `B` symmetric positive definite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipse {
    /// Centre `c`.
    pub centre: Vector2<f64>,
    /// Symmetric positive-definite `B`: maps the ellipse about its centre onto the unit
    /// circle. Its eigenvalues are the reciprocal semi-axes.
    pub unit_map: Matrix2<f64>,
}

impl Ellipse {
    /// Semi-axes, largest first (in the unit of the points). `None` if `unit_map` is not
    /// positive definite.
    pub fn semi_axes(&self) -> Option<(f64, f64)> {
        let (l, _) = sym_eigen2(&self.unit_map)?;
        if l[0] > 0.0 {
            Some((1.0 / l[0], 1.0 / l[1]))
        } else {
            None
        }
    }

    /// The compass calibration that maps this ellipse onto a circle, and that circle's
    /// radius (the field): `hard_iron = c`, `soft_iron = F·B`, `F = 1/√det B`, so
    /// `det(soft_iron) = 1`.
    pub fn calibration(&self) -> (CompassCalibration2d, f64) {
        let field = 1.0 / self.unit_map.determinant().sqrt();
        (
            CompassCalibration2d {
                hard_iron: self.centre,
                soft_iron: self.unit_map * field,
            },
            field,
        )
    }
}

/// The direct least-squares ellipse fit alone (steps 1–4 of the module documentation):
/// Fitzgibbon, Pilu & Fisher (1999) in the form of Halíř & Flusser (1998), on normalised
/// data. Fast (a single pass over the points plus 3×3 algebra) and always an ellipse.
pub fn fit_ellipse_direct(points: &[Vector2<f64>]) -> Result<Ellipse> {
    let (norm, e, _) = direct_normalised(points, f64::INFINITY)?;
    Ok(denormalise(&norm, &e))
}

/// Refuses too few or non-finite points, normalises, checks for collinear data, fits.
/// Returns the normaliser and the ellipse in normalised coordinates.
pub(crate) fn direct_normalised<R: Readings<2> + ?Sized>(
    points: &R,
    max_axis_ratio: f64,
) -> Result<(Normaliser<2>, Ellipse, Moments2)> {
    if points.len() < MIN_POINTS_2D {
        return Err(Error::TooFewPoints {
            got: points.len(),
            need: MIN_POINTS_2D,
        });
    }
    let norm = Normaliser::of_finite(points, "magnetometer reading")?;
    let (s, cov, table) = moments(points, &norm)?;
    // Collinear: the spread across the best line is nil compared with the spread along it
    // (the trace of `cov` is 1 after normalisation).
    let (l, _) = sym_eigen2(&cov).ok_or(Error::Degenerate {
        reason: "the readings could not be analysed",
    })?;
    if l[0] <= 1e-12 {
        return Err(Error::Degenerate {
            reason: "the readings lie on a straight line; the sensor must turn so the field traces a circle",
        });
    }
    let e = conic_to_ellipse(&solve_direct(&s)?, max_axis_ratio)?;
    Ok((norm, e, table))
}

/// The moments `Σ qqᵀ`-style sums the direct fit needs, in normalised coordinates: the
/// 6×6 scatter matrix of `(x², xy, y², x, y, 1)`, the 2×2 covariance, and the same sums as
/// a table `Σ xⁱ yʲ` for the quality report.
fn moments<R: Readings<2> + ?Sized>(
    points: &R,
    norm: &Normaliser<2>,
) -> Result<(SMatrix<f64, 6, 6>, Matrix2<f64>, Moments2)> {
    // The 14 distinct monomials of degree 1 to 4, accumulated separately so the loop is
    // plain arithmetic (the 10k-point benchmark lives here), segment by segment (see
    // `fold`).
    let inv = 1.0 / norm.scale;
    let c = norm.centre;
    let add = |m: &mut [f64; 14], run: &[Vector2<f64>]| {
        let [x4, x3y, x2y2, xy3, y4, x3, x2y, xy2, y3, x2, xy, y2, sx, sy] = m;
        for p in run {
            let x = (p.x - c.x) * inv;
            let y = (p.y - c.y) * inv;
            let (xx, xyv, yy) = (x * x, x * y, y * y);
            *x4 += xx * xx;
            *x3y += xx * xyv;
            *x2y2 += xx * yy;
            *xy3 += xyv * yy;
            *y4 += yy * yy;
            *x3 += xx * x;
            *x2y += xx * y;
            *xy2 += x * yy;
            *y3 += yy * y;
            *x2 += xx;
            *xy += xyv;
            *y2 += yy;
            *sx += x;
            *sy += y;
        }
    };
    let sums = fold(
        points,
        &RunFold {
            start: || [0.0; 14],
            add,
            merge: add_sums,
        },
    )?;
    let [x4, x3y, x2y2, xy3, y4, x3, x2y, xy2, y3, x2, xy, y2, sx, sy] = sums;
    let n = points.len() as f64;
    #[rustfmt::skip]
    let s = SMatrix::<f64, 6, 6>::from_row_slice(&[
        x4,   x3y,  x2y2, x3,  x2y, x2,
        x3y,  x2y2, xy3,  x2y, xy2, xy,
        x2y2, xy3,  y4,   xy2, y3,  y2,
        x3,   x2y,  xy2,  x2,  xy,  sx,
        x2y,  xy2,  y3,   xy,  y2,  sy,
        x2,   xy,   y2,   sx,  sy,  n,
    ]);
    let mut table: Moments2 = [[0.0; 5]; 5];
    table[0] = [n, sy, y2, y3, y4];
    table[1][..4].copy_from_slice(&[sx, xy, xy2, xy3]);
    table[2][..3].copy_from_slice(&[x2, x2y, x2y2]);
    table[3][..2].copy_from_slice(&[x3, x3y]);
    table[4][0] = x4;
    Ok((s, Matrix2::new(x2, xy, xy, y2) / n, table))
}

/// Halíř & Flusser (1998): split the scatter matrix into the quadratic (`S1`), mixed (`S2`)
/// and linear (`S3`) blocks, eliminate the linear coefficients (`a₂ = T a₁`,
/// `T = −S3⁻¹ S2ᵀ`, their eq. 14), and solve the reduced 3×3 constrained problem
/// `min a₁ᵀ M a₁` s.t. `a₁ᵀ C₁ a₁ = 1`, `M = S1 + S2 T` (eq. 21), `C₁` the ellipse
/// constraint `4ac − b²` (Fitzgibbon et al. eq. 5). Returns `(a, b, c, d, e, f)`.
pub(crate) fn solve_direct(s: &SMatrix<f64, 6, 6>) -> Result<SVector<f64, 6>> {
    let s1: Matrix3<f64> = s.fixed_view::<3, 3>(0, 0).into_owned();
    let s2: Matrix3<f64> = s.fixed_view::<3, 3>(0, 3).into_owned();
    let s3: Matrix3<f64> = s.fixed_view::<3, 3>(3, 3).into_owned();
    let s3_inv = s3.try_inverse().ok_or(Error::Degenerate {
        reason: "the readings lie on a straight line; the sensor must turn so the field traces a circle",
    })?;
    let t = -s3_inv * s2.transpose();
    let m = s1 + s2 * t;
    let m = (m + m.transpose()) * 0.5;
    // Not an ellipse at all? The best conic without the ellipse constraint, normalised by
    // the rotation-invariant a² + b²/2 + c² (so the test does not depend on orientation),
    // is the smallest eigenvector of D⁻¹ M D⁻¹ with D = diag(1, 1/√2, 1).
    let d_inv = Matrix3::from_diagonal(&Vector3::new(1.0, core::f64::consts::SQRT_2, 1.0));
    if let Some((_, v)) = sym_eigen3(&(d_inv * m * d_inv)) {
        let u = d_inv * v.column(0);
        let disc = 4.0 * u[0] * u[2] - u[1] * u[1];
        let size = u[0] * u[0] + 0.5 * u[1] * u[1] + u[2] * u[2];
        if disc <= 1e-9 * size {
            return Err(Error::NotAnEllipse {
                detail: if disc < -1e-9 * size {
                    " (it is a hyperbola)"
                } else {
                    " (it is a parabola)"
                },
            });
        }
    }
    // 4ac − b² = a₁ᵀ C₁ a₁ for a₁ = (a, b, c).
    let c1 = Matrix3::new(0.0, 0.0, 2.0, 0.0, -1.0, 0.0, 2.0, 0.0, 0.0);
    let a1 = constrained_min3(&m, &c1).ok_or(Error::Degenerate {
        reason: "fewer than five distinct readings off a line; record a turn with more varied headings",
    })?;
    let a2 = t * a1;
    Ok(SVector::<f64, 6>::new(
        a1[0], a1[1], a1[2], a2[0], a2[1], a2[2],
    ))
}

/// Centre and unit map of the conic `a x² + b xy + c y² + d x + e y + f = 0`.
pub(crate) fn conic_to_ellipse(k: &SVector<f64, 6>, max_axis_ratio: f64) -> Result<Ellipse> {
    let q = Matrix2::new(k[0], 0.5 * k[1], 0.5 * k[1], k[2]);
    let l = Vector2::new(k[3], k[4]);
    let q_inv = q.try_inverse().ok_or(Error::NotAnEllipse {
        detail: " (it is a parabola)",
    })?;
    let centre = -0.5 * q_inv * l;
    let kappa = centre.dot(&(q * centre)) - k[5];
    let a = q / kappa;
    let unit_map = sym_sqrt2(&a).ok_or(Error::NotAnEllipse {
        detail: " (it is an empty or point ellipse)",
    })?;
    let e = Ellipse { centre, unit_map };
    check_axis_ratio(&e, max_axis_ratio)?;
    Ok(e)
}

pub(crate) fn check_axis_ratio(e: &Ellipse, max_axis_ratio: f64) -> Result<()> {
    match e.semi_axes() {
        Some((a, b)) if a / b <= max_axis_ratio => Ok(()),
        Some(_) => Err(Error::NotAnEllipse {
            detail: " (it is flatter than any plausible soft iron; see max_axis_ratio)",
        }),
        None => Err(Error::NotAnEllipse {
            detail: " (it is an empty or point ellipse)",
        }),
    }
}

/// Back from normalised coordinates: `q = (m − μ)/s` ⇒ centre `μ + s·c`, map `B/s`.
pub(crate) fn denormalise(norm: &Normaliser<2>, e: &Ellipse) -> Ellipse {
    Ellipse {
        centre: norm.centre + e.centre * norm.scale,
        unit_map: e.unit_map / norm.scale,
    }
}

/// Parameter vector of the refinement: `(c_x, c_y, B₁₁, B₁₂, B₂₂)`.
pub(crate) fn to_params(e: &Ellipse) -> SVector<f64, 5> {
    SVector::<f64, 5>::new(
        e.centre.x,
        e.centre.y,
        e.unit_map[(0, 0)],
        e.unit_map[(0, 1)],
        e.unit_map[(1, 1)],
    )
}

pub(crate) fn from_params(p: &SVector<f64, 5>) -> Ellipse {
    Ellipse {
        centre: Vector2::new(p[0], p[1]),
        unit_map: Matrix2::new(p[2], p[3], p[3], p[4]),
    }
}
