//! Direction sectors: which of `n` equal sectors of a full turn (counted counter-clockwise
//! from +x) the direction of a 2-D vector lies in, exactly as `atan2` places it, found
//! through the coarse arctangent of the fine direction bins wherever that is far enough
//! from a sector boundary to decide, and through `atan2` itself where it is not.

use core::f64::consts::TAU;

use truenorth_core::wrap_two_pi;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

use super::direction_bins::coarse_turns;

/// How close (radians) to a sector boundary the coarse direction of [`coarse_turns`] may
/// come before the direction is handed to `atan2`.
///
/// Both paths stand at a distance from the exact direction θ of the vector (the angle of
/// the two `f64` coordinates as they are):
/// - the coarse one by the error of the Abramowitz & Stegun (1964) 4.4.47 polynomial,
///   1.15·10⁻⁵ rad (tested below and in the fine bins), plus the rounding of its octant
///   reduction and of the products by 1/2π and by `n`, a few ulps of 2π, under 10⁻¹⁴ rad;
/// - [`sector_of_angle`] by the error of `atan2` (about one ulp of π), the rounding of the
///   wrap into [0, 2π) (half an ulp of 2π), the difference between `TAU` and 2π (under 10⁻¹⁵
///   rad), and the rounding of the division by `TAU` and the product by `n` (half an ulp
///   each, relative): together under 10⁻¹⁴ rad.
///
/// A coarse direction farther than 1.15·10⁻⁵ + 2·10⁻¹⁴ rad from every boundary therefore
/// has θ, and the direction `atan2` gives, in its own sector; the margin takes three times
/// the polynomial's error (the fine bins take the same factor), so a worst case the tests
/// sampled past is still covered. Such a direction is not at the wrap either: it lies
/// clear of 0 and 2π, so the wrap of `atan2`'s (−π, 0) into (π, 2π), its rounding to
/// exactly 2π (which [`wrap_two_pi`] returns as 0) and the `min(n − 1)` that catches a
/// product rounded up to `n` do not apply to it; those directions take the exact path.
/// About one direction in 600 falls inside the margin at 128 sectors (2 · 4·10⁻⁵ · 128/2π).
const NEAR_BOUNDARY_RAD: f64 = 4.0e-5;

/// [`NEAR_BOUNDARY_RAD`] as a share of a full turn, the unit of [`coarse_turns`].
const NEAR_BOUNDARY_TURNS: f64 = NEAR_BOUNDARY_RAD / TAU;

/// The sector among `n` (≥ 1) of the angle `angle_rad` (finite, any turn):
/// `⌊wrap(angle)/2π · n⌋`, capped at `n − 1` for the product that rounds up to `n`. This is
/// the rule [`sector`] reproduces.
#[inline]
fn sector_of_angle(angle_rad: f64, n: usize) -> usize {
    ((wrap_two_pi(angle_rad) / TAU * n as f64) as usize).min(n.saturating_sub(1))
}

/// The sector among `n` of the direction of `(x, y)` from the coarse direction alone, or
/// `None` if that lies within [`NEAR_BOUNDARY_RAD`] of a sector boundary (the wrap at
/// 0 = 2π included), where only `atan2` can decide.
#[inline(always)]
fn sector_if_clear(y: f64, x: f64, n: usize) -> Option<usize> {
    let sectors = n as f64;
    // In [0, n]: `coarse_turns` is in [0, 1]. Truncation is its floor; it goes through `u32`
    // because x86-64 converts between doubles and `u64` in a dozen instructions or more
    // each way and `u32` in one or two. Past 2³² it saturates, `inside` is then 1 or more
    // and `atan2` decides. Subtracting the integer part of a double is exact.
    let u = coarse_turns(y, x) * sectors;
    let k = u as u32;
    let inside = u - f64::from(k);
    let margin = NEAR_BOUNDARY_TURNS * sectors;
    // A clear `u` is below n − margin, so `k` < n; `min` only proves it.
    (inside > margin && inside < 1.0 - margin).then_some((k as usize).min(n.saturating_sub(1)))
}

/// The sector by `atan2`, kept out of line: it is the rare path.
#[inline(never)]
fn sector_exact(y: f64, x: f64, n: usize) -> usize {
    sector_of_angle(y.atan2(x), n)
}

/// The sector among `n` (≥ 1) of the direction of `(x, y)` (finite, not both zero):
/// exactly `sector_of_angle(y.atan2(x), n)`, bit for bit, but through the coarse direction
/// where that is clear of a sector boundary ([`NEAR_BOUNDARY_RAD`]), since `atan2` was a
/// fifth of the time of the binned and turn calibrators, which only need the sector.
#[inline]
pub(crate) fn sector(y: f64, x: f64, n: usize) -> usize {
    sector_if_clear(y, x, n).unwrap_or_else(|| sector_exact(y, x, n))
}

/// How far (radians) inside the remembered sector of a [`SectorHint`] a direction must
/// lie, by its cross products with the sector's boundary directions, to take that sector
/// without [`sector`].
///
/// The cross product of a boundary direction `b` (unit, `b.x·y − b.y·x`) with `(x, y)` is
/// `|d| sin(θ − θ_b)`. As computed it is off by the error of `b` (its angle `2πk/n` rounded,
/// a few ulps of 2π, and its sine and cosine rounded, under 4·10⁻¹⁵ together) and the
/// rounding of two products and a difference, so by under 4·10⁻¹⁵ · (|x| + |y|) (products
/// that underflow add at most 3·2⁻¹⁰⁷⁵, nothing beside the least `|x| + |y|` admitted).
/// As `|d| ≤ |x| + |y|`, a cross product above `HINT_MARGIN_RAD · (|x| + |y|)` puts θ past
/// the boundary by more than `HINT_MARGIN_RAD − 4·10⁻¹⁵` rad (`asin v ≥ v`); past both
/// boundaries of a sector narrower than π (n ≥ 3) it lies inside, farther from both than
/// the 10⁻¹⁴ rad within which [`NEAR_BOUNDARY_RAD`] shows `atan2` and the exact rule can
/// move a direction to another sector: `sector_of_angle(atan2)` gives the remembered one.
/// Ten thousand times that, still a negligible share of any sector.
const HINT_MARGIN_RAD: f64 = 1.0e-10;

/// Least and greatest `|x| + |y|` a [`SectorHint`] decides: clear of subnormal products and
/// of overflow in the sums.
const HINT_SCALE: (f64, f64) = (1.0e-280, 1.0e280);

/// Most sectors a [`SectorHint`] keeps the boundary directions of (the binned ellipse's
/// most bins); more are placed by [`sector`] alone.
const HINT_MAX_SECTORS: usize = 128;

/// The sector of the last direction of a stream of directions, and the boundary
/// directions of all `n` sectors, so that the next direction, which in a dense recording
/// is almost always in the same sector or the next one, is placed by cross products with
/// them instead of the arctangent of [`sector`]: exactly the same sector (see
/// [`HINT_MARGIN_RAD`]), found faster.
///
/// A cache: it never changes a result, so every two hints compare equal (a calibrator's
/// equality is that of what it has learned).
#[derive(Debug, Clone)]
pub(crate) struct SectorHint {
    /// The sector count the boundary directions are for; 0 before any.
    n: usize,
    /// The remembered sector (below `n`).
    k: usize,
    /// `(cos, sin)` of `2πj/n` for `j` in `0..=n`.
    boundaries: [(f64, f64); HINT_MAX_SECTORS + 1],
}

impl PartialEq for SectorHint {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl SectorHint {
    /// No sector remembered.
    pub(crate) const fn new() -> Self {
        Self {
            n: 0,
            k: 0,
            boundaries: [(0.0, 0.0); HINT_MAX_SECTORS + 1],
        }
    }

    /// [`sector`] of `(x, y)` among `n`, bit for bit; remembers it for the next call.
    #[inline(always)]
    pub(crate) fn sector(&mut self, y: f64, x: f64, n: usize) -> usize {
        if self.n == n && self.inside(self.k, y, x) {
            self.k
        } else {
            self.place(y, x, n)
        }
    }

    /// Whether `(x, y)` lies inside sector `k` (below `self.n`) by [`HINT_MARGIN_RAD`].
    #[inline(always)]
    fn inside(&self, k: usize, y: f64, x: f64) -> bool {
        let (lo, hi) = (self.boundaries[k], self.boundaries[k + 1]);
        let scale = x.abs() + y.abs();
        let margin = HINT_MARGIN_RAD * scale;
        let past_lo = lo.0 * y - lo.1 * x;
        let before_hi = hi.1 * x - hi.0 * y;
        (past_lo > margin) & (before_hi > margin) & (scale > HINT_SCALE.0) & (scale < HINT_SCALE.1)
    }

    /// The sector when it is not the remembered one: one of its neighbours, by their
    /// boundary directions, or else by [`sector`]; remembered (for 3 to
    /// [`HINT_MAX_SECTORS`] sectors, which are narrower than π and whose boundary
    /// directions it keeps, taken here when `n` changes).
    #[inline(never)]
    fn place(&mut self, y: f64, x: f64, n: usize) -> usize {
        if !(3..=HINT_MAX_SECTORS).contains(&n) {
            return sector(y, x, n);
        }
        if self.n != n {
            for (j, b) in self.boundaries[..=n].iter_mut().enumerate() {
                let (sin, cos) = (TAU * j as f64 / n as f64).sin_cos();
                *b = (cos, sin);
            }
            self.n = n;
        } else {
            for k in [(self.k + 1) % n, (self.k + n - 1) % n] {
                if self.inside(k, y, x) {
                    self.k = k;
                    return k;
                }
            }
        }
        self.k = sector(y, x, n);
        self.k
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::direction_bins::tests::worst_coarse_error_rad;
    use crate::seed::binned::MAX_BINS;
    use proptest::prelude::*;

    /// Every sector count in use (the binned ellipse's even 8..=`MAX_BINS`, the direction
    /// slots' 72) and all others up to `MAX_BINS`.
    const COUNTS: core::ops::RangeInclusive<usize> = 1..=MAX_BINS;

    /// The rule as the calibrators wrote it before [`sector`]: what it must reproduce.
    fn reference(y: f64, x: f64, n: usize) -> usize {
        ((wrap_two_pi(y.atan2(x)) / TAU * n as f64) as usize).min(n - 1)
    }

    /// Asserts [`sector`] against [`reference`] for every count.
    fn check_all_counts(y: f64, x: f64) -> Result<(), TestCaseError> {
        for n in COUNTS {
            prop_assert_eq!(
                sector(y, x, n),
                reference(y, x, n),
                "({:e}, {:e}), n = {}",
                x,
                y,
                n
            );
        }
        Ok(())
    }

    /// `v` moved by `ulps` units in the last place (away from or towards zero by the sign
    /// of `ulps`, through the bits); zero stays zero.
    fn nudge(v: f64, ulps: i64) -> f64 {
        if v == 0.0 {
            v
        } else {
            f64::from_bits((v.to_bits() as i64 + ulps) as u64)
        }
    }

    /// The margin rests on the coarse polynomial's error, measured here as in the fine
    /// bins, on a finer grid.
    #[test]
    fn margin_covers_the_coarse_error_three_times() {
        let worst = worst_coarse_error_rad(1_000_000);
        assert!(worst < 1.2e-5, "{worst}");
        assert!(NEAR_BOUNDARY_RAD > 3.0 * worst, "{worst}");
    }

    /// Every boundary of every count, at radii from 10⁻³⁰⁰ to 10³⁰⁰, on it and up to three
    /// ulps off it in each coordinate: where `atan2`'s rounding decides the sector.
    #[test]
    fn matches_atan2_on_and_beside_every_boundary() {
        for n in COUNTS {
            for k in 0..n {
                let (sin, cos) = (TAU * k as f64 / n as f64).sin_cos();
                for r in [1e-300, 3e-7, 1.0, 7e5, 1e300] {
                    for ux in -3..=3 {
                        for uy in -3..=3 {
                            let (y, x) = (nudge(r * sin, uy), nudge(r * cos, ux));
                            assert_eq!(
                                sector(y, x, n),
                                reference(y, x, n),
                                "({x:e}, {y:e}), n = {n}, k = {k}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// The axes with both signs of zero, ±π (just above and below the negative x axis),
    /// the wrap at 0 = 2π (just above and below the positive x axis), and the extremes of
    /// the `f64` range.
    #[test]
    fn matches_atan2_on_the_axes_and_at_the_wrap() {
        let tiny = f64::from_bits(1); // the least subnormal
        let mut cases = Vec::new();
        for r in [tiny, 1e-300, 1.0, 1e300, f64::MAX] {
            for z in [0.0, -0.0, tiny, -tiny, 1e-300, -1e-300, 1e-17, -1e-17] {
                cases.extend([(z, r), (z, -r), (r, z), (-r, z)]);
            }
        }
        for (y, x) in cases {
            check_all_counts(y, x).unwrap();
        }
    }

    /// Sectors are decided by the coarse path for all but a few directions (else the
    /// comparisons above would hold trivially, and nothing would be saved).
    #[test]
    fn the_coarse_path_decides_almost_every_direction() {
        let mut exact = 0;
        let total = 100_000;
        for k in 0..total {
            let (y, x) = (TAU * (k as f64 + 0.3) / total as f64).sin_cos();
            exact += usize::from(sector_if_clear(y, x, MAX_BINS).is_none());
        }
        // 2 · 4·10⁻⁵ rad of every 2π/128 (0.16 %), and the directions at the wrap.
        assert!(exact > 0 && exact < total / 400, "{exact} of {total}");
    }

    /// A hint that remembers sector `k` of `n` (placed by a direction at its middle).
    fn hint_at(k: usize, n: usize) -> SectorHint {
        let mut hint = SectorHint::new();
        let (y, x) = (TAU * (k as f64 + 0.5) / n as f64).sin_cos();
        assert_eq!(hint.sector(y, x, n), k);
        hint
    }

    /// The hinted sector on and beside every boundary of every count, as in
    /// `matches_atan2_on_and_beside_every_boundary`, with the hint fresh or remembering
    /// either sector of the boundary, the one past either, or the opposite one: every path
    /// (the remembered sector, a neighbour, the full rule) meets the boundaries.
    #[test]
    fn the_hint_matches_atan2_on_and_beside_every_boundary() {
        for n in COUNTS {
            for k in 0..n {
                let (sin, cos) = (TAU * k as f64 / n as f64).sin_cos();
                let remembered = [
                    k,
                    (k + 1) % n,
                    (k + n - 1) % n,
                    (k + 2 * n - 2) % n,
                    (k + n / 2) % n,
                ];
                for r in [1e-300, 3e-7, 1.0, 7e5, 1e300] {
                    for ux in -3..=3 {
                        for uy in -3..=3 {
                            let (y, x) = (nudge(r * sin, uy), nudge(r * cos, ux));
                            let want = reference(y, x, n);
                            assert_eq!(
                                SectorHint::new().sector(y, x, n),
                                want,
                                "({x:e}, {y:e}), n = {n}"
                            );
                            for at in remembered {
                                let mut hint = hint_at(at, n);
                                assert_eq!(
                                    hint.sector(y, x, n),
                                    want,
                                    "({x:e}, {y:e}), n = {n}, k = {k}, remembered {at}"
                                );
                                // Remembered now: the same again.
                                assert_eq!(hint.sector(y, x, n), want);
                            }
                        }
                    }
                }
            }
        }
    }

    /// A hint kept for one count and then asked about another takes the other's
    /// boundaries.
    #[test]
    fn the_hint_follows_a_change_of_count() {
        let mut hint = hint_at(3, 64);
        for (n, a) in [
            (72, 1.0),
            (8, 2.5),
            (64, 4.0),
            (2, 1.0),
            (200, 6.0),
            (64, 4.0),
        ] {
            let (y, x) = f64::sin_cos(a);
            assert_eq!(hint.sector(y, x, n), reference(y, x, n), "n = {n}");
        }
    }

    /// On a dense turn (with noise across the sector boundaries) the remembered sector or
    /// a neighbour places almost every direction, so the hint saves the arctangent.
    #[test]
    fn the_hint_places_a_dense_turn_by_cross_products() {
        let n = 72;
        let mut hint = SectorHint::new();
        let (mut full, total) = (0, 100_000);
        for i in 0..total {
            let noise = 0.01 * ((i as f64 * 7.3).sin());
            let (y, x) = (TAU * i as f64 / total as f64 + noise).sin_cos();
            let (before_n, before_k) = (hint.n, hint.k);
            let near = before_n == n
                && [before_k, (before_k + 1) % n, (before_k + n - 1) % n]
                    .iter()
                    .any(|&k| hint.inside(k, y, x));
            full += usize::from(!near);
            assert_eq!(hint.sector(y, x, n), reference(y, x, n));
        }
        assert!(full < 10, "{full} of {total} by the full rule");
    }

    /// A magnitude 10^e, e in [−300, 300], with either sign.
    fn magnitude() -> impl Strategy<Value = f64> {
        (-300.0f64..300.0, any::<bool>()).prop_map(|(e, neg)| {
            let m = 10f64.powf(e);
            if neg { -m } else { m }
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4_000))]

        /// Directions anywhere, the coordinates of independent random magnitudes.
        #[test]
        fn matches_atan2_for_independent_coordinates(x in magnitude(), y in magnitude()) {
            check_all_counts(y, x)?;
        }

        /// Directions anywhere at one random magnitude.
        #[test]
        fn matches_atan2_at_any_scale(a in 0.0f64..TAU, r in magnitude()) {
            let (sin, cos) = a.sin_cos();
            check_all_counts(r * sin, r * cos)?;
        }

        /// A stream of directions a small random step apart (at one random scale), each
        /// hinted by the one before, for a random count.
        #[test]
        fn the_hint_matches_atan2_along_a_random_walk(
            n in 1usize..=MAX_BINS,
            start in 0.0f64..TAU,
            steps in proptest::collection::vec(-0.2f64..0.2, 1..200),
            r in magnitude(),
        ) {
            let mut hint = SectorHint::new();
            let mut a = start;
            for step in steps {
                a += step;
                let (sin, cos) = a.sin_cos();
                let (y, x) = (r * sin, r * cos);
                prop_assert_eq!(hint.sector(y, x, n), reference(y, x, n), "({:e}, {:e}), n = {}", x, y, n);
            }
        }

        /// Directions near a boundary of every count, within a few margins of it: where a
        /// margin too narrow for the coarse error would let the coarse path decide wrongly.
        #[test]
        fn matches_atan2_near_a_boundary(
            f in 0.0f64..1.0,
            off_rad in -1e-4f64..1e-4,
            r in magnitude(),
        ) {
            for n in COUNTS {
                let k = (f * n as f64) as usize;
                let (sin, cos) = (TAU * k as f64 / n as f64 + off_rad).sin_cos();
                let (y, x) = (r * sin, r * cos);
                prop_assert_eq!(sector(y, x, n), reference(y, x, n), "({:e}, {:e}), n = {}", x, y, n);
            }
        }
    }
}
