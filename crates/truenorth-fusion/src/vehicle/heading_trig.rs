//! The sine and cosine of a heading that changes by small steps, kept up to date by small
//! rotations instead of a `sin_cos` per sample, and the small-angle arctangent of an
//! innovation.

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Largest step taken by the series, rad: its truncation error is below
/// 0.2⁷/5040 ≈ 2.5·10⁻⁹ rad per step.
const SERIES_STEP_RAD: f64 = 0.2;

/// Rotations by series between exact resynchronisations: bounds the accumulated rounding
/// and truncation at 64 × 2.5·10⁻⁹ rad.
const RESYNC_EVERY: u32 = 64;

/// `(sin, cos)` of an angle, carried along as the angle moves.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HeadingTrig {
    angle: f64,
    sin: f64,
    cos: f64,
    steps: u32,
}

impl HeadingTrig {
    /// At `angle` (rad).
    pub fn new(angle: f64) -> Self {
        let (sin, cos) = angle.sin_cos();
        Self {
            angle,
            sin,
            cos,
            steps: 0,
        }
    }

    /// `(sin, cos)` of `angle`, rotating from the last angle asked for.
    #[inline]
    pub fn at(&mut self, angle: f64) -> (f64, f64) {
        let d = angle - self.angle;
        if d == 0.0 {
            return (self.sin, self.cos);
        }
        self.steps += 1;
        if d.abs() > SERIES_STEP_RAD || self.steps >= RESYNC_EVERY || !d.is_finite() {
            *self = Self::new(angle);
            return (self.sin, self.cos);
        }
        let d2 = d * d;
        let sd = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0)));
        let cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0));
        let (s, c) = (self.sin * cd + self.cos * sd, self.cos * cd - self.sin * sd);
        // One Newton step back to unit length.
        let k = 1.5 - 0.5 * (s * s + c * c);
        self.angle = angle;
        self.sin = s * k;
        self.cos = c * k;
        (self.sin, self.cos)
    }
}

/// `atan2(y, x)`, by series when the angle is small (|y| ≤ x/4: error below
/// 0.25¹¹/11 ≈ 4·10⁻⁸ rad), the library function otherwise.
#[inline]
pub fn small_atan2(y: f64, x: f64) -> f64 {
    if x > 0.0 && y.abs() <= 0.25 * x {
        let t = y / x;
        let t2 = t * t;
        t * (1.0
            - t2 * (1.0 / 3.0 - t2 * (1.0 / 5.0 - t2 * (1.0 / 7.0 - t2 * (1.0 / 9.0 - t2 / 11.0)))))
    } else {
        y.atan2(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn follows_the_angle_through_any_walk(steps in proptest::collection::vec(-0.5f64..0.5, 1..400)) {
            let mut t = HeadingTrig::new(0.3);
            let mut a = 0.3;
            for d in steps {
                a += d;
                let (s, c) = t.at(a);
                prop_assert!((s - a.sin()).abs() < 1e-7 && (c - a.cos()).abs() < 1e-7);
            }
        }

        #[test]
        fn small_atan2_agrees_with_atan2(y in -10.0f64..10.0, x in -10.0f64..10.0) {
            prop_assert!((small_atan2(y, x) - y.atan2(x)).abs() < 1e-7);
        }
    }
}
