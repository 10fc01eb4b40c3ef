//! Coverage: how much of the circle (2-D: heading bins and the largest empty arc) or of
//! the sphere (3-D: equal-area direction cells) the readings fill, seen from a centre, and
//! the centre-free turning of the raw locus.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use core::f64::consts::TAU;

use nalgebra::{Vector2, Vector3};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{Error, Result, angle_diff};

use super::{COVERAGE_BINS, GAP_BINS, SPHERE_BANDS, SPHERE_CELLS, SPHERE_SECTORS};
use crate::lm::{BLOCK, blocks};

#[allow(unused_imports)]
use truenorth_core::Float as _;

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

/// Direction of `(x, y)` (not both zero) as a share of a full turn in [0, 1), counted
/// counter-clockwise from +x.
///
/// Bins only need the angle to a small fraction of a bin, and `atan2` was the largest cost
/// of the whole quality pass, so this uses the minimax polynomial of Abramowitz & Stegun
/// (1964) 4.4.49 for `atan z` on [0, 1] (|error| ≤ 2·10⁻⁸ rad) with an octant reduction.
#[inline]
pub(crate) fn turns(y: f64, x: f64) -> f64 {
    use core::f64::consts::{FRAC_PI_2, PI};
    const A: [f64; 8] = [
        -0.333_331_452_8,
        0.199_935_508_5,
        -0.142_088_994_4,
        0.106_562_639_3,
        -0.075_289_640_0,
        0.042_909_613_8,
        -0.016_165_736_7,
        0.002_866_225_7,
    ];
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    // Written as one division of selected operands so that it compiles without branches
    // (and vectorises in the quality pass); the value is the same.
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    let z = num / den;
    let z2 = z * z;
    let mut poly = A[7];
    for &a in A[..7].iter().rev() {
        poly = poly * z2 + a;
    }
    let first = z + z * z2 * poly;
    let mut a = if swap { FRAC_PI_2 - first } else { first };
    if x < 0.0 {
        a = PI - a;
    }
    if y < 0.0 {
        a = TAU - a;
    }
    let t = a / TAU;
    if t >= 1.0 { 0.0 } else { t }
}

/// Occupancy of the fine (gap) direction bins; a coarse (coverage) bin is occupied when one
/// of the [`GAP_BINS`]` / `[`COVERAGE_BINS`] fine bins inside it is.
pub(super) struct AngleBins {
    fine: [bool; GAP_BINS],
}

/// Fine bins per coarse bin.
pub(super) const FINE_PER_COARSE: usize = GAP_BINS / COVERAGE_BINS;

/// The fine bin of the direction `t` (a share of a full turn in [0, 1), from [`turns`]).
/// Written without branches and in `u32` so that it stays in SIMD registers in the block
/// loops; NaN gives bin 0 (callers skip such rows).
#[inline(always)]
pub(super) fn fine_bin(t: f64) -> u32 {
    ((t * GAP_BINS as f64) as u32).min(GAP_BINS as u32 - 1)
}

impl AngleBins {
    pub(super) fn new() -> Self {
        Self {
            fine: [false; GAP_BINS],
        }
    }

    /// Marks the direction of `d` (skipped if zero or not finite).
    #[inline]
    pub(super) fn add(&mut self, d: &Vector2<f64>) {
        if !(d.x.is_finite() && d.y.is_finite()) || (d.x == 0.0 && d.y == 0.0) {
            return;
        }
        self.mark(turns(d.y, d.x));
    }

    /// Marks the direction `t` (a share of a full turn in [0, 1), from [`turns`]).
    #[inline]
    pub(super) fn mark(&mut self, t: f64) {
        self.mark_bin(fine_bin(t));
    }

    /// Marks the fine bin `f` (from [`fine_bin`]).
    #[inline(always)]
    pub(super) fn mark_bin(&mut self, f: u32) {
        self.fine[f as usize] = true;
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

/// Marks the equal-area cells of the directions `d` (a block of vectors, one array per
/// coordinate, with their norms `n`) in `filled`, for the first `len` rows whose norm is
/// positive and finite.
///
/// The cell: Archimedes — the area of a band of the unit sphere is 2π·Δz, so equal steps in
/// `z = d_z/|d|` give equal-area bands — and equal sectors of longitude in each band. The
/// arithmetic goes over the whole block first, in a loop the compiler vectorises; only the
/// marking is done point by point.
#[inline(always)]
pub(super) fn mark_sphere_cells(
    d: &[[f64; BLOCK]; 3],
    n: &[f64; BLOCK],
    len: usize,
    filled: &mut [bool; SPHERE_CELLS],
) -> usize {
    let mut cell = [0u32; BLOCK];
    for i in 0..BLOCK {
        let band = ((d[2][i] / n[i]).clamp(-1.0, 1.0) + 1.0) * 0.5 * SPHERE_BANDS as f64;
        // Computed either way and then chosen, so that the loop has no branch.
        let ti = turns(d[1][i], d[0][i]);
        let t = if d[0][i] == 0.0 && d[1][i] == 0.0 {
            0.0
        } else {
            ti
        };
        // Both in [0, 8] and [0, 16] (or NaN, for a row that is skipped), where `as u32`
        // truncates like `as usize`; u32 keeps the conversion in SIMD registers.
        let b = (band as u32).min(SPHERE_BANDS as u32 - 1);
        let sector = ((t * SPHERE_SECTORS as f64) as u32).min(SPHERE_SECTORS as u32 - 1);
        cell[i] = b * SPHERE_SECTORS as u32 + sector;
    }
    let mut marked = 0;
    for i in 0..len {
        if n[i] > 0.0 && n[i].is_finite() {
            filled[cell[i] as usize] = true;
            marked += 1;
        }
    }
    marked
}

/// Share of the [`SPHERE_CELLS`] equal-area direction cells that hold at least one point,
/// seen from `centre`, in [0, 1]. Non-finite points are skipped. Allocates nothing.
pub fn sphere_coverage<'a>(
    points: impl IntoIterator<Item = &'a Vector3<f64>>,
    centre: &Vector3<f64>,
) -> f64 {
    let mut filled = [false; SPHERE_CELLS];
    let mut points = points.into_iter();
    // A block of points at a time (see `crate::lm::BLOCK`).
    loop {
        let mut d = [[0.0; BLOCK]; 3];
        let mut len = 0;
        for p in points.by_ref().take(BLOCK) {
            for (k, dk) in d.iter_mut().enumerate() {
                dk[len] = p[k] - centre[k];
            }
            len += 1;
        }
        if len == 0 {
            break;
        }
        let n: [f64; BLOCK] = core::array::from_fn(|i| {
            (d[0][i] * d[0][i] + d[1][i] * d[1][i] + d[2][i] * d[2][i]).sqrt()
        });
        mark_sphere_cells(&d, &n, len, &mut filled);
    }
    filled.iter().filter(|&&f| f).count() as f64 / SPHERE_CELLS as f64
}

/// How far the tangent of the locus turns along `points` taken in order, radians (≥ 0): a
/// lower bound that errs short.
///
/// A centre-free measure of the arc that a set of readings covers. Tangents at opposite ends
/// of a diameter of any ellipse are parallel, so over half a turn the tangent of the raw
/// locus turns by exactly π whatever the hard and soft iron; over a shorter arc it turns by
/// less. A calibrator whose own centre is wrong sees its readings spread over more of the
/// circle than they are; this measure cannot be fooled that way.
///
/// The turning is taken between successive chords. On a convex curve each chord's direction
/// lies between the tangents at its two ends (mean value theorem), so the result never exceeds
/// the tangent's turning from the first point to the last: half an ellipse never reads as
/// more than π. It falls short by up to one chord's turning at each end. The wrapped
/// differences telescope, so noise enters only through the two end chords; chords shorter
/// than `min_chord` (and than 10⁻¹² of the locus size) are skipped, the next point being
/// taken from the last one kept, so that noisy points a short way apart cannot turn the
/// chords at random. Fewer than three usable points give 0.
pub fn locus_turning_rad<'a>(
    points: impl IntoIterator<Item = &'a Vector2<f64>>,
    min_chord: f64,
) -> f64 {
    let mut prev_point: Option<Vector2<f64>> = None;
    let mut dir: Option<f64> = None;
    let mut turned = 0.0;
    // Compared squared, so that a skipped point costs no square root (the batch fits pass
    // every reading through here).
    let chord2 = min_chord.max(0.0) * min_chord.max(0.0);
    for p in points {
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        let Some(q) = prev_point else {
            prev_point = Some(*p);
            continue;
        };
        let d = p - q;
        let scale2 = p
            .norm_squared()
            .max(q.norm_squared())
            .max(f64::MIN_POSITIVE);
        if d.norm_squared() <= chord2.max(1e-24 * scale2) {
            continue;
        }
        let a = d.y.atan2(d.x);
        if let Some(prev) = dir {
            turned += angle_diff(a, prev);
        }
        dir = Some(a);
        prev_point = Some(*p);
    }
    turned.abs()
}

/// Refuses a 2-D calibration whose data span less than `need_deg` of heading (see
/// [`super::MIN_ARC_DEG`]) with [`Error::InsufficientCoverage`].
pub fn require_arc(coverage: &Coverage, need_deg: f64) -> Result<()> {
    let covered_deg = coverage.span_rad().to_degrees();
    if covered_deg < need_deg {
        Err(Error::InsufficientCoverage {
            // Rounded down, so a refusal never prints a span equal to the one it needs.
            covered_deg: covered_deg.floor(),
            need_deg,
        })
    } else {
        Ok(())
    }
}

/// Refuses a 3-D calibration whose data fill less than `need` of the direction cells (see
/// [`super::MIN_SPHERE_COVERAGE`]) with [`Error::InsufficientCoverage`]; the degrees reported are
/// the solid angle covered, as an equivalent share of 360°.
pub fn require_sphere_coverage(fraction: f64, need: f64) -> Result<()> {
    if fraction < need {
        Err(Error::InsufficientSphereCoverage {
            covered_fraction: fraction,
            need_fraction: need,
        })
    } else {
        Ok(())
    }
}

/// Coverage of the calibrated readings `cal(p)` of `points` about the origin, with the same
/// arithmetic as [`super::assess_2d`] (so a calibrator that refuses on it and reports
/// [`super::assess_2d`]'s coverage sees the same bins). Non-finite readings are skipped. Allocates
/// nothing.
pub fn calibrated_coverage_2d(points: &[Vector2<f64>], cal: &CompassCalibration2d) -> Coverage {
    let mut bins = AngleBins::new();
    let (s, c) = (&cal.soft_iron, &cal.hard_iron);
    // A block of points at a time (see `crate::lm::BLOCK`): every direction first, in a loop
    // without branches that the compiler vectorises, then the marking.
    let mut bin = [0u32; BLOCK];
    let mut keep = [false; BLOCK];
    for ([px, py], len) in blocks(points) {
        for i in 0..BLOCK {
            let (dx, dy) = (px[i] - c.x, py[i] - c.y);
            let (hx, hy) = (
                s[(0, 0)] * dx + s[(0, 1)] * dy,
                s[(1, 0)] * dx + s[(1, 1)] * dy,
            );
            let rho2 = hx * hx + hy * hy;
            keep[i] = rho2 > 0.0 && rho2.is_finite();
            bin[i] = fine_bin(turns(hy, hx));
        }
        for i in 0..len {
            if keep[i] {
                bins.mark_bin(bin[i]);
            }
        }
    }
    bins.coverage()
}
