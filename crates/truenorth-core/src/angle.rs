//! Angle wrapping and unwrapping. Every angle difference in truenorth goes through here so
//! that the (-π, π] convention is applied in one place.

use core::f64::consts::PI;

#[cfg(not(feature = "std"))]
use crate::Float as _;

const TWO_PI: f64 = 2.0 * PI;

/// `x` modulo 2π in [0, 2π] (floor-based, so it also works without `std`).
#[inline]
fn rem_two_pi(x: f64) -> f64 {
    x - TWO_PI * (x / TWO_PI).floor()
}

/// Wraps an angle into (-π, π]. Non-finite input is returned unchanged (NaN stays NaN) so the
/// caller's validation can report it.
#[inline]
pub fn wrap_pi(angle_rad: f64) -> f64 {
    // Most angles wrapped are differences of wrapped angles, already in range or one turn
    // out: no division for those.
    if angle_rad > -PI && angle_rad <= PI {
        return angle_rad;
    }
    if !angle_rad.is_finite() {
        return angle_rad;
    }
    // rem_euclid gives [0, 2π); shift so that -π maps to +π.
    let r = rem_two_pi(angle_rad + PI) - PI;
    if r <= -PI { r + TWO_PI } else { r }
}

/// Wraps an angle into [0, 2π) — the range a compass heading is shown in.
#[inline]
pub fn wrap_two_pi(angle_rad: f64) -> f64 {
    if !angle_rad.is_finite() {
        return angle_rad;
    }
    let r = rem_two_pi(angle_rad);
    // The reduction can round up to exactly 2π for tiny negative inputs.
    if r >= TWO_PI {
        0.0
    } else if r < 0.0 {
        (r + TWO_PI).min(TWO_PI.next_down())
    } else {
        r
    }
}

/// The signed difference `a - b`, wrapped into (-π, π].
#[inline]
pub fn angle_diff(a_rad: f64, b_rad: f64) -> f64 {
    wrap_pi(a_rad - b_rad)
}

/// The angle equal to `angle_rad` modulo 2π that lies within π of `reference_rad`.
#[inline]
pub fn unwrap_near(reference_rad: f64, angle_rad: f64) -> f64 {
    reference_rad + angle_diff(angle_rad, reference_rad)
}

/// Turns a stream of wrapped angles into a continuous one (no 2π jumps), assuming that
/// consecutive samples differ by less than π.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Unwrapper {
    last_rad: Option<f64>,
}

impl Unwrapper {
    /// A new unwrapper; the first angle it sees is passed through unchanged.
    pub const fn new() -> Self {
        Self { last_rad: None }
    }

    /// Feeds the next wrapped angle and returns the continuous angle.
    pub fn push(&mut self, wrapped_rad: f64) -> f64 {
        let out = match self.last_rad {
            Some(last) => unwrap_near(last, wrapped_rad),
            None => wrapped_rad,
        };
        if out.is_finite() {
            self.last_rad = Some(out);
        }
        out
    }

    /// The last continuous angle, if any.
    pub fn last(&self) -> Option<f64> {
        self.last_rad
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn edges() {
        assert_eq!(wrap_pi(PI), PI);
        assert_eq!(wrap_pi(-PI), PI);
        assert_eq!(wrap_pi(0.0), 0.0);
        assert!(wrap_pi(f64::NAN).is_nan());
        assert_eq!(wrap_two_pi(-1e-300), 0.0);
    }

    proptest! {
        #[test]
        fn wrap_pi_is_in_range_and_congruent(a in -1e6f64..1e6) {
            let w = wrap_pi(a);
            prop_assert!(w > -PI && w <= PI);
            // w - a is a whole number of turns.
            let turns = (w - a) / TWO_PI;
            prop_assert!((turns - turns.round()).abs() < 1e-6);
        }

        #[test]
        fn wrap_pi_is_idempotent(a in -1e6f64..1e6) {
            let w = wrap_pi(a);
            prop_assert_eq!(wrap_pi(w), w);
        }

        #[test]
        fn wrap_two_pi_in_range(a in -1e6f64..1e6) {
            let w = wrap_two_pi(a);
            prop_assert!((0.0..TWO_PI).contains(&w));
        }

        #[test]
        fn angle_diff_is_antisymmetric(a in -10.0f64..10.0, b in -10.0f64..10.0) {
            let d1 = angle_diff(a, b);
            let d2 = angle_diff(b, a);
            // Antisymmetric except at the ±π boundary, where both are +π.
            prop_assume!((d1.abs() - PI).abs() > 1e-9);
            prop_assert!((d1 + d2).abs() < 1e-9);
        }

        #[test]
        fn unwrapper_recovers_continuous_signal(
            start in -10.0f64..10.0,
            steps in proptest::collection::vec(-3.0f64..3.0, 1..200),
        ) {
            let mut u = Unwrapper::new();
            let mut truth = start;
            let first = u.push(wrap_pi(truth));
            let offset = first - truth;
            for s in steps {
                truth += s;
                let got = u.push(wrap_pi(truth));
                prop_assert!((got - truth - offset).abs() < 1e-6);
            }
        }
    }
}
