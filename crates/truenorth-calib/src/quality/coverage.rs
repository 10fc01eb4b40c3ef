//! Coverage: how much of the circle (2-D: heading bins and the largest empty arc) or of
//! the sphere (3-D: equal-area direction cells) the readings fill, seen from a centre, and
//! the centre-free turning of the raw locus.

use core::f64::consts::TAU;

use nalgebra::{Vector2, Vector3};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{Error, Result, angle_diff};

use super::support::{GAP_BINS, Support2d};
use crate::numerics::blocks::{BLOCK, blocks};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Number of heading bins used for coverage (10° each).
pub const COVERAGE_BINS: usize = 36;

/// Equal-area latitude bands of the direction cells on the sphere (uniform in `sin(lat)`,
/// so every band has the same area).
pub const SPHERE_BANDS: usize = 8;

/// Longitude sectors per band of the direction cells on the sphere.
pub const SPHERE_SECTORS: usize = 16;

/// Number of equal-area direction cells on the sphere (`SPHERE_BANDS × SPHERE_SECTORS`,
/// each about 320 square degrees, roughly 18° × 18° at the equator).
pub const SPHERE_CELLS: usize = SPHERE_BANDS * SPHERE_SECTORS;

/// The shortest arc of a turn, degrees, from which a 2-D calibration is accepted.
///
/// A half circle does not determine an ellipse (the missing half is extrapolated, and a
/// small noise at its ends moves the centre a lot), so every 2-D calibrator refuses spans up
/// to a little beyond 180°; the margin keeps a noisy half circle from slipping through.
pub const MIN_ARC_DEG: f64 = 200.0;

/// The share of the direction cells on the sphere ([`SPHERE_CELLS`]) below which the online
/// ellipsoid calibrator explains a failed fit as too little of the sphere seen (no
/// calibrator refuses a successful fit on it: whether the orientations determine a 3-D
/// calibration is judged by their dilution, see [`require_determined`](super::require_determined)).
///
/// One turn about a single axis traces a great circle, which passes through about 20–25 %
/// of the cells and does not determine an ellipsoid; turns about two or more axes reach
/// well beyond this.
pub const MIN_SPHERE_COVERAGE: f64 = 0.3;

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

/// Coefficients of `atan z ≈ z (a₁ + a₃z² + a₅z⁴ + a₇z⁶ + a₉z⁸)` on [0, 1]: Abramowitz &
/// Stegun (1964) 4.4.47, |error| ≤ 10⁻⁵ rad (1.15·10⁻⁵ with the coefficients as printed,
/// tested). Coarse, but only used to find the bin of a direction that lies well inside one
/// (see [`bin_if_clear`]).
const ATAN_COARSE: [f64; 5] = [
    0.999_866_0,
    -0.330_299_5,
    0.180_141_0,
    -0.085_133_0,
    0.020_835_1,
];

/// How close (a share of a fine bin) to a bin boundary the coarse direction of
/// [`coarse_turns`] may come before the direction is handed to [`turns`]: 0.005 of a 0.5° bin
/// is 4.4·10⁻⁵ rad, over three times the error of [`ATAN_COARSE`] (1.15·10⁻⁵ rad) plus that
/// of [`turns`] (under 10⁻⁷ rad, tested). Outside it both angles lie in the same bin. About
/// one direction in eighty falls inside it.
const NEAR_BOUNDARY_BINS: f64 = 0.005;

/// Direction of `(x, y)` as a share of a full turn (in about [0, 1]), through the coarse
/// [`ATAN_COARSE`]: the octant reduction of [`turns`] (the same operands, so the same rounding
/// of the ratio) with a shorter polynomial. Written like [`turns`], without branches, so that
/// the block loops vectorise it.
#[inline(always)]
pub(super) fn coarse_turns(y: f64, x: f64) -> f64 {
    use core::f64::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    let z = num / den;
    let z2 = z * z;
    let mut poly = ATAN_COARSE[4];
    for &a in ATAN_COARSE[..4].iter().rev() {
        poly = poly * z2 + a;
    }
    let first = z * poly;
    let mut a = if swap { FRAC_PI_2 - first } else { first };
    if x < 0.0 {
        a = PI - a;
    }
    if y < 0.0 {
        a = TAU - a;
    }
    // A product, not a quotient as in `turns`: the margin covers its rounding, and a
    // division is the slowest step of the loop.
    let t = a * (1.0 / TAU);
    if t >= 1.0 { 0.0 } else { t }
}

/// Fractional bits of the fixed-point coarse direction ([`coarse_fixed`]).
const FIXED_BITS: u32 = 10;

/// The coarse direction [`coarse_turns`] in fine bins, in fixed point with `FIXED_BITS`
/// bits below the bin (truncated: the scaling by a power of two is exact, so the integer
/// part is the bin and the fraction the position inside it). An integer result keeps the block loops in SIMD
/// registers; NaN gives 0, which [`bin_if_clear`] refuses.
#[inline(always)]
pub(super) fn coarse_fixed(y: f64, x: f64) -> u32 {
    (coarse_turns(y, x) * (GAP_BINS << FIXED_BITS) as f64) as u32
}

/// The fine bin of the fixed-point coarse direction `q` ([`coarse_fixed`]), or `None` if it
/// lies within [`NEAR_BOUNDARY_BINS`] of a bin boundary, where [`turns`] must decide.
#[inline(always)]
fn bin_if_clear(q: u32) -> Option<u32> {
    const ONE: u32 = 1 << FIXED_BITS;
    // Clear when the position inside the bin is in [6, 1018)/1024 ⊂ [0.005, 0.995]. The
    // direction is at most 2π (plus rounding), so a clear bin is below GAP_BINS; `min` only
    // proves it.
    const LOW: u32 = (NEAR_BOUNDARY_BINS * ONE as f64) as u32 + 1;
    let frac = q & (ONE - 1);
    (LOW..=ONE - LOW)
        .contains(&frac)
        .then_some((q >> FIXED_BITS).min(GAP_BINS as u32 - 1))
}

/// `fine_bin(turns(y, x))`, kept out of line: it is the rare path of the block loops, which
/// stay small without it.
#[inline(never)]
fn fine_bin_exact(y: f64, x: f64) -> u32 {
    fine_bin(turns(y, x))
}

/// The fine bin of the direction of `(x, y)` (finite, not both zero): exactly
/// `fine_bin(turns(y, x))`, through the coarse direction where that is far enough from a bin
/// boundary to decide ([`bin_if_clear`]), and through [`turns`] itself where it is not, so
/// that where a direction on or next to a boundary lands is decided by one rule everywhere.
#[inline]
pub(super) fn fine_bin_xy(y: f64, x: f64) -> u32 {
    bin_if_clear(coarse_fixed(y, x)).unwrap_or_else(|| fine_bin_exact(y, x))
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
        self.mark_bin(fine_bin_xy(d.y, d.x));
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

/// The equal-area cell of the direction `(x, y, z)` of norm `n` (see [`mark_sphere_cells`]),
/// in `0..SPHERE_CELLS`; an arbitrary cell for a zero or non-finite direction, which callers
/// skip. Written without branches so that block loops vectorise it.
#[inline(always)]
pub(crate) fn sphere_cell(x: f64, y: f64, z: f64, n: f64) -> u32 {
    let band = ((z / n).clamp(-1.0, 1.0) + 1.0) * 0.5 * SPHERE_BANDS as f64;
    // Both in [0, 8] (or NaN, for a row that is skipped), where `as u32` truncates like
    // `as usize`; u32 keeps the conversion in SIMD registers.
    let b = (band as u32).min(SPHERE_BANDS as u32 - 1);
    b * SPHERE_SECTORS as u32 + sector_16(y, x)
}

/// The sixteenth of a turn, counted counter-clockwise from +x, that `(x, y)` points into,
/// in `0..16` (a direction on a boundary goes to either side).
///
/// By comparisons instead of an arctangent, which was the largest cost of the 3-D quality
/// pass: within a quadrant, the angle `φ = atan(|y|/|x|)` has passed `k · 22.5°` when
/// `|y| ≥ tan(k · 22.5°) |x|`, with `tan 22.5° = √2 − 1` and `tan 67.5° = √2 + 1`; the
/// quadrant then mirrors or shifts that count.
#[inline(always)]
fn sector_16(y: f64, x: f64) -> u32 {
    const TAN_22_5: f64 = core::f64::consts::SQRT_2 - 1.0;
    const TAN_67_5: f64 = core::f64::consts::SQRT_2 + 1.0;
    const _: () = assert!(SPHERE_SECTORS == 16);
    let (ax, ay) = (x.abs(), y.abs());
    let q = u32::from(ay >= TAN_22_5 * ax) + u32::from(ay >= ax) + u32::from(ay >= TAN_67_5 * ax);
    match (x < 0.0, y < 0.0) {
        (false, false) => q,
        (true, false) => 7 - q,
        (true, true) => 8 + q,
        (false, true) => 15 - q,
    }
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
        cell[i] = sphere_cell(d[0][i], d[1][i], d[2][i], n[i]);
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
    // A block of points at a time (see `crate::numerics::blocks::BLOCK`).
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
        let d2 = d.norm_squared();
        // The common case first: a chord shorter than `min_chord` is skipped whatever the
        // scale, without the two norms the scale test needs.
        if d2 <= chord2 {
            continue;
        }
        let scale2 = p
            .norm_squared()
            .max(q.norm_squared())
            .max(f64::MIN_POSITIVE);
        if d2 <= chord2.max(1e-24 * scale2) {
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

/// How far beyond each true end of an arc its outermost reading may lie, in standard
/// deviations of the per-reading heading noise: 3. The ends of the arc a set of readings
/// covers are its two outermost directions, and noise scatters a few dozen readings near an
/// end by up to about 3σ (the largest of 30 normal deviates exceeds 3σ with probability
/// 4 %); at 7 % noise that widens a 150° arc to nearly 200°.
pub const ARC_END_NOISE_SIGMAS: f64 = 3.0;

/// Refuses a 2-D calibration whose data span less than `need_deg` of heading (see
/// [`MIN_ARC_DEG`]) with [`Error::InsufficientCoverage`]: the span of `coverage` less
/// [`ARC_END_NOISE_SIGMAS`] of the per-reading heading noise `noise_rad` at each end (0 when
/// unknown), so that noise cannot widen a short arc into an accepted one. The refusal
/// gives both the span and the allowance.
pub fn require_arc(coverage: &Coverage, noise_rad: f64, need_deg: f64) -> Result<()> {
    let noise_deg = if noise_rad.is_finite() && noise_rad > 0.0 {
        (2.0 * ARC_END_NOISE_SIGMAS * noise_rad).to_degrees()
    } else {
        0.0
    };
    let span_deg = coverage.span_rad().to_degrees();
    if need_deg > 0.0 && span_deg - noise_deg < need_deg {
        Err(Error::InsufficientCoverage {
            // Rounded so that a refusal never prints a net span equal to the one it needs.
            covered_deg: span_deg.floor(),
            noise_deg: noise_deg.ceil(),
            need_deg,
        })
    } else {
        Ok(())
    }
}

/// Refuses a 3-D calibration whose data fill less than `need` of the direction cells (see
/// [`MIN_SPHERE_COVERAGE`]) with [`Error::InsufficientCoverage`]; the degrees reported are
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
    calibrated_bins_2d(points, cal).coverage()
}

/// The coverage of [`calibrated_coverage_2d`] and the support of the same directions (each
/// 0.5° bin once; see the `support` module), from one pass.
pub(crate) fn calibrated_directions_2d(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
) -> (Coverage, Support2d) {
    let bins = calibrated_bins_2d(points, cal);
    (bins.coverage(), bins.support())
}

/// The direction bins of the calibrated readings of [`calibrated_coverage_2d`].
fn calibrated_bins_2d(points: &[Vector2<f64>], cal: &CompassCalibration2d) -> AngleBins {
    let mut bins = AngleBins::new();
    let (s, c) = (&cal.soft_iron, &cal.hard_iron);
    let calibrated = |x: f64, y: f64| {
        let (dx, dy) = (x - c.x, y - c.y);
        (
            s[(0, 0)] * dx + s[(0, 1)] * dy,
            s[(1, 0)] * dx + s[(1, 1)] * dy,
        )
    };
    // A block of points at a time (see `crate::numerics::blocks::BLOCK`): every direction first, in a loop
    // without branches that the compiler vectorises, then the marking, where the few
    // directions next to a bin boundary are computed again and binned by `turns`.
    let mut coarse = [0u32; BLOCK];
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
    bins
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate alloc;
    use alloc::vec::Vec;
    use nalgebra::Matrix2;
    use proptest::prelude::*;

    /// The bin of `(x, y)` by `turns` and `fine_bin`: the rule the coarse path must
    /// reproduce exactly.
    fn reference_bin(y: f64, x: f64) -> u32 {
        fine_bin(turns(y, x))
    }

    /// The fine bin of the exact angle (`atan2`), and how far that angle is from the nearest
    /// bin boundary, radians.
    fn atan2_bin(y: f64, x: f64) -> (u32, f64) {
        let bins = y.atan2(x).rem_euclid(TAU) / TAU * GAP_BINS as f64;
        let off = (bins - bins.round()).abs() * TAU / GAP_BINS as f64;
        (fine_bin(bins / GAP_BINS as f64), off)
    }

    /// The margin of `NEAR_BOUNDARY_BINS` rests on the error of the coarse polynomial.
    #[test]
    fn coarse_direction_is_within_its_error_bound() {
        let mut worst: f64 = 0.0;
        for k in 0..200_000 {
            let a = TAU * k as f64 / 200_000.0;
            let (y, x) = a.sin_cos();
            let mut d = (coarse_turns(y, x) - turns(y, x)).abs();
            d = d.min(1.0 - d);
            worst = worst.max(d * TAU);
        }
        // 1.15·10⁻⁵ rad measured (A&S quote 10⁻⁵ for the exact coefficients), plus the error
        // of `turns`: well inside the margin.
        assert!(worst < 1.2e-5, "{worst}");
        assert!(NEAR_BOUNDARY_BINS * TAU / GAP_BINS as f64 > 3.0 * worst);
    }

    /// A direction on a bin boundary, nudged by `ulps` units in the last place of each
    /// coordinate.
    fn boundary(k: u32, r: f64, ulps_x: i64, ulps_y: i64) -> (f64, f64) {
        let a = TAU * k as f64 / GAP_BINS as f64;
        let nudge = |v: f64, u: i64| {
            if v == 0.0 || u == 0 {
                v
            } else {
                f64::from_bits((v.to_bits() as i64 + u) as u64)
            }
        };
        (nudge(r * a.sin(), ulps_y), nudge(r * a.cos(), ulps_x))
    }

    fn direction() -> impl Strategy<Value = (f64, f64)> {
        prop_oneof![
            // Anywhere, at any scale.
            (-1e3f64..1e3, -1e3f64..1e3, -200i32..200)
                .prop_map(|(x, y, e)| (y * 2f64.powi(e), x * 2f64.powi(e))),
            // On a bin boundary, or a few ulps either side of one.
            (0u32..GAP_BINS as u32, 1e-6f64..1e6, -4i64..=4, -4i64..=4)
                .prop_map(|(k, r, ux, uy)| boundary(k, r, ux, uy)),
            // On the axes and diagonals, signed zeros included.
            (0usize..12, 1e-3f64..1e3).prop_map(|(o, r)| {
                [
                    (0.0, r),
                    (-0.0, r),
                    (r, 0.0),
                    (r, -0.0),
                    (0.0, -r),
                    (-0.0, -r),
                    (-r, 0.0),
                    (-r, -0.0),
                    (r, r),
                    (-r, r),
                    (-r, -r),
                    (r, -r),
                ][o]
            }),
        ]
        .prop_filter("not both zero", |(y, x)| *x != 0.0 || *y != 0.0)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        /// The coarse path with its fallback bins every direction exactly as `turns` does,
        /// on bin boundaries as well as between them; and as `atan2` does, wherever the
        /// exact angle is not within the error of `turns` of a boundary.
        #[test]
        fn bin_matches_turns_and_atan2((y, x) in direction()) {
            let bin = fine_bin_xy(y, x);
            prop_assert_eq!(bin, reference_bin(y, x), "({}, {})", x, y);
            prop_assert!(bin < GAP_BINS as u32);
            let (exact, off) = atan2_bin(y, x);
            if off > 1e-7 {
                prop_assert_eq!(bin, exact, "({}, {}) {} rad from a boundary", x, y, off);
            }
        }

        /// The sector of a direction by comparisons is the sixteenth of a turn `atan2`
        /// places it in, wherever the angle is not within rounding of a boundary.
        #[test]
        fn sector_matches_atan2((y, x) in direction()) {
            let t = y.atan2(x).rem_euclid(core::f64::consts::TAU) / core::f64::consts::TAU * 16.0;
            let s = sector_16(y, x);
            prop_assert!(s < 16);
            if (t - t.round()).abs() > 1e-9 {
                prop_assert_eq!(s, (t as u32).min(15), "({}, {}) at {} sixteenths", x, y, t);
            }
        }

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
