//! Coverage of the sphere: the share of equal-area direction cells the readings fill, seen
//! from a centre.

use nalgebra::Vector3;
use truenorth_core::{Error, Result};

use crate::numerics::blocks::BLOCK;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Equal-area latitude bands of the direction cells on the sphere (uniform in `sin(lat)`,
/// so every band has the same area).
pub const SPHERE_BANDS: usize = 8;

/// Longitude sectors per band of the direction cells on the sphere.
pub const SPHERE_SECTORS: usize = 16;

/// Number of equal-area direction cells on the sphere (`SPHERE_BANDS × SPHERE_SECTORS`,
/// each about 320 square degrees, roughly 18° × 18° at the equator).
pub const SPHERE_CELLS: usize = SPHERE_BANDS * SPHERE_SECTORS;

/// The share of the direction cells on the sphere ([`SPHERE_CELLS`]) below which the online
/// ellipsoid calibrator explains a failed fit as too little of the sphere seen (no
/// calibrator refuses a successful fit on it: whether the orientations determine a 3-D
/// calibration is judged by their dilution, see [`require_determined`](super::require_determined)).
///
/// One turn about a single axis traces a great circle, which passes through about 20–25 %
/// of the cells and does not determine an ellipsoid; turns about two or more axes reach
/// well beyond this.
pub const MIN_SPHERE_COVERAGE: f64 = 0.3;

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

#[cfg(test)]
mod tests {
    use super::super::direction_bins::tests::direction;
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

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
    }
}
