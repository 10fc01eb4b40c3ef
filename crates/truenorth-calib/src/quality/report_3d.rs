//! The 3-D [`CompassQuality`] of a calibration, from one pass over the readings: coverage
//! of the equal-area direction cells, the support's dilution and the information matrix.

use nalgebra::Vector3;
use truenorth_compass::CompassCalibration3d;
use truenorth_core::{CompassQuality, FitQuality};

use super::bounds::{
    MONOMIALS_3D, QUAD_3D, information_3d, monomial_plan_3d, noise_rms_deg, worst_3d,
};
use super::sphere_cells::sphere_cell;
use super::support::{Support3d, support_dilution};
use super::uncertainty::bound_and_uncertainty;
use crate::numerics::blocks::{BLOCK, blocks, dot_block, sum_block};
use crate::numerics::linalg::{condition_from_eigenvalues, sym_eigen9};
use crate::numerics::readings::Readings;
use crate::numerics::segments::{RunFold, add_sums, by_blocks, fold};
use crate::quality::SPHERE_CELLS;
use truenorth_core::Result;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

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
