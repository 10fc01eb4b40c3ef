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

/// The cell of `h` as [`sphere_cell`] gives it with `n = |h|`, for one vector at a time:
/// `None` where `|h|` is zero or not finite.
///
/// The band is found without the square root and the division of `z/|h|`, which were most
/// of the time of an online 3-D push (the longest chain of dependent operations in it):
/// `|z|/|h|` is placed against the band edges ¼, ½ and ¾ by comparing `z²` with their
/// squares times `|h|²`, and the sign of `z` picks the hemisphere. Where that is not
/// certain — `z²` within 10⁻⁹·|h|² of an edge's, a negative `z` within 3·10⁻⁵·|h| of the
/// equator (where `z/|h| + 1` may round to 1, the upper band), or `|h|²` so small that its
/// terms may have lost precision — the cell is computed as [`sphere_cell`] does. Away from
/// those, the comparisons' rounding (a few units in 10¹⁶ of `|h|²`) cannot change a sign,
/// and the roundings of `z/|h|` (a few in 10¹⁶) cannot move it across an edge, so the
/// cell is the same for every `h` (and the tests compare both near every edge).
#[inline(always)]
pub(crate) fn sphere_cell_of(h: &Vector3<f64>) -> Option<u32> {
    /// Squares of the band edges in `|z|/|h|`, from the equator.
    const EDGES_SQ: [f64; 3] = [1.0 / 16.0, 0.25, 9.0 / 16.0];
    /// Relative distance from an edge, in `z²/|h|²`, below which the band is computed.
    const MARGIN: f64 = 1e-9;
    /// Smallest `|h|²` compared: its terms stay normal numbers or negligible.
    const SMALLEST: f64 = 1e-250;
    const _: () = assert!(SPHERE_BANDS == 8);
    // `|h| > 0` and finite exactly when `|h|²` is, as `|h|` is its square root.
    let ss = h.norm_squared();
    if !(ss > 0.0 && ss.is_finite()) {
        return None;
    }
    let z2 = h.z * h.z;
    let mut near = ss < SMALLEST || (h.z < 0.0 && z2 <= MARGIN * ss);
    let mut from_equator = 0;
    for e in EDGES_SQ {
        let d = z2 - e * ss;
        near |= d.abs() <= MARGIN * ss;
        from_equator += u32::from(d > 0.0);
    }
    if near {
        return Some(sphere_cell(h.x, h.y, h.z, ss.sqrt()));
    }
    // −0 goes up, as `−0/|h| + 1 = 1`.
    let band = if h.z >= 0.0 {
        4 + from_equator
    } else {
        3 - from_equator
    };
    Some(band * SPHERE_SECTORS as u32 + sector_16(h.y, h.x))
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

    /// [`sphere_cell`] with the norm, as the online ellipsoid sorted its readings.
    fn exact(h: &Vector3<f64>) -> Option<u32> {
        let n = h.norm();
        (n > 0.0 && n.is_finite()).then(|| sphere_cell(h.x, h.y, h.z, n))
    }

    /// `z` moved by `k` units in the last place.
    fn ulps(z: f64, k: i64) -> f64 {
        if z == 0.0 {
            return f64::from_bits(k.unsigned_abs()) * (k.signum() as f64);
        }
        f64::from_bits((z.to_bits() as i64 + k * z.signum() as i64) as u64)
    }

    /// The cell without the square root and the division is the cell, at and around every
    /// band edge (within a few hundred units in the last place of `z`, on both sides), at
    /// the equator and the poles, at tiny and huge norms, and for zero and non-finite
    /// vectors.
    #[test]
    fn cell_by_comparisons_is_the_cell_near_every_edge() {
        let mut checked = 0;
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        for scale in [1e-200, 1e-155, 1e-3, 1.0, 47.6, 1e150, 1e200] {
            for _ in 0..200 {
                let phi = uniform() * core::f64::consts::TAU;
                let rho = scale * (0.1 + uniform());
                let (x, y) = (rho * phi.cos(), rho * phi.sin());
                // z with z/|h| at each band edge, the equator and the poles' neighbourhood.
                for w in [-0.75f64, -0.5, -0.25, 0.0, 0.25, 0.5, 0.75, 0.999_999] {
                    let z0 = w * rho / (1.0 - w * w).sqrt();
                    for k in (-300..=300).step_by(7).chain(-3..=3) {
                        let h = Vector3::new(x, y, ulps(z0, k));
                        assert_eq!(sphere_cell_of(&h), exact(&h), "{h:?}");
                        checked += 1;
                    }
                }
                let h = Vector3::new(x, y, scale * (2.0 * uniform() - 1.0));
                assert_eq!(sphere_cell_of(&h), exact(&h), "{h:?}");
            }
        }
        for h in [
            Vector3::zeros(),
            Vector3::new(0.0, 0.0, -0.0),
            Vector3::new(1.0, 0.0, -0.0),
            Vector3::new(0.0, 0.0, -5e-324),
            Vector3::new(1e-320, 0.0, -1e-320),
            Vector3::new(0.0, 0.0, 1.0),
            Vector3::new(0.0, 0.0, -1.0),
            Vector3::new(1e300, 1e300, 1e300),
            Vector3::new(f64::NAN, 0.0, 1.0),
            Vector3::new(0.0, f64::INFINITY, 1.0),
        ] {
            assert_eq!(sphere_cell_of(&h), exact(&h), "{h:?}");
        }
        assert!(checked > 1_000_000);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        /// The cell by comparisons is the cell for any vector.
        #[test]
        fn cell_by_comparisons_is_the_cell(
            x in -1e3f64..1e3,
            y in -1e3f64..1e3,
            z in -1e3f64..1e3,
        ) {
            let h = Vector3::new(x, y, z);
            prop_assert_eq!(sphere_cell_of(&h), exact(&h));
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
    }
}
