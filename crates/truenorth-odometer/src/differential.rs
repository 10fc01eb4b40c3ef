//! Heading change from the difference of two wheel distances (US 4,788,645 eqs. 1/7 and 2/8).
//!
//! Sign: the left wheel rolling further means a right turn, i.e. a positive heading change
//! (heading clockwise from north, body y to the right).

use truenorth_core::{Error, Result, check_finite};

use truenorth_core::check_positive;

/// Plain differential heading change `Δθ = (D_L − D_R) / T` (eq. 1/7), radians.
pub fn heading_change_plain_rad(dist_l_m: f64, dist_r_m: f64, track_m: f64) -> Result<f64> {
    let l = check_finite("left wheel distance", dist_l_m)?;
    let r = check_finite("right wheel distance", dist_r_m)?;
    let t = check_positive("track_m", track_m)?;
    // Huge finite inputs can overflow; say so instead of returning inf.
    check_finite("heading change (wheel distances too large)", (l - r) / t)
}

/// The speed factor `1 + aV²` of eq. 2/8, checked to be positive (a negative `a` at a high
/// speed could make it vanish, and dividing by it would then be meaningless).
pub fn speed_factor(speed_coeff_s2_per_m2: f64, speed_mps: f64) -> Result<f64> {
    let a = check_finite("speed coefficient a (s²/m²)", speed_coeff_s2_per_m2)?;
    let v = check_finite("speed_mps", speed_mps)?;
    check_speed_factor(1.0 + a * v * v)
}

/// Refuses a speed factor `1 + aV²` that is not positive and finite.
pub(crate) fn check_speed_factor(f: f64) -> Result<f64> {
    if !(f > 0.0 && f.is_finite()) {
        return Err(Error::OutOfRange {
            what: "speed factor 1 + aV² (lower |a| or the speed)",
            value: f,
            min: f64::MIN_POSITIVE,
            max: f64::MAX,
        });
    }
    Ok(f)
}

/// Speed-corrected heading change `Δθ = ΔD / (T·(1 + aV²))` (eq. 2/8), radians: the
/// wheels' difference grows with speed (load transfer and tyre forces in the turn) and
/// `a` (s²/m²) takes that out.
pub fn heading_change_speed_corrected_rad(
    dist_l_m: f64,
    dist_r_m: f64,
    track_m: f64,
    speed_coeff_s2_per_m2: f64,
    speed_mps: f64,
) -> Result<f64> {
    let plain = heading_change_plain_rad(dist_l_m, dist_r_m, track_m)?;
    let factor = speed_factor(speed_coeff_s2_per_m2, speed_mps)?;
    check_finite("heading change (inputs too large)", plain / factor)
}

/// The curvature ratio `c = ΔD/AD = (D_L − D_R) / ((D_L + D_R)/2)` that the effective track
/// depends on (eq. 3/14). Zero when neither wheel moved; a typed error when the wheels moved
/// equal and opposite amounts (a turn on the spot has no finite ratio).
pub fn curvature_ratio(dist_l_m: f64, dist_r_m: f64) -> Result<f64> {
    let l = check_finite("left wheel distance", dist_l_m)?;
    let r = check_finite("right wheel distance", dist_r_m)?;
    let mean = 0.5 * (l + r);
    let diff = l - r;
    if mean == 0.0 {
        if diff == 0.0 {
            return Ok(0.0);
        }
        return Err(Error::OutOfRange {
            what: "curvature ratio ΔD/AD (wheels moved equal and opposite distances)",
            value: if diff > 0.0 {
                f64::INFINITY
            } else {
                f64::NEG_INFINITY
            },
            min: f64::MIN,
            max: f64::MAX,
        });
    }
    // Very unequal tiny distances can overflow; report that rather than return inf.
    check_finite("curvature ratio ΔD/AD", diff / mean)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn left_longer_is_a_right_turn(d in 0.0f64..10.0, extra in 1e-6f64..1.0, t in 0.5f64..3.0) {
            prop_assert!(heading_change_plain_rad(d + extra, d, t).unwrap() > 0.0);
            prop_assert!(heading_change_plain_rad(d, d + extra, t).unwrap() < 0.0);
        }

        #[test]
        fn speed_correction_divides_by_the_factor(
            l in -5.0f64..5.0, r in -5.0f64..5.0, t in 0.5f64..3.0, a in 0.0f64..1e-3, v in 0.0f64..40.0,
        ) {
            let plain = heading_change_plain_rad(l, r, t).unwrap();
            let corr = heading_change_speed_corrected_rad(l, r, t, a, v).unwrap();
            prop_assert!((corr * (1.0 + a * v * v) - plain).abs() < 1e-12 * (1.0 + plain.abs()));
        }

        #[test]
        fn no_panic_and_typed_errors(
            l in proptest::num::f64::ANY, r in proptest::num::f64::ANY,
            t in proptest::num::f64::ANY, a in proptest::num::f64::ANY,
        ) {
            let ok = l.is_finite() && r.is_finite() && t.is_finite() && t > 0.0;
            match heading_change_plain_rad(l, r, t) {
                Ok(x) => prop_assert!(ok && x.is_finite()),
                Err(_) => prop_assert!(!ok || ((l - r) / t).is_infinite()),
            }
            if let Ok(x) = heading_change_speed_corrected_rad(l, r, t, a, 10.0) {
                prop_assert!(x.is_finite());
            }
            if let Ok(c) = curvature_ratio(l, r) {
                prop_assert!(c.is_finite());
            }
        }
    }

    #[test]
    fn ratio_edge_cases() {
        assert_eq!(curvature_ratio(0.0, 0.0).unwrap(), 0.0);
        assert!(curvature_ratio(1.0, -1.0).is_err());
        assert!((curvature_ratio(1.1, 0.9).unwrap() - 0.2).abs() < 1e-12);
        assert!(speed_factor(-0.01, 20.0).is_err());
        assert!(heading_change_plain_rad(1.0, 0.0, 0.0).is_err());
    }
}
