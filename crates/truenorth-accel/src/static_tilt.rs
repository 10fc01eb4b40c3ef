//! Static tilt: pitch and roll from one specific-force reading, valid when the sensor is not
//! accelerating (so that it senses gravity only; see [`crate::QuasiStaticDetector`]).
//!
//! At rest, with `R = Rz(ψ)·Ry(θ)·Rx(φ)` (core's Z-Y-X convention) and z down,
//! `f_b = Rᵀ(0, 0, −g) = (g sin θ, −g sin φ cos θ, −g cos φ cos θ)`, so
//!
//! `θ = atan2(f_x, √(f_y² + f_z²))`, `φ = atan2(−f_y, −f_z)`.
//!
//! Only ratios of the components enter, so the reading's unit and magnitude do not matter
//! (g or m/s², a scale error common to all axes, or a |f| that is not quite g).
//!
//! # Against the seed (WO 00/36376)
//!
//! The seed takes readings in g of the gravity direction, `A = −f/g` (level: `A_z = +1`), and
//! prints `P = asin(A_x)`, `R = asin(A_y / cos P)`, and with a third axis
//! `A_z > 0: R`, `A_z < 0 and A_x > 0: π − R`, `A_z < 0 and A_x < 0: −π − R`.
//! Differences:
//! * The upside-down branch is keyed on the sign of `A_x` (the pitch axis). The two branches
//!   differ by exactly 2π, so the angle is right modulo 2π, but keyed on `A_x` it can leave
//!   (−π, π] (roll −120° with the nose a little down, A_x > 0, comes out as +240°) and it is undefined
//!   for `A_x = 0`. Geometrically the branch follows the sign of the roll, i.e. of `A_y`:
//!   `A_y ≥ 0: π − R`, `A_y < 0: −π − R` — which is `atan2(A_y, A_z)`, used here.
//! * `asin(A_y / cos P)` needs `|A_y / cos P| ≤ 1` (noise or |a| ≠ 1 g break it) and divides by
//!   zero at P = ±90°; `asin(A_x)` needs |A_x| ≤ 1. `atan2` of ratios has neither problem.
//! * With `A = −f/g` in these axes, `A_x = −sin θ`, so the seed's P is positive nose down;
//!   here pitch is positive nose up, as in core's [`Tilt`].

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{Error, Result, Tilt, check_finite, check_finite3, wrap_pi};

use nalgebra::Vector3;

/// Below this specific-force magnitude (≈ 0.05 g) the reading's direction is dominated by a
/// consumer accelerometer's bias and noise (tens of mg), or the sensor is falling, so no
/// tilt is computed.
pub const MIN_SPECIFIC_FORCE_MPS2: f64 = 0.5;

/// Pitch and roll from a specific-force reading in body axes (any unit, but
/// [`MIN_SPECIFIC_FORCE_MPS2`] assumes m/s²). Pitch in [−π/2, π/2], roll in (−π, π]; at
/// pitch ±90° roll is not defined and is reported as 0 (as core's `EulerZyx` does).
///
/// A typed error when a component is not finite or |f| < [`MIN_SPECIFIC_FORCE_MPS2`].
pub fn static_tilt(f_b: &Vector3<f64>) -> Result<Tilt> {
    check_finite3("specific force", f_b)?;
    // Scale before squaring so that huge finite readings do not overflow the norm.
    let scale = f_b.amax();
    let norm = if scale > 0.0 {
        scale * (f_b / scale).norm()
    } else {
        0.0
    };
    if norm < MIN_SPECIFIC_FORCE_MPS2 {
        return Err(Error::OutOfRange {
            what: "specific-force magnitude |f| for static tilt (free fall or no reading)",
            value: norm,
            min: MIN_SPECIFIC_FORCE_MPS2,
            max: f64::INFINITY,
        });
    }
    let (fx, fy, fz) = (f_b.x / scale, f_b.y / scale, f_b.z / scale);
    let horizontal = fy.hypot(fz);
    let pitch_rad = fx.atan2(horizontal);
    // atan2(±0, ±0) would give ±0 or ±π depending on zero signs; roll is undefined there.
    let roll_rad = if horizontal == 0.0 {
        0.0
    } else {
        wrap_pi((-fy).atan2(-fz))
    };
    Ok(Tilt {
        pitch_rad,
        roll_rad,
    })
}

/// Pitch from the forward axis alone (the two-dimensional variant of WO 00/36376):
/// `θ = asin(f_x / g)`. A typed error when `|f_x| > g` (the sensor is accelerating, so the
/// reading is not gravity alone) or an input is not finite.
pub fn pitch_from_forward_axis_rad(f_x_mps2: f64, gravity_mps2: f64) -> Result<f64> {
    let fx = check_finite("forward specific force f_x", f_x_mps2)?;
    let g = check_finite("gravity_mps2", gravity_mps2)?;
    if g <= 0.0 {
        return Err(Error::OutOfRange {
            what: "gravity_mps2",
            value: g,
            min: f64::MIN_POSITIVE,
            max: f64::MAX,
        });
    }
    if fx.abs() > g {
        return Err(Error::OutOfRange {
            what: "forward specific force f_x (exceeds gravity: the sensor is accelerating)",
            value: fx,
            min: -g,
            max: g,
        });
    }
    Ok((fx / g).asin())
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;
    use proptest::prelude::*;
    use truenorth_core::{EulerZyx, STANDARD_GRAVITY_MPS2, angle_diff};

    const G: f64 = STANDARD_GRAVITY_MPS2;

    fn at_rest(yaw: f64, pitch: f64, roll: f64) -> Vector3<f64> {
        let q = EulerZyx {
            yaw_rad: yaw,
            pitch_rad: pitch,
            roll_rad: roll,
        }
        .to_quaternion();
        q.inverse_transform_vector(&Vector3::new(0.0, 0.0, -G))
    }

    /// The seed's printed formulas (WO 00/36376), on A = −f/g, for comparison only.
    fn seed_printed(f: &Vector3<f64>) -> Option<(f64, f64)> {
        let a = -f / G;
        let p = a.x.asin();
        let r = (a.y / p.cos()).asin();
        if !(p.is_finite() && r.is_finite()) || a.x == 0.0 {
            return None;
        }
        let r = if a.z > 0.0 {
            r
        } else if a.x > 0.0 {
            PI - r
        } else {
            -PI - r
        };
        Some((p, r))
    }

    proptest! {
        #[test]
        fn recovers_pitch_and_roll_at_rest_in_any_attitude(
            yaw in -PI..PI, pitch in -1.55f64..1.55, roll in -PI..PI, scale in 0.1f64..100.0,
        ) {
            // `scale`: magnitude (unit, common scale error) must not matter.
            let t = static_tilt(&(at_rest(yaw, pitch, roll) * scale)).unwrap();
            prop_assert!((t.pitch_rad - pitch).abs() < 1e-9, "{} vs {pitch}", t.pitch_rad);
            prop_assert!(angle_diff(t.roll_rad, roll).abs() < 1e-9, "{} vs {roll}", t.roll_rad);
            prop_assert!(t.roll_rad > -PI && t.roll_rad <= PI);
        }

        /// The printed rule gives the same angle modulo 2π where its asin is defined.
        #[test]
        fn seed_rule_agrees_modulo_two_pi(yaw in -PI..PI, pitch in -1.4f64..1.4, roll in -PI..PI) {
            let f = at_rest(yaw, pitch, roll);
            let ours = static_tilt(&f).unwrap();
            if let Some((p, r)) = seed_printed(&f) {
                prop_assert!((p + ours.pitch_rad).abs() < 1e-6, "seed pitch is nose-down positive");
                prop_assert!(angle_diff(r, ours.roll_rad).abs() < 1e-6);
            }
        }

        #[test]
        fn no_panic_and_typed_errors(
            x in proptest::num::f64::ANY, y in proptest::num::f64::ANY, z in proptest::num::f64::ANY,
        ) {
            let f = Vector3::new(x, y, z);
            match static_tilt(&f) {
                Ok(t) => prop_assert!(t.pitch_rad.is_finite() && t.roll_rad.is_finite()),
                Err(Error::NonFinite { .. }) => prop_assert!(!(x.is_finite() && y.is_finite() && z.is_finite())),
                Err(Error::OutOfRange { .. }) => prop_assert!(x.abs().max(y.abs()).max(z.abs()) < MIN_SPECIFIC_FORCE_MPS2),
                Err(e) => prop_assert!(false, "unexpected {e:?}"),
            }
            let _ = pitch_from_forward_axis_rad(x, y);
        }

        #[test]
        fn forward_axis_pitch_matches_at_rest(pitch in -1.57f64..1.57, roll in -PI..PI) {
            let f = at_rest(0.3, pitch, roll);
            prop_assert!((pitch_from_forward_axis_rad(f.x, G).unwrap() - pitch).abs() < 1e-6);
        }
    }

    /// Where the printed branch choice (sign of A_x) goes wrong: roll −120° with the nose a
    /// little down (A_x > 0) comes out as +240°, outside (−π, π]; ours gives −120°.
    #[test]
    fn printed_branch_leaves_the_range_where_ours_does_not() {
        let roll = -120f64.to_radians();
        let f = at_rest(0.0, -0.1, roll);
        let (_, r) = seed_printed(&f).unwrap();
        assert!(r > PI, "printed rule gave {}", r.to_degrees());
        let ours = static_tilt(&f).unwrap();
        assert!((ours.roll_rad - roll).abs() < 1e-12);
    }

    #[test]
    fn edges() {
        let level = static_tilt(&Vector3::new(0.0, 0.0, -G)).unwrap();
        assert_eq!((level.pitch_rad, level.roll_rad), (0.0, 0.0));
        let nose_up = static_tilt(&Vector3::new(G, 0.0, 0.0)).unwrap();
        assert_eq!(nose_up.pitch_rad, PI / 2.0);
        assert_eq!(nose_up.roll_rad, 0.0);
        let upside_down = static_tilt(&Vector3::new(0.0, 0.0, G)).unwrap();
        assert_eq!(upside_down.roll_rad, PI);
        assert!(static_tilt(&Vector3::new(0.0, 0.0, -0.1)).is_err());
        assert!(static_tilt(&Vector3::zeros()).is_err());
        assert!(pitch_from_forward_axis_rad(1.1 * G, G).is_err());
    }
}
