//! Whether one direction has turned at least a given angle from another, exactly as the
//! difference of their `atan2` decides it, found through the coarse arctangent of the
//! fine direction bins wherever that is far enough from the threshold to decide.

use core::f64::consts::TAU;

use nalgebra::Vector2;
use truenorth_core::angle_diff;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

use super::direction_bins::coarse_turns;

/// How close (radians) to the threshold the coarse angle between the directions may come
/// before `atan2` decides.
///
/// The coarse angle is the circular distance between the two coarse directions of
/// [`coarse_turns`], each within 1.15·10⁻⁵ rad of the exact direction (Abramowitz & Stegun
/// (1964) 4.4.47, tested with the fine bins) plus a few ulps of 2π; the circular distance
/// moves by no more than its arguments, so it lies within 2.4·10⁻⁵ rad of the exact angle
/// between the directions. The exact rule, `|angle_diff(atan2 a, atan2 b)|`, lies within a
/// few ulps of π of it too (two `atan2` and a difference, wrapped). A coarse angle farther
/// than both from the threshold is on the same side of it as the exact rule's; the margin
/// takes four times that.
const NEAR_THRESHOLD_RAD: f64 = 1.0e-4;

/// A direction as the exact rule and the coarse test take it: `atan2` (radians) and the
/// coarse direction (a share of a full turn).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Direction {
    rad: f64,
    turns: f64,
}

impl Direction {
    /// The direction of `v`.
    pub(crate) fn of(v: &Vector2<f64>) -> Self {
        Self {
            rad: v.y.atan2(v.x),
            turns: coarse_turns(v.y, v.x),
        }
    }
}

/// Whether the direction of `a` lies at least `min_rad` (in [0, π]) from `from`: exactly
/// `angle_diff(a.y.atan2(a.x), from_rad).abs() >= min_rad`, bit for bit, but through the
/// coarse directions where their angle is clear of `min_rad` ([`NEAR_THRESHOLD_RAD`]), since
/// the `atan2` was a fifth of the merit circle's push. A zero or non-finite vector makes
/// the coarse angle NaN, which is clear of nothing: the exact rule decides it.
#[inline]
pub(crate) fn turned_at_least(a: &Vector2<f64>, from: &Direction, min_rad: f64) -> bool {
    let mut d = coarse_turns(a.y, a.x) - from.turns;
    // Both in [0, 1]: one turn at most brings the difference into [−½, ½].
    if d > 0.5 {
        d -= 1.0;
    } else if d < -0.5 {
        d += 1.0;
    }
    let coarse_rad = d.abs() * TAU;
    if coarse_rad >= min_rad + NEAR_THRESHOLD_RAD {
        true
    } else if coarse_rad < min_rad - NEAR_THRESHOLD_RAD {
        false
    } else {
        turned_exactly(a, from.rad, min_rad)
    }
}

/// The exact rule of [`turned_at_least`], kept out of line: it is the rare path.
#[inline(never)]
fn turned_exactly(a: &Vector2<f64>, from_rad: f64, min_rad: f64) -> bool {
    angle_diff(a.y.atan2(a.x), from_rad).abs() >= min_rad
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;
    use proptest::prelude::*;

    /// The rule as the merit circle wrote it: what [`turned_at_least`] must reproduce.
    fn reference(a: &Vector2<f64>, b: &Vector2<f64>, min_rad: f64) -> bool {
        angle_diff(a.y.atan2(a.x), b.y.atan2(b.x)).abs() >= min_rad
    }

    /// A magnitude 10^e, e in [−300, 300].
    fn magnitude() -> impl Strategy<Value = f64> {
        -300.0f64..300.0
    }

    /// The margin rests on the coarse polynomial's error (measured with the fine bins).
    #[test]
    fn margin_covers_twice_the_coarse_error() {
        let worst = crate::quality::direction_bins::tests::worst_coarse_error_rad(200_000);
        assert!(NEAR_THRESHOLD_RAD > 4.0 * 2.0 * worst, "{worst}");
    }

    /// On the threshold and a few ulps of the angle either side of it, at the wrap, and
    /// with zero or infinite vectors.
    #[test]
    fn matches_atan2_at_the_threshold_and_the_edges() {
        let thresholds = [0.0, 1e-9, 0.3, 30f64.to_radians(), 1.0, PI - 1e-9, PI];
        for b_rad in [0.0, 1e-12, 0.7, PI / 2.0, PI, -PI + 1e-12, -2.0, TAU - 1e-9] {
            for r in [1e-300, 1.0, 1e300] {
                let b = Vector2::new(b_rad.cos(), b_rad.sin()) * r;
                let from = Direction::of(&b);
                for min_rad in thresholds {
                    for off in [-3e-4, -1e-4, -1e-9, -1e-15, 0.0, 1e-15, 1e-9, 1e-4, 3e-4] {
                        for sign in [1.0, -1.0] {
                            let t = b_rad + sign * (min_rad + off);
                            let a = Vector2::new(t.cos(), t.sin()) * r;
                            assert_eq!(
                                turned_at_least(&a, &from, min_rad),
                                reference(&a, &b, min_rad),
                                "{a:?} from {b:?}, min {min_rad}"
                            );
                        }
                    }
                    for a in [
                        Vector2::zeros(),
                        Vector2::new(f64::INFINITY, 1.0),
                        Vector2::new(-0.0, 0.0),
                    ] {
                        assert_eq!(
                            turned_at_least(&a, &from, min_rad),
                            reference(&a, &b, min_rad)
                        );
                    }
                }
            }
        }
    }

    /// Almost every turn a dense turn shows is decided without `atan2`.
    #[test]
    fn the_coarse_angle_decides_almost_every_turn() {
        let from = Direction::of(&Vector2::new(1.0, 0.0));
        let min_rad = 30f64.to_radians();
        let total = 100_000;
        let exact = (0..total)
            .filter(|&k| {
                let t = TAU * (k as f64 + 0.3) / total as f64;
                let d = coarse_turns(t.sin(), t.cos()) - from.turns;
                let d = d - d.round();
                (d.abs() * TAU - min_rad).abs() < NEAR_THRESHOLD_RAD
            })
            .count();
        assert!(exact > 0 && exact < total / 1000, "{exact} of {total}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        /// Any two directions at independent scales and any threshold.
        #[test]
        fn matches_atan2_anywhere(
            ta in 0.0f64..TAU, tb in 0.0f64..TAU, ea in magnitude(), eb in magnitude(),
            min_rad in 0.0f64..=PI,
        ) {
            let a = Vector2::new(ta.cos(), ta.sin()) * 10f64.powf(ea);
            let b = Vector2::new(tb.cos(), tb.sin()) * 10f64.powf(eb);
            prop_assert_eq!(turned_at_least(&a, &Direction::of(&b), min_rad), reference(&a, &b, min_rad));
        }

        /// Two directions within a few margins of the threshold apart.
        #[test]
        fn matches_atan2_near_the_threshold(
            tb in 0.0f64..TAU, off in -3e-4f64..3e-4, min_rad in 0.0f64..=PI,
            sign in prop_oneof![Just(1.0), Just(-1.0)], e in magnitude(),
        ) {
            let r = 10f64.powf(e);
            let t = tb + sign * (min_rad + off);
            let a = Vector2::new(t.cos(), t.sin()) * r;
            let b = Vector2::new(tb.cos(), tb.sin()) * r;
            prop_assert_eq!(turned_at_least(&a, &Direction::of(&b), min_rad), reference(&a, &b, min_rad));
        }
    }
}
