//! Heading from the field: of a horizontal field vector, and, by tilt compensation, of a
//! three-axis reading on a tilted body.
//!
//! With `R = Rz(ψ) · Ry(θ) · Rx(φ)` (body → NED), the body reading is `m = Rᵀ f`, so
//! `Ry(θ) · Rx(φ) · m = Rz(ψ)ᵀ f`: undoing pitch and roll leaves the field as a *level* body at
//! the same heading would see it, `(H cos ψ, −H sin ψ, Z)`, and the heading follows as in 2-D.
//! (WO 00/36376 writes it as `Hx = cos P·Mx + sin P·Mz`, with roll; the form here is that
//! formula with both angles, derived from the rotation.)

use nalgebra::{Vector2, Vector3};
use truenorth_core::{Real, Result, Tilt, check_finite, check_finite3};

/// Heading (radians, clockwise from magnetic north, (-π, π]) of a horizontal field vector in
/// body axes (x forward, y right): `ψ = atan2(−h_y, h_x)`.
#[inline]
pub fn heading_from_horizontal(h: &Vector2<f64>) -> f64 {
    heading_from_horizontal_in(h)
}

/// [`heading_from_horizontal`] in the float type `T`.
#[inline]
pub fn heading_from_horizontal_in<T: Real>(h: &Vector2<T>) -> T {
    (-h.y).atan2(h.x)
}

/// The field as a level body at the same heading would see it: `Ry(pitch) · Rx(roll) · m`.
///
/// Components: `x = cos θ·m_x + sin θ sin φ·m_y + sin θ cos φ·m_z`,
/// `y = cos φ·m_y − sin φ·m_z`, `z = −sin θ·m_x + cos θ sin φ·m_y + cos θ cos φ·m_z`.
#[inline]
pub fn level_field(m_body: &Vector3<f64>, tilt: &Tilt) -> Vector3<f64> {
    level_field_in(m_body, tilt)
}

/// [`level_field`] in the reading's float type `T`; the angles are converted to it before
/// their sines.
#[inline]
pub fn level_field_in<T: Real>(m_body: &Vector3<T>, tilt: &Tilt) -> Vector3<T> {
    let (sp, cp) = T::of(tilt.pitch_rad).sin_cos();
    let (sr, cr) = T::of(tilt.roll_rad).sin_cos();
    // Rx(φ) first: y' = cos φ·y − sin φ·z, z' = sin φ·y + cos φ·z.
    let y1 = cr * m_body.y - sr * m_body.z;
    let z1 = sr * m_body.y + cr * m_body.z;
    // Then Ry(θ): x'' = cos θ·x + sin θ·z', z'' = −sin θ·x + cos θ·z'.
    Vector3::new(cp * m_body.x + sp * z1, y1, -sp * m_body.x + cp * z1)
}

/// Tilt-compensated heading (radians clockwise from magnetic north, (-π, π]) of a calibrated
/// three-axis reading. Allocation-free; returns NaN for non-finite input (see
/// [`tilt_compensated_heading_checked`] for a typed error instead).
#[inline]
pub fn tilt_compensated_heading(m_body: &Vector3<f64>, tilt: &Tilt) -> f64 {
    tilt_compensated_heading_in(m_body, tilt)
}

/// [`tilt_compensated_heading`] in the reading's float type `T`.
#[inline]
pub fn tilt_compensated_heading_in<T: Real>(m_body: &Vector3<T>, tilt: &Tilt) -> T {
    heading_from_horizontal_in(&level_field_in(m_body, tilt).xy())
}

/// [`tilt_compensated_heading`] that refuses non-finite readings or angles with a typed error.
pub fn tilt_compensated_heading_checked(m_body: &Vector3<f64>, tilt: &Tilt) -> Result<f64> {
    check_finite3("magnetometer reading", m_body)?;
    check_finite("pitch", tilt.pitch_rad)?;
    check_finite("roll", tilt.roll_rad)?;
    Ok(tilt_compensated_heading(m_body, tilt))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AttitudeTruth, earth_field_ned, heading_from_horizontal};
    use proptest::prelude::*;
    use truenorth_core::{EulerZyx, angle_diff};

    proptest! {
        #[test]
        fn recovers_heading_at_any_tilt(
            yaw in -3.1f64..3.1, pitch in -1.5f64..1.5, roll in -3.1f64..3.1,
            incl in -1.45f64..1.45, total in 1.0f64..100.0,
        ) {
            let att = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll };
            let m = AttitudeTruth { attitude: att, field_ned: earth_field_ned(total, incl) }.body_field();
            let h = tilt_compensated_heading(&m, &att.tilt());
            prop_assert!(angle_diff(h, yaw).abs() < 1e-7, "h {} yaw {}", h, yaw);
            let lvl = level_field(&m, &att.tilt());
            prop_assert!((lvl.z - total * incl.sin()).abs() < 1e-9 * total);
        }
    }

    #[test]
    fn ignoring_tilt_is_wrong_and_compensating_is_right() {
        // 20° nose up, heading 90°, strong dip: the uncompensated heading is far off.
        let att = EulerZyx {
            yaw_rad: 1.0,
            pitch_rad: 20f64.to_radians(),
            roll_rad: 0.0,
        };
        let m = AttitudeTruth {
            attitude: att,
            field_ned: earth_field_ned(50.0, 65f64.to_radians()),
        }
        .body_field();
        let naive = heading_from_horizontal(&m.xy());
        assert!(angle_diff(naive, 1.0).abs() > 10f64.to_radians());
        assert!(angle_diff(tilt_compensated_heading(&m, &att.tilt()), 1.0).abs() < 1e-9);
        assert!(
            tilt_compensated_heading_checked(&Vector3::new(f64::NAN, 0.0, 0.0), &att.tilt())
                .is_err()
        );
    }
}
