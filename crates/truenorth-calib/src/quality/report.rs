//! Report assembly: the 2-D and 3-D [`CompassQuality`] of a calibration, from one pass
//! over the readings or (2-D) from the monomial sums of the fit.

use nalgebra::Vector2;
use nalgebra::Vector3;
use truenorth_compass::{CompassCalibration2d, CompassCalibration3d};
use truenorth_core::{CompassQuality, FitQuality};

use super::bounds::{
    MONOMIALS_2D, MONOMIALS_3D, QUAD_3D, information_2d, information_3d, monomial_plan_3d,
    noise_rms_deg, worst_2d, worst_3d,
};
use super::coverage::Coverage;
use super::pass_2d::{ReportSums, sums_2d};
use super::sphere_cells::sphere_cell;
use super::support::{Support2d, Support3d, support_dilution};
use super::uncertainty::bound_and_uncertainty;
use crate::fits::readings::Readings;
use crate::numerics::blocks::{BLOCK, blocks, dot_block, sum_block};
use crate::numerics::linalg::{condition_from_eigenvalues, sym_eigen5, sym_eigen9};
use crate::numerics::segments::{RunFold, add_sums, by_blocks, fold};
use crate::quality::SPHERE_CELLS;
use truenorth_core::Result;

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

/// Counts in `in_cell` the kept readings of one block (`len` points) of readings `p` in
/// each equal-area cell of their directions under `cal`.
#[inline(always)]
fn count_cells(
    in_cell: &mut [u32; SPHERE_CELLS],
    p: &[[f64; BLOCK]; 3],
    len: usize,
    cal: &CompassCalibration3d,
) {
    let b = CalibratedBlock::of(p, len, cal);
    for i in 0..len {
        if b.kept[i] > 0.0 {
            in_cell[b.cell[i] as usize] += 1;
        }
    }
}

/// The kept readings of `points` in each equal-area cell under `cal` ([`count_cells`]),
/// segment by segment (see `fold`).
fn cell_counts<R: Readings<3> + ?Sized>(
    points: &R,
    cal: &CompassCalibration3d,
) -> Result<[u32; SPHERE_CELLS]> {
    fold(
        points,
        &RunFold {
            start: || [0u32; SPHERE_CELLS],
            add: by_blocks(
                |in_cell: &mut [u32; SPHERE_CELLS], p: &[[f64; BLOCK]; 3], len| {
                    count_cells(in_cell, p, len, cal);
                },
            ),
            merge: |in_cell: &mut [u32; SPHERE_CELLS], later: [u32; SPHERE_CELLS]| {
                for (a, b) in in_cell.iter_mut().zip(later) {
                    *a += b;
                }
            },
        },
    )
}

/// One over the number of kept readings in each equal-area cell (0 for an empty cell), from
/// the counts of [`count_cells`]: the weights of the support.
fn cell_weights(in_cell: &[u32; SPHERE_CELLS]) -> [f64; SPHERE_CELLS] {
    core::array::from_fn(|k| {
        if in_cell[k] > 0 {
            1.0 / f64::from(in_cell[k])
        } else {
            0.0
        }
    })
}

/// The dilution of the support of the directions of `points` under `cal` alone (see the
/// `support` module), as [`assess_3d`] reports it in [`CompassUncertainty::dilution`](truenorth_core::CompassUncertainty::dilution), without the
/// sums of every reading, the residuals and the bound: what a check of the geometry before
/// a fit needs. Allocates nothing.
/// An error replaying `points` is returned as it is.
pub(crate) fn support_dilution_3d<R: Readings<3> + ?Sized>(
    points: &R,
    cal: &CompassCalibration3d,
) -> Result<f64> {
    let in_cell = cell_counts(points, cal)?;
    let weight = cell_weights(&in_cell);
    let plan = monomial_plan_3d();
    // Each segment's accumulator carries its block's columns (every entry is written for
    // each block).
    type Acc = ([f64; MONOMIALS_3D], [[f64; BLOCK]; 9], [[f64; BLOCK]; 9]);
    let (sums, _, _) = fold(
        points,
        &RunFold {
            start: || ([0.0; MONOMIALS_3D], [[0.0; BLOCK]; 9], [[0.0; BLOCK]; 9]),
            add: by_blocks(
                |(sums, cols, weighted): &mut Acc, p: &[[f64; BLOCK]; 3], len| {
                    CalibratedBlock::of(p, len, cal).monomials(&weight, cols, weighted);
                    for (wk, &(a, c)) in sums.iter_mut().zip(&plan) {
                        *wk += dot_block(&weighted[a], &cols[c]);
                    }
                },
            ),
            merge: |(sums, _, _): &mut Acc, (later, _, _): Acc| add_sums(sums, later),
        },
    )?;
    let cells = weight.iter().filter(|&&x| x > 0.0).count();
    let support = Support3d { sums, cells };
    Ok(support_dilution(&support.information(), cells, worst_3d))
}

/// A block of readings calibrated (see `crate::numerics::blocks::BLOCK`): `h = soft_iron · (p − hard_iron)`
/// as `CompassCalibration3d::correct`, its norm, its equal-area cell and whether the row is
/// kept (1: finite, not at the centre, not past the end of the data; 0 otherwise). Every
/// loop is written without branches so that it vectorises.
struct CalibratedBlock {
    h: [[f64; BLOCK]; 3],
    rho: [f64; BLOCK],
    cell: [u32; BLOCK],
    kept: [f64; BLOCK],
}

impl CalibratedBlock {
    #[inline(always)]
    fn of(p: &[[f64; BLOCK]; 3], len: usize, cal: &CompassCalibration3d) -> Self {
        let (s, c) = (&cal.soft_iron, &cal.hard_iron);
        let mut b = Self {
            h: [[0.0; BLOCK]; 3],
            rho: [0.0; BLOCK],
            cell: [0; BLOCK],
            kept: [0.0; BLOCK],
        };
        // Row `i` of every column at once: indexed, so that the loop vectorises.
        #[allow(clippy::needless_range_loop)]
        for i in 0..BLOCK {
            let d = [p[0][i] - c.x, p[1][i] - c.y, p[2][i] - c.z];
            for a in 0..3 {
                b.h[a][i] = s[(a, 0)] * d[0] + s[(a, 1)] * d[1] + s[(a, 2)] * d[2];
            }
            let rho =
                (b.h[0][i] * b.h[0][i] + b.h[1][i] * b.h[1][i] + b.h[2][i] * b.h[2][i]).sqrt();
            b.rho[i] = rho;
            b.kept[i] = if rho > 0.0 && rho.is_finite() && i < len {
                1.0
            } else {
                0.0
            };
        }
        for i in 0..BLOCK {
            b.cell[i] = sphere_cell(b.h[0][i], b.h[1][i], b.h[2][i], b.rho[i]);
        }
        b
    }

    /// The directions `u = h/|h|` in `cols` 0–2 and the products `u_a u_b` of `QUAD_3D` in
    /// columns 3–8, zeros for the rows not kept (which then add nothing to a sum);
    /// `weighted` the same times the reading's cell weight from `weight`. The weights are
    /// looked up apart, so that the arithmetic loop has no indexed load and vectorises.
    #[inline(always)]
    fn monomials(
        &self,
        weight: &[f64; SPHERE_CELLS],
        cols: &mut [[f64; BLOCK]; 9],
        weighted: &mut [[f64; BLOCK]; 9],
    ) {
        let mut w = [0.0; BLOCK];
        for i in 0..BLOCK {
            w[i] = weight[self.cell[i] as usize] * self.kept[i];
        }
        for i in 0..BLOCK {
            let k = self.kept[i] > 0.0;
            let inv_rho = 1.0 / self.rho[i];
            for (col, h) in cols.iter_mut().zip(&self.h) {
                col[i] = if k { h[i] * inv_rho } else { 0.0 };
            }
            for (j, &(a, c)) in QUAD_3D.iter().enumerate() {
                cols[3 + j][i] = cols[a][i] * cols[c][i];
            }
            for a in 0..9 {
                weighted[a][i] = w[i] * cols[a][i];
            }
        }
    }
}

/// The 3-D quality report of `cal` on `points` and what they determine: coverage as the
/// information share of an evenly covered sphere ([`CompassUncertainty::efficiency`](truenorth_core::CompassUncertainty::efficiency) of the
/// support, see the `support` module), residual RMS relative to `field` (the radius of the
/// calibrated sphere; see [`super::mean_corrected_norm_3d`] if the calibrator defines
/// none), the condition number of the support's 9-parameter information matrix and the
/// direction-error bound of the module documentation (from every reading). Non-finite
/// readings are skipped. Allocates nothing.
pub fn assess_3d(
    points: &[Vector3<f64>],
    cal: &CompassCalibration3d,
    field: f64,
) -> CompassQuality {
    let mut in_cell = [0u32; SPHERE_CELLS];
    for (p, len) in blocks(points) {
        count_cells(&mut in_cell, &p, len, cal);
    }
    let mut sums = Sums3d::new(cell_weights(&in_cell), field);
    for (p, len) in blocks(points) {
        sums.add_block(&p, len, cal);
    }
    sums.report(field)
}

/// [`assess_3d`] of readings replayed (see [`Readings`]); an error replaying them is
/// returned as it is.
pub(crate) fn assess_3d_of<R: Readings<3> + ?Sized>(
    points: &R,
    cal: &CompassCalibration3d,
    field: f64,
) -> Result<CompassQuality> {
    assess_3d_with_harmonics_of(points, cal, field).map(|(q, _)| q)
}

/// [`assess_3d_of`] and, from the same pass, the first and second harmonics `(h₁, h₂)` of
/// the calibrated directions `u` (the length of their mean; the distance of their second
/// moment from `I/3` over `√(2/3)`; each 0 for an even tumble, 1 for readings all in one
/// direction), `None` without a usable reading.
pub(crate) fn assess_3d_with_harmonics_of<R: Readings<3> + ?Sized>(
    points: &R,
    cal: &CompassCalibration3d,
    field: f64,
) -> Result<(CompassQuality, Option<(f64, f64)>)> {
    let in_cell = cell_counts(points, cal)?;
    let weight = cell_weights(&in_cell);
    let sums = fold(
        points,
        &RunFold {
            start: || Sums3d::new(weight, field),
            add: by_blocks(|sums: &mut Sums3d, p: &[[f64; BLOCK]; 3], len| {
                sums.add_block(p, len, cal);
            }),
            merge: |sums: &mut Sums3d, later| sums.merge(&later),
        },
    )?;
    let harmonics = sums.direction_harmonics();
    Ok((sums.report(field), harmonics))
}

/// The sums of [`assess_3d`]'s second pass, a block of readings at a time: of the squared
/// residuals and of the monomials of `u` that make up the information matrix (see
/// `information_3d`), plain and weighted by the cells.
struct Sums3d {
    weight: [f64; SPHERE_CELLS],
    inv_f: f64,
    plan: [(usize, usize); MONOMIALS_3D],
    sums: [f64; MONOMIALS_3D],
    support_sums: [f64; MONOMIALS_3D],
    ss: f64,
    n: usize,
    /// Sums of the columns: of `u` (0–2) and of its products `u_a u_b` (3–8).
    moments: [f64; 9],
    // The block's columns, kept between blocks (every entry is written for each block).
    cols: [[f64; BLOCK]; 9],
    weighted: [[f64; BLOCK]; 9],
    r2: [f64; BLOCK],
}

impl Sums3d {
    fn new(weight: [f64; SPHERE_CELLS], field: f64) -> Self {
        Self {
            weight,
            inv_f: 1.0 / field,
            plan: monomial_plan_3d(),
            sums: [0.0; MONOMIALS_3D],
            support_sums: [0.0; MONOMIALS_3D],
            ss: 0.0,
            n: 0,
            moments: [0.0; 9],
            cols: [[0.0; BLOCK]; 9],
            weighted: [[0.0; BLOCK]; 9],
            r2: [0.0; BLOCK],
        }
    }

    /// Adds the sums of `later`, the sums of the readings that follow these (with the same
    /// weights and field).
    fn merge(&mut self, later: &Self) {
        add_sums(&mut self.sums, later.sums);
        add_sums(&mut self.support_sums, later.support_sums);
        add_sums(&mut self.moments, later.moments);
        self.ss += later.ss;
        self.n += later.n;
    }

    /// Adds a block (see `crate::numerics::blocks::BLOCK`): first every point's direction,
    /// its products (`CalibratedBlock::monomials`) and its residual, then the sums.
    #[inline(always)]
    fn add_block(&mut self, p: &[[f64; BLOCK]; 3], len: usize, cal: &CompassCalibration3d) {
        let Self {
            cols, weighted, r2, ..
        } = self;
        let b = CalibratedBlock::of(p, len, cal);
        b.monomials(&self.weight, cols, weighted);
        for ((sq, rho), kept) in r2.iter_mut().zip(&b.rho).zip(&b.kept) {
            let r = rho * self.inv_f - 1.0;
            *sq = if *kept > 0.0 { r * r } else { 0.0 };
        }
        for ((sk, wk), &(a, c)) in self
            .sums
            .iter_mut()
            .zip(self.support_sums.iter_mut())
            .zip(&self.plan)
        {
            *sk += dot_block(&cols[a], &cols[c]);
            *wk += dot_block(&weighted[a], &cols[c]);
        }
        for (m, col) in self.moments.iter_mut().zip(cols.iter()) {
            *m += sum_block(col);
        }
        self.ss += sum_block(r2);
        self.n += sum_block(&b.kept) as usize;
    }

    /// See [`assess_3d_with_harmonics_of`].
    fn direction_harmonics(&self) -> Option<(f64, f64)> {
        if self.n == 0 {
            return None;
        }
        let inv = 1.0 / self.n as f64;
        let [x, y, z, xx, xy, xz, yy, yz, zz] = self.moments.map(|m| m * inv);
        let h1 = (x * x + y * y + z * z).sqrt();
        let third = 1.0 / 3.0;
        let (dx, dy, dz) = (xx - third, yy - third, zz - third);
        let h2 = (dx * dx + dy * dy + dz * dz + 2.0 * (xy * xy + xz * xz + yz * yz)).sqrt()
            / (2.0f64 / 3.0).sqrt();
        Some((h1, h2))
    }

    /// The report from the sums.
    fn report(self, field: f64) -> CompassQuality {
        let Self {
            weight,
            sums,
            support_sums,
            ss,
            n,
            ..
        } = self;
        let support = Support3d {
            sums: support_sums,
            cells: weight.iter().filter(|&&x| x > 0.0).count(),
        };
        let info = information_3d(&sums);
        let support_info = support.information();
        let residual_rms_rel = if n > 0 { (ss / n as f64).sqrt() } else { 0.0 };
        let condition = sym_eigen9(&support_info)
            .map(|(l, _)| condition_from_eigenvalues(l.as_slice()))
            .unwrap_or(f64::INFINITY);
        let (bound, uncertainty) = bound_and_uncertainty(
            &info,
            support_dilution(&support_info, support.cells, worst_3d),
            ss,
            n,
            field,
            3,
            worst_3d,
        );
        CompassQuality {
            fit: FitQuality {
                points: n,
                coverage: uncertainty.efficiency(3),
                residual_rms_rel,
                condition,
            },
            heading_error_3sigma_deg: bound,
            heading_error_systematic_deg: 0.0,
            heading_noise_rms_deg: noise_rms_deg(ss, n, 9),
            field_magnitude: field,
            field_ratio_to_expected: None,
            uncertainty,
        }
    }
}
