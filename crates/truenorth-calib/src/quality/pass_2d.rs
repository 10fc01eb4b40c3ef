//! The one pass over the 2-D readings behind the report of
//! [`assess_2d`](super::assess_2d): each calibrated reading's direction and residual, a block
//! at a time, summed into the information matrix's monomials and marked in the heading bins.

use nalgebra::Vector2;
use truenorth_compass::CompassCalibration2d;

use super::bounds::MONOMIALS_2D;
use super::coverage::{AngleBins, Coverage};
use super::direction_bins::turns;
use super::support::Support2d;
use crate::numerics::blocks::{BLOCK, blocks, dot_block, sum_block};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// What the one pass over the readings of [`assess_2d`](super::assess_2d) leaves for the report: the sums of
/// the information matrix's twelve monomials, the sum of the squared residuals, the count of
/// usable readings, their coverage and the support of their directions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ReportSums {
    pub sums: [f64; 12],
    pub ss: f64,
    pub n: usize,
    pub coverage: Coverage,
    pub support: Support2d,
}

/// The pass of [`assess_2d`](super::assess_2d).
pub(super) fn sums_2d(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
    field: f64,
) -> ReportSums {
    let mut bins = AngleBins::new();
    // Sums of the squared residuals and of the monomials of `u` that make up the
    // information matrix (see `information_2d`).
    let mut sums = [0.0; MONOMIALS_2D];
    let mut ss = 0.0;
    let mut n = 0usize;
    let inv_f = 1.0 / field;
    // A block of points at a time (see `crate::numerics::blocks::BLOCK`): first every point's direction,
    // its products, its residual and its heading, then the sums and the bins.
    for ([px, py], len) in blocks(points) {
        let block = DirectionBlock2d::of(&px, &py, len, cal, inv_f);
        block.add_sums(&mut sums, &mut ss);
        n += block.mark(len, &mut bins);
    }
    ReportSums {
        sums,
        ss,
        n,
        coverage: bins.coverage(),
        support: bins.support(),
    }
}

/// A block of 2-D readings calibrated (see `crate::numerics::blocks::BLOCK`): each row's
/// direction `u = h/|h|` (`h = soft_iron · (p − hard_iron)`), its products, its squared
/// residual and its heading (as a share of a turn). The rows not kept (non-finite, at the
/// centre, past the end of the data) have a zero direction and residual, which add nothing
/// to the sums and mark the row as skipped for the bins (a kept row's direction is a unit
/// vector).
struct DirectionBlock2d {
    ux: [f64; BLOCK],
    uy: [f64; BLOCK],
    xx: [f64; BLOCK],
    xy: [f64; BLOCK],
    yy: [f64; BLOCK],
    r2: [f64; BLOCK],
    t: [f64; BLOCK],
}

impl DirectionBlock2d {
    /// The block of the readings `(px, py)`, `len` of them data, under `cal` with the
    /// reciprocal of the field `inv_f`; one loop without branches, which vectorises.
    #[inline(always)]
    fn of(
        px: &[f64; BLOCK],
        py: &[f64; BLOCK],
        len: usize,
        cal: &CompassCalibration2d,
        inv_f: f64,
    ) -> Self {
        let (s, c) = (&cal.soft_iron, &cal.hard_iron);
        let mut b = Self {
            ux: [0.0; BLOCK],
            uy: [0.0; BLOCK],
            xx: [0.0; BLOCK],
            xy: [0.0; BLOCK],
            yy: [0.0; BLOCK],
            r2: [0.0; BLOCK],
            t: [0.0; BLOCK],
        };
        for i in 0..BLOCK {
            // h = soft_iron · (p − hard_iron), as `CompassCalibration2d::correct`.
            let (dx, dy) = (px[i] - c.x, py[i] - c.y);
            let (hx, hy) = (
                s[(0, 0)] * dx + s[(0, 1)] * dy,
                s[(1, 0)] * dx + s[(1, 1)] * dy,
            );
            let rho = (hx * hx + hy * hy).sqrt();
            let keep = rho > 0.0 && rho.is_finite() && i < len;
            let inv_rho = 1.0 / rho;
            let (x, y) = if keep {
                (hx * inv_rho, hy * inv_rho)
            } else {
                (0.0, 0.0)
            };
            let r = rho * inv_f - 1.0;
            b.ux[i] = x;
            b.uy[i] = y;
            b.xx[i] = x * x;
            b.xy[i] = x * y;
            b.yy[i] = y * y;
            b.r2[i] = if keep { r * r } else { 0.0 };
            b.t[i] = turns(hy, hx);
        }
        b
    }

    /// Adds the block's monomials of `u` to `sums` (in the order of `information_2d`: x², xy,
    /// y², x³, x²y, xy², y³, x⁴, x³y, x²y², xy³, y⁴) and its squared residuals to `ss`.
    #[inline(always)]
    fn add_sums(&self, sums: &mut [f64; MONOMIALS_2D], ss: &mut f64) {
        let (ux, uy, xx, xy, yy) = (&self.ux, &self.uy, &self.xx, &self.xy, &self.yy);
        let products = [
            (ux, ux),
            (ux, uy),
            (uy, uy),
            (xx, ux),
            (xx, uy),
            (yy, ux),
            (yy, uy),
            (xx, xx),
            (xx, xy),
            (xx, yy),
            (xy, yy),
            (yy, yy),
        ];
        for (sk, (a, b)) in sums.iter_mut().zip(products) {
            *sk += dot_block(a, b);
        }
        *ss += sum_block(&self.r2);
    }

    /// Marks the headings of the kept rows among the first `len` in `bins`; how many.
    #[inline(always)]
    fn mark(&self, len: usize, bins: &mut AngleBins) -> usize {
        let mut n = 0;
        for i in 0..len {
            if self.ux[i] != 0.0 || self.uy[i] != 0.0 {
                bins.mark(self.t[i]);
                n += 1;
            }
        }
        n
    }
}
