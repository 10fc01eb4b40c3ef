//! Coverage of the circle: how much of it (heading bins and the largest empty arc) the
//! readings fill, seen from a centre or after a calibration.

use core::f64::consts::TAU;

use nalgebra::Vector2;
use truenorth_compass::CompassCalibration2d;

use super::direction_bins::{bin_if_clear, coarse_fixed, fine_bin, fine_bin_exact, fine_bin_xy};
use super::support::{GAP_BINS, Support2d};
use crate::numerics::blocks::{BLOCK, blocks};
use crate::numerics::readings::{Readings, replay_points};
use crate::numerics::segments::{RunFold, by_blocks, fold};
use truenorth_core::Result;

/// Number of heading bins used for coverage (10° each).
pub const COVERAGE_BINS: usize = 36;

/// How much of the circle a set of points covers, seen from a centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coverage {
    /// Share of the [`COVERAGE_BINS`] direction bins that hold at least one point, in [0, 1].
    pub fraction: f64,
    /// The largest empty arc between consecutive occupied directions, radians (measured in
    /// bins of 0.5°).
    pub largest_gap_rad: f64,
}

impl Coverage {
    /// The arc covered: 2π minus the largest gap, radians.
    pub fn span_rad(&self) -> f64 {
        TAU - self.largest_gap_rad
    }
}

/// Occupancy of the fine (gap) direction bins; a coarse (coverage) bin is occupied when one
/// of the [`GAP_BINS`]` / `[`COVERAGE_BINS`] fine bins inside it is.
pub(super) struct AngleBins {
    fine: [bool; GAP_BINS],
}

/// Fine bins per coarse bin.
pub(super) const FINE_PER_COARSE: usize = GAP_BINS / COVERAGE_BINS;

impl AngleBins {
    pub(super) fn new() -> Self {
        Self {
            fine: [false; GAP_BINS],
        }
    }

    /// Adds the directions marked in `later`.
    pub(super) fn merge(&mut self, later: &Self) {
        for (a, b) in self.fine.iter_mut().zip(&later.fine) {
            *a |= *b;
        }
    }

    /// Marks the direction of `d` (skipped if zero or not finite).
    #[inline]
    pub(super) fn add(&mut self, d: &Vector2<f64>) {
        if !(d.x.is_finite() && d.y.is_finite()) || (d.x == 0.0 && d.y == 0.0) {
            return;
        }
        self.mark_bin(fine_bin_xy(d.y, d.x));
    }

    /// Marks the direction `t` (a share of a full turn in [0, 1), from [`turns`](crate::quality::direction_bins::turns)).
    #[inline]
    pub(super) fn mark(&mut self, t: f64) {
        self.mark_bin(fine_bin(t));
    }

    /// Marks the fine bin `f` (from [`fine_bin`]).
    #[inline(always)]
    pub(super) fn mark_bin(&mut self, f: u32) {
        self.fine[f as usize] = true;
    }

    /// The directions marked, each 0.5° bin once (see the `support` module).
    pub(super) fn support(&self) -> Support2d {
        Support2d::of_bins(&self.fine)
    }

    pub(super) fn coverage(&self) -> Coverage {
        let Some(start) = self.fine.iter().position(|&f| f) else {
            return Coverage {
                fraction: 0.0,
                largest_gap_rad: TAU,
            };
        };
        let n = self
            .fine
            .chunks_exact(FINE_PER_COARSE)
            .filter(|c| c.iter().any(|&f| f))
            .count();
        // Largest run of empty fine bins, going once round the circle from an occupied one.
        let (mut gap, mut run) = (0usize, 0usize);
        for k in 1..=GAP_BINS {
            if self.fine[(start + k) % GAP_BINS] {
                run = 0;
            } else {
                run += 1;
                gap = gap.max(run);
            }
        }
        Coverage {
            fraction: n as f64 / COVERAGE_BINS as f64,
            largest_gap_rad: gap as f64 * TAU / GAP_BINS as f64,
        }
    }
}

/// Coverage of `points` seen from `centre`: share of 10° bins filled and the largest empty
/// arc. Non-finite points are skipped. Allocates nothing.
pub fn coverage<'a>(
    points: impl IntoIterator<Item = &'a Vector2<f64>>,
    centre: &Vector2<f64>,
) -> Coverage {
    let mut bins = AngleBins::new();
    for p in points {
        bins.add(&(p - centre));
    }
    bins.coverage()
}

/// Coverage of `readings` seen from `centre`, as [`coverage`] gives for them in one slice.
pub(crate) fn coverage_of<R: Readings<2> + ?Sized>(
    readings: &R,
    centre: &Vector2<f64>,
) -> Result<Coverage> {
    let mut bins = AngleBins::new();
    replay_points(readings, |p| bins.add(&(p - centre)))?;
    Ok(bins.coverage())
}

/// Coverage of the calibrated readings `cal(p)` of `points` about the origin, with the same
/// arithmetic as [`super::assess_2d`] (so a calibrator that refuses on it and reports
/// [`super::assess_2d`]'s coverage sees the same bins). Non-finite readings are skipped. Allocates
/// nothing.
pub fn calibrated_coverage_2d(points: &[Vector2<f64>], cal: &CompassCalibration2d) -> Coverage {
    let mut bins = AngleBins::new();
    for (p, len) in blocks(points) {
        mark_calibrated_block(&mut bins, &p, len, cal);
    }
    bins.coverage()
}

/// The coverage of [`calibrated_coverage_2d`] and the support of the same directions (each
/// 0.5° bin once; see the `support` module), from one pass over `readings`.
pub(crate) fn calibrated_directions_2d<R: Readings<2> + ?Sized>(
    readings: &R,
    cal: &CompassCalibration2d,
) -> Result<(Coverage, Support2d)> {
    let bins = fold(
        readings,
        &RunFold {
            start: AngleBins::new,
            add: by_blocks(|bins: &mut AngleBins, p: &[[f64; BLOCK]; 2], len| {
                mark_calibrated_block(bins, p, len, cal);
            }),
            merge: |bins: &mut AngleBins, later| bins.merge(&later),
        },
    )?;
    Ok((bins.coverage(), bins.support()))
}

/// Marks in `bins` the directions of the calibrated readings of [`calibrated_coverage_2d`]
/// of one block (`len` points) of readings `p`.
#[inline(always)]
fn mark_calibrated_block(
    bins: &mut AngleBins,
    [px, py]: &[[f64; BLOCK]; 2],
    len: usize,
    cal: &CompassCalibration2d,
) {
    let (s, c) = (&cal.soft_iron, &cal.hard_iron);
    let calibrated = |x: f64, y: f64| {
        let (dx, dy) = (x - c.x, y - c.y);
        (
            s[(0, 0)] * dx + s[(0, 1)] * dy,
            s[(1, 0)] * dx + s[(1, 1)] * dy,
        )
    };
    // Every direction first, in a loop without branches that the compiler vectorises (see
    // `crate::numerics::blocks::BLOCK`), then the marking, where the few directions next to
    // a bin boundary are computed again and binned by `turns`.
    let mut coarse = [0u32; BLOCK];
    let mut keep = [false; BLOCK];
    for i in 0..BLOCK {
        let (dx, dy) = (px[i] - c.x, py[i] - c.y);
        let (hx, hy) = (
            s[(0, 0)] * dx + s[(0, 1)] * dy,
            s[(1, 0)] * dx + s[(1, 1)] * dy,
        );
        let rho2 = hx * hx + hy * hy;
        keep[i] = rho2 > 0.0 && rho2.is_finite();
        coarse[i] = coarse_fixed(hy, hx);
    }
    for i in 0..len {
        if keep[i] {
            let b = bin_if_clear(coarse[i]).unwrap_or_else(|| {
                let (hx, hy) = calibrated(px[i], py[i]);
                fine_bin_exact(hy, hx)
            });
            bins.mark_bin(b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::direction_bins::tests::{boundary, reference_bin};
    use super::*;
    extern crate alloc;
    use alloc::vec::Vec;
    use nalgebra::Matrix2;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        /// The calibrated coverage (fraction and largest gap) is the one the bins of `turns`
        /// give, bit for bit.
        #[test]
        fn calibrated_coverage_matches_turns_bins(
            pts in proptest::collection::vec((-5.0f64..5.0, -5.0f64..5.0), 0..300),
            on_boundary in proptest::collection::vec((0u32..GAP_BINS as u32, 0.1f64..3.0), 0..50),
            a in 0.5f64..2.0, b in 0.5f64..2.0, c in -0.4f64..0.4,
            cx in -1.0f64..1.0, cy in -1.0f64..1.0,
        ) {
            let cal = CompassCalibration2d {
                hard_iron: Vector2::new(cx, cy),
                soft_iron: Matrix2::new(a, c, c, b),
            };
            // Readings whose calibrated directions lie on bin boundaries (identity soft iron
            // for those, so that they stay on them), and arbitrary ones.
            let mut points: Vec<Vector2<f64>> =
                pts.iter().map(|&(x, y)| Vector2::new(x, y)).collect();
            let got = calibrated_coverage_2d(&points, &cal);
            let mut bins = AngleBins::new();
            for p in &points {
                let h = cal.soft_iron * (p - cal.hard_iron);
                let rho2 = h.norm_squared();
                if rho2 > 0.0 && rho2.is_finite() {
                    bins.mark_bin(reference_bin(h.y, h.x));
                }
            }
            prop_assert_eq!(got, bins.coverage());

            let ident = CompassCalibration2d { hard_iron: Vector2::new(cx, cy), soft_iron: Matrix2::identity() };
            points = on_boundary
                .iter()
                .map(|&(k, r)| {
                    let (y, x) = boundary(k, r, 0, 0);
                    Vector2::new(x + cx, y + cy)
                })
                .collect();
            let got = calibrated_coverage_2d(&points, &ident);
            let mut bins = AngleBins::new();
            for p in &points {
                let h = p - ident.hard_iron;
                if h.norm_squared() > 0.0 {
                    bins.mark_bin(reference_bin(h.y, h.x));
                }
            }
            prop_assert_eq!(got, bins.coverage());
        }
    }
}
