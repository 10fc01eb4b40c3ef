//! The 2-D [`CompassQuality`] of a calibration, from one pass over the readings or from the
//! monomial sums of the fit.

use nalgebra::Vector2;
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{CompassQuality, FitQuality};

use super::bounds::{MONOMIALS_2D, information_2d, noise_rms_deg, worst_2d};
use super::coverage::Coverage;
use super::pass_2d::{ReportSums, sums_2d};
use super::support::{Support2d, support_dilution};
use super::uncertainty::bound_and_uncertainty;
use crate::numerics::linalg::{condition_from_eigenvalues, sym_eigen5};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// A 2-D quality report and the coverage behind it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Assessment2d {
    /// The report to return with the solution.
    pub quality: CompassQuality,
    /// Coverage of the calibrated headings (seen from the origin of the calibrated circle).
    pub coverage: Coverage,
}

/// Everything the 2-D report needs, in one pass over the raw readings: the calibrated
/// readings' residuals against `field`, their heading bins, and the information matrix
/// of the module documentation. `field` is the radius of the calibrated circle (for a
/// calibrator that does not define one, pass [`super::mean_corrected_norm_2d`]).
///
/// Non-finite readings are skipped. Allocates nothing.
pub fn assess_2d(points: &[Vector2<f64>], cal: &CompassCalibration2d, field: f64) -> Assessment2d {
    let s = Assessment2d::sums(points, cal, field);
    report_2d(&s.sums, s.ss, s.n, s.coverage, &s.support, field)
}

impl Assessment2d {
    /// The one pass over the readings of [`assess_2d`], without the report built from it
    /// (so that a caller can spread the two over separate steps; see
    /// [`Self::support_figures`] and [`Self::from_sums`]).
    pub(crate) fn sums(
        points: &[Vector2<f64>],
        cal: &CompassCalibration2d,
        field: f64,
    ) -> ReportSums {
        sums_2d(points, cal, field)
    }

    /// The condition number and the dilution of the support of `s` (the costlier half of
    /// the report built from the sums).
    pub(crate) fn support_figures(s: &ReportSums) -> SupportFigures {
        support_figures_2d(&s.support)
    }

    /// The report from the sums `s` and their [`Self::support_figures`]: exactly what
    /// [`assess_2d`] returns.
    pub(crate) fn from_sums(s: &ReportSums, support: SupportFigures, field: f64) -> Self {
        report_2d_with(&s.sums, s.ss, s.n, s.coverage, field, support)
    }
}

/// Sums `Σ xⁱ yʲ` (`i + j ≤ 4`) of a set of 2-D points, `m[i][j]` (entries with
/// `i + j > 4` unused): everything the 2-D report needs besides the coverage, for any
/// ellipse, without another pass over the points.
pub(crate) type Moments2 = [[f64; 5]; 5];

/// A polynomial in `(x, y)` of degree ≤ 4, `p[i][j]` the coefficient of `xⁱ yʲ`.
type Poly2 = [[f64; 5]; 5];

/// The product of two polynomials, truncated to degree 4 (the callers' products never
/// exceed it).
fn poly_mul(a: &Poly2, b: &Poly2) -> Poly2 {
    let mut out = [[0.0; 5]; 5];
    for i in 0..5 {
        for j in 0..5 - i {
            if a[i][j] == 0.0 {
                continue;
            }
            for k in 0..5 - i - j {
                for l in 0..5 - i - j - k {
                    out[i + k][j + l] += a[i][j] * b[k][l];
                }
            }
        }
    }
    out
}

/// `Σ p(x, y)` over the points whose moments are `m`.
fn poly_sum(p: &Poly2, m: &Moments2) -> f64 {
    let mut s = 0.0;
    for i in 0..5 {
        for j in 0..5 - i {
            s += p[i][j] * m[i][j];
        }
    }
    s
}

/// The 2-D report of the ellipse `{ q : |B (q − c)| = 1 }` from the moments `m` of the `n`
/// points `q` it was fitted to (in the same coordinates), with the coverage and support of
/// the calibrated directions measured separately (`directions`, see
/// `calibrated_directions_2d`) and `field` the radius of the calibrated circle in the
/// caller's unit.
///
/// The calibrated reading is `field · w` with `w = B (q − c)`, so every quantity of
/// [`assess_2d`] is a sum over the points of a function of `w`, and `w` is affine in `q`:
/// a polynomial in `w` of degree ≤ 4 is one in `q`, summed exactly by the moments. Two are
/// replaced by polynomials to first order in the residual `r = |w| − 1` (a few per cent at
/// most for any accepted fit): the squared residual by `g²/4`, `g = |w|² − 1 = r (2 + r)`
/// (relative error about `r`, which averages out over a turn), and the direction
/// `u = w/|w|` in the monomials of the information matrix by `w` (relative error
/// `deg · r`, likewise). The sums of the moments cancel to `Σ g²`, so the residual has a
/// rounding floor of about `√ε ≈ 10⁻⁸` relative to the field.
pub(crate) fn assess_2d_from_moments(
    m: &Moments2,
    n: usize,
    centre: &Vector2<f64>,
    unit_map: &nalgebra::Matrix2<f64>,
    directions: (Coverage, Support2d),
    field: f64,
) -> Assessment2d {
    let b = unit_map;
    let t = -(b * centre);
    let mut wx: Poly2 = [[0.0; 5]; 5];
    let mut wy: Poly2 = [[0.0; 5]; 5];
    wx[0][0] = t.x;
    wx[1][0] = b[(0, 0)];
    wx[0][1] = b[(0, 1)];
    wy[0][0] = t.y;
    wy[1][0] = b[(1, 0)];
    wy[0][1] = b[(1, 1)];
    let mut one: Poly2 = [[0.0; 5]; 5];
    one[0][0] = 1.0;
    // Powers w_x^a and w_y^b, a, b ≤ 4.
    let mut px = [one; 5];
    let mut py = [one; 5];
    for k in 1..5 {
        px[k] = poly_mul(&px[k - 1], &wx);
        py[k] = poly_mul(&py[k - 1], &wy);
    }
    let sum = |a: usize, bb: usize| poly_sum(&poly_mul(&px[a], &py[bb]), m);
    // In the order of `information_2d`.
    let sums = [
        sum(2, 0),
        sum(1, 1),
        sum(0, 2),
        sum(3, 0),
        sum(2, 1),
        sum(1, 2),
        sum(0, 3),
        sum(4, 0),
        sum(3, 1),
        sum(2, 2),
        sum(1, 3),
        sum(0, 4),
    ];
    // Σ g² = Σ (|w|² − 1)² = Σ |w|⁴ − 2 Σ |w|² + n.
    let w4 = sums[7] + 2.0 * sums[9] + sums[11];
    let w2 = sums[0] + sums[2];
    let ss = if n > 0 {
        (0.25 * (w4 - 2.0 * w2 + n as f64)).max(0.0)
    } else {
        0.0
    };
    report_2d(&sums, ss, n, directions.0, &directions.1, field)
}

/// The first and second harmonics of the calibrated directions `w = B (q − c)` of the `n`
/// points with moments `m`: `|Σw|/n` and `|Σ(w_x² − w_y², 2w_xw_y)|/n` (0 for readings
/// spread evenly round the circle; `w` stands in for `u = w/|w|` as in
/// [`assess_2d_from_moments`]).
pub(crate) fn direction_harmonics(
    m: &Moments2,
    n: usize,
    centre: &Vector2<f64>,
    unit_map: &nalgebra::Matrix2<f64>,
) -> (f64, f64) {
    let t = -(unit_map * centre);
    let mut wx: Poly2 = [[0.0; 5]; 5];
    let mut wy: Poly2 = [[0.0; 5]; 5];
    wx[0][0] = t.x;
    wx[1][0] = unit_map[(0, 0)];
    wx[0][1] = unit_map[(0, 1)];
    wy[0][0] = t.y;
    wy[1][0] = unit_map[(1, 0)];
    wy[0][1] = unit_map[(1, 1)];
    let inv = 1.0 / n.max(1) as f64;
    let (sx, sy) = (poly_sum(&wx, m), poly_sum(&wy, m));
    let (xx, yy, xy) = (
        poly_sum(&poly_mul(&wx, &wx), m),
        poly_sum(&poly_mul(&wy, &wy), m),
        poly_sum(&poly_mul(&wx, &wy), m),
    );
    (
        (sx * sx + sy * sy).sqrt() * inv,
        ((xx - yy).powi(2) + 4.0 * xy * xy).sqrt() * inv,
    )
}

/// The report from the sums of the information matrix's monomials and of the squared
/// residuals of `n` readings, and the coverage and support of their directions (shared by
/// [`assess_2d`] and [`assess_2d_from_moments`]).
fn report_2d(
    sums: &[f64; MONOMIALS_2D],
    ss: f64,
    n: usize,
    coverage: Coverage,
    support: &Support2d,
    field: f64,
) -> Assessment2d {
    report_2d_with(sums, ss, n, coverage, field, support_figures_2d(support))
}

/// What the report takes from the support of the directions: the condition number and the
/// dilution of its information matrix (see the `support` module).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SupportFigures {
    condition: f64,
    dilution: f64,
}

/// The condition number (infinite when its eigenvalues cannot be found) and the dilution
/// of a 2-D support.
fn support_figures_2d(support: &Support2d) -> SupportFigures {
    let info = support.information();
    SupportFigures {
        condition: sym_eigen5(&info)
            .map(|(l, _)| condition_from_eigenvalues(l.as_slice()))
            .unwrap_or(f64::INFINITY),
        dilution: support_dilution(&info, support.cells, worst_2d),
    }
}

/// [`report_2d`] given the figures of its support.
fn report_2d_with(
    sums: &[f64; MONOMIALS_2D],
    ss: f64,
    n: usize,
    coverage: Coverage,
    field: f64,
    support: SupportFigures,
) -> Assessment2d {
    let info = information_2d(sums);
    let residual_rms_rel = if n > 0 { (ss / n as f64).sqrt() } else { 0.0 };
    let condition = support.condition;
    let (bound, uncertainty) =
        bound_and_uncertainty(&info, support.dilution, ss, n, field, 2, worst_2d);
    Assessment2d {
        quality: CompassQuality {
            fit: FitQuality {
                points: n,
                coverage: coverage.fraction,
                residual_rms_rel,
                condition,
            },
            heading_error_3sigma_deg: bound,
            heading_error_systematic_deg: 0.0,
            heading_noise_rms_deg: noise_rms_deg(ss, n, 5),
            field_magnitude: field,
            field_ratio_to_expected: None,
            uncertainty,
        },
        coverage,
    }
}

/// The 2-D quality report of `cal` on `points` (see [`assess_2d`]).
pub fn quality_2d(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
    field: f64,
) -> CompassQuality {
    assess_2d(points, cal, field).quality
}
