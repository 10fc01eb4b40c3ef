//! Direction bins: the direction of a 2-D vector as a share of a full turn ([`turns`]) and
//! its fine (0.5°) bin, found through a coarse arctangent wherever that is far enough from a
//! bin boundary to decide, and through [`turns`] where it is not.

use core::f64::consts::TAU;

use truenorth_core::Real;

use super::support::GAP_BINS;

/// Direction of `(x, y)` (not both zero) as a share of a full turn in [0, 1), counted
/// counter-clockwise from +x.
///
/// Bins only need the angle to a small fraction of a bin, and `atan2` was the largest cost
/// of the whole quality pass, so this uses the minimax polynomial of Abramowitz & Stegun
/// (1964) 4.4.49 for `atan z` on [0, 1] (|error| ≤ 2·10⁻⁸ rad) with an octant reduction.
#[inline]
pub(crate) fn turns(y: f64, x: f64) -> f64 {
    turns_in(y, x)
}

/// [`turns`] in the float type `T` (the same operations, so the same bits for `f64`), for
/// the per-sample paths that run in `f32`.
#[inline]
pub(crate) fn turns_in<T: Real>(y: T, x: T) -> T {
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
    let mut poly = T::of(A[7]);
    for &a in A[..7].iter().rev() {
        poly = poly * z2 + T::of(a);
    }
    let first = z + z * z2 * poly;
    let mut a = if swap {
        T::of(FRAC_PI_2) - first
    } else {
        first
    };
    if x < T::zero() {
        a = T::of(PI) - a;
    }
    if y < T::zero() {
        a = T::of(TAU) - a;
    }
    let t = a / T::of(TAU);
    if t >= T::one() { T::zero() } else { t }
}

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
pub(super) fn bin_if_clear(q: u32) -> Option<u32> {
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
pub(super) fn fine_bin_exact(y: f64, x: f64) -> u32 {
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

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The bin of `(x, y)` by `turns` and `fine_bin`: the rule the coarse path must
    /// reproduce exactly.
    pub(in crate::quality) fn reference_bin(y: f64, x: f64) -> u32 {
        fine_bin(turns(y, x))
    }

    /// The fine bin of the exact angle (`atan2`), and how far that angle is from the nearest
    /// bin boundary, radians.
    fn atan2_bin(y: f64, x: f64) -> (u32, f64) {
        let bins = y.atan2(x).rem_euclid(TAU) / TAU * GAP_BINS as f64;
        let off = (bins - bins.round()).abs() * TAU / GAP_BINS as f64;
        (fine_bin(bins / GAP_BINS as f64), off)
    }

    /// The largest distance (radians, across the wrap) of [`coarse_turns`] from [`turns`]
    /// over `steps` evenly spaced unit directions.
    pub(in crate::quality) fn worst_coarse_error_rad(steps: u32) -> f64 {
        let mut worst: f64 = 0.0;
        for k in 0..steps {
            let a = TAU * f64::from(k) / f64::from(steps);
            let (y, x) = a.sin_cos();
            let mut d = (coarse_turns(y, x) - turns(y, x)).abs();
            d = d.min(1.0 - d);
            worst = worst.max(d * TAU);
        }
        worst
    }

    /// The margin of `NEAR_BOUNDARY_BINS` rests on the error of the coarse polynomial.
    #[test]
    fn coarse_direction_is_within_its_error_bound() {
        let worst = worst_coarse_error_rad(200_000);
        // 1.15·10⁻⁵ rad measured (A&S quote 10⁻⁵ for the exact coefficients), plus the error
        // of `turns`: well inside the margin.
        assert!(worst < 1.2e-5, "{worst}");
        assert!(NEAR_BOUNDARY_BINS * TAU / GAP_BINS as f64 > 3.0 * worst);
    }

    /// A direction on a bin boundary, nudged by `ulps` units in the last place of each
    /// coordinate.
    pub(in crate::quality) fn boundary(k: u32, r: f64, ulps_x: i64, ulps_y: i64) -> (f64, f64) {
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

    /// Directions anywhere, on bin boundaries (and a few ulps beside them), and on the axes
    /// and diagonals.
    pub(in crate::quality) fn direction() -> impl Strategy<Value = (f64, f64)> {
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
    }
}
