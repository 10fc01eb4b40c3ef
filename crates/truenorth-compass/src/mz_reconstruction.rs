//! Reconstructing the missing vertical magnetometer axis (WO 00/36376).
//!
//! A body with only two magnetometers (body x and y) cannot be tilt-compensated directly: the
//! body-z component is missing. The seed recovers it from the total field `Ht` measured at
//! start-up, `|M_z| = √(Ht² − M_x² − M_y²)`, and takes its sign from a comparison of the
//! sensor plane's current *slant angle* with the initial one.
//!
//! ## The sign, derived (the OCR'd text garbles the formula)
//! Let `(aa, ·, cc)` be the body z axis in the frame of magnetic north (north, east, down):
//! `aa = cos φ sin θ cos ψ + sin φ sin ψ`, `cc = cos θ cos φ`, with ψ the previous azimuth and
//! θ, φ the current pitch and roll. The seed's slant angle is `θ₂ = asin(aa / √(aa² + cc²))`:
//! the tilt of the sensor plane towards magnetic north. The field is `Ht·(cos I, 0, sin I)`
//! (I: inclination, positive down), so
//! `M_z = Ht·(aa cos I + cc sin I) = Ht·√(aa² + cc²)·sin(θ₂ + I)`.
//! Hence `M_z > 0` exactly when `θ₂ > −I`: the seed's rule "+ when the current slant angle is
//! larger than the initial slant angle θ₀, − otherwise" holds with `θ₀ = −I`, the slant at
//! which the sensor plane contains the field. Here θ₂ is computed with `atan2(aa, cc)`, which
//! equals the `asin` form while the body is upright (`cc > 0`) and keeps the rule right when
//! it is not.
//!
//! The reconstruction is only as good as `Ht`: where the sensor plane nearly contains the field
//! (`M_x² + M_y² ≈ Ht²`), `|M_z|` is ill-conditioned and noise can push the radicand below zero.
//! A small negative radicand (within `tolerance`) reads as `M_z = 0`; a larger one is a typed
//! error — the field has changed since start-up or the two axes are not calibrated.

use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result, Tilt, check_finite, check_finite2, check_finite3};

use crate::{level_field, tilt_compensated_heading};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Reconstructs `M_z` from two calibrated axes, the start-up field and the tilt.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MzReconstruction {
    total_field: f64,
    inclination_rad: f64,
    tolerance: f64,
}

impl MzReconstruction {
    /// Default tolerance: a horizontal-plane magnitude up to 2 % above the start-up total field
    /// is taken as noise (`M_z = 0`) rather than refused.
    pub const DEFAULT_TOLERANCE: f64 = 0.02;

    /// From the total field `Ht` (> 0, calibrated unit) and the inclination (radians, positive
    /// down), both as measured at start-up.
    pub fn new(total_field: f64, inclination_rad: f64) -> Result<Self> {
        check_finite("start-up total field", total_field)?;
        check_finite("inclination", inclination_rad)?;
        if total_field <= 0.0 {
            return Err(Error::OutOfRange {
                what: "start-up total field",
                value: total_field,
                min: f64::MIN_POSITIVE,
                max: f64::INFINITY,
            });
        }
        let half_pi = core::f64::consts::FRAC_PI_2;
        if inclination_rad.abs() > half_pi {
            return Err(Error::OutOfRange {
                what: "inclination (rad)",
                value: inclination_rad,
                min: -half_pi,
                max: half_pi,
            });
        }
        Ok(Self {
            total_field,
            inclination_rad,
            tolerance: Self::DEFAULT_TOLERANCE,
        })
    }

    /// From a full three-component calibrated reading taken at start-up with a known tilt (the
    /// seed stores `M_x(0)`, `M_y(0)` and `M_z(0)`, turning one magnetometer vertical to get the
    /// last): `Ht = |m₀|`, and the inclination from the levelled reading.
    pub fn from_startup_reading(m0: &Vector3<f64>, tilt0: &Tilt) -> Result<Self> {
        check_finite3("start-up magnetometer reading", m0)?;
        check_finite("start-up pitch", tilt0.pitch_rad)?;
        check_finite("start-up roll", tilt0.roll_rad)?;
        let lvl = level_field(m0, tilt0);
        let horizontal = lvl.x.hypot(lvl.y);
        if horizontal == 0.0 && lvl.z == 0.0 {
            return Err(Error::Degenerate {
                reason: "the start-up magnetometer reading is zero; calibrate the magnetometer first",
            });
        }
        Self::new(m0.norm(), lvl.z.atan2(horizontal))
    }

    /// Sets the tolerance (≥ 0) on `(M_x² + M_y²)/Ht²` above 1 that is read as `M_z = 0`.
    pub fn with_tolerance(mut self, tolerance: f64) -> Result<Self> {
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(Error::OutOfRange {
                what: "M_z reconstruction tolerance",
                value: tolerance,
                min: 0.0,
                max: f64::INFINITY,
            });
        }
        self.tolerance = tolerance;
        Ok(self)
    }

    /// The start-up total field `Ht`.
    pub fn total_field(&self) -> f64 {
        self.total_field
    }

    /// The start-up inclination, radians, positive down.
    pub fn inclination_rad(&self) -> f64 {
        self.inclination_rad
    }

    /// The seed's initial slant angle θ₀ = −I: the slant at which the sensor plane contains
    /// the field, where `M_z` changes sign.
    pub fn initial_slant_rad(&self) -> f64 {
        -self.inclination_rad
    }

    /// `|M_z| = √(Ht² − M_x² − M_y²)`; a typed error when the radicand is negative beyond the
    /// tolerance.
    pub fn magnitude(&self, mxy: &Vector2<f64>) -> Result<f64> {
        check_finite2("magnetometer reading", mxy)?;
        let ht2 = self.total_field * self.total_field;
        let rad = ht2 - mxy.norm_squared();
        if rad >= 0.0 {
            Ok(rad.sqrt())
        } else if -rad <= self.tolerance * ht2 {
            Ok(0.0)
        } else {
            Err(Error::OutOfRange {
                what: "(M_x² + M_y²) / Ht² for the M_z reconstruction (the field changed since start-up, or the axes are not calibrated)",
                value: mxy.norm_squared() / ht2,
                min: 0.0,
                max: 1.0 + self.tolerance,
            })
        }
    }

    /// The seed's slant angle θ₂ of the sensor plane towards magnetic north, from the current
    /// tilt and the previous azimuth ψ (radians): `atan2(aa, cc)` with `aa`, `cc` as in the
    /// module documentation.
    pub fn slant_angle_rad(tilt: &Tilt, azimuth_rad: f64) -> f64 {
        let (sp, cp) = tilt.pitch_rad.sin_cos();
        let (sr, cr) = tilt.roll_rad.sin_cos();
        let (sy, cy) = azimuth_rad.sin_cos();
        let aa = cr * sp * cy + sr * sy;
        let cc = cp * cr;
        aa.atan2(cc)
    }

    /// The sign of `M_z`: +1 when the current slant angle exceeds the initial one (`θ₂ > θ₀`,
    /// i.e. `sin(θ₂ − θ₀) ≥ 0`), −1 otherwise.
    pub fn sign(&self, tilt: &Tilt, previous_azimuth_rad: f64) -> f64 {
        let slant = Self::slant_angle_rad(tilt, previous_azimuth_rad);
        if (slant - self.initial_slant_rad()).sin() >= 0.0 {
            1.0
        } else {
            -1.0
        }
    }

    /// The three-component body reading with `M_z` reconstructed, from the two calibrated
    /// axes, the current tilt and the previous azimuth (heading) estimate.
    pub fn reconstruct(
        &self,
        mxy: &Vector2<f64>,
        tilt: &Tilt,
        previous_azimuth_rad: f64,
    ) -> Result<Vector3<f64>> {
        check_finite("pitch", tilt.pitch_rad)?;
        check_finite("roll", tilt.roll_rad)?;
        check_finite("previous azimuth", previous_azimuth_rad)?;
        let mz = self.magnitude(mxy)? * self.sign(tilt, previous_azimuth_rad);
        Ok(Vector3::new(mxy.x, mxy.y, mz))
    }

    /// Tilt-compensated heading from two calibrated axes (radians clockwise from magnetic
    /// north, (-π, π]).
    pub fn heading_rad(
        &self,
        mxy: &Vector2<f64>,
        tilt: &Tilt,
        previous_azimuth_rad: f64,
    ) -> Result<f64> {
        let m = self.reconstruct(mxy, tilt, previous_azimuth_rad)?;
        Ok(tilt_compensated_heading(&m, tilt))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AttitudeTruth, earth_field_ned};
    use proptest::prelude::*;
    use truenorth_core::{EulerZyx, angle_diff};

    proptest! {
        #[test]
        fn reconstructs_mz_and_heading(
            yaw in -3.1f64..3.1, pitch in -1.0f64..1.0, roll in -1.0f64..1.0,
            incl in -1.3f64..1.3, total in 10.0f64..60.0,
            prev_err in -0.3f64..0.3,
        ) {
            let field = earth_field_ned(total, incl);
            let att = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll };
            let m = AttitudeTruth { attitude: att, field_ned: field }.body_field();
            let level = AttitudeTruth { attitude: EulerZyx::default(), field_ned: field }.body_field();
            let rec = MzReconstruction::from_startup_reading(&level, &Tilt::default()).unwrap();
            prop_assert!((rec.inclination_rad() - incl).abs() < 1e-9);
            // The magnitude is always right.
            let mag = rec.magnitude(&m.xy()).unwrap();
            prop_assert!((mag - m.z.abs()).abs() < 1e-6 * total);
            // The sign (and so the heading) is right wherever M_z is not too close to zero for
            // a previous-azimuth error to flip it (elsewhere the magnitude check above is all
            // there is to test, so the case passes rather than counting as a reject).
            if m.z.abs() <= 0.3 * total {
                return Ok(());
            }
            let got = rec.reconstruct(&m.xy(), &att.tilt(), yaw + prev_err).unwrap();
            prop_assert!((got - m).norm() < 1e-6 * total, "got {:?} want {:?}", got, m);
            let h = rec.heading_rad(&m.xy(), &att.tilt(), yaw + prev_err).unwrap();
            prop_assert!(angle_diff(h, yaw).abs() < 1e-6);
        }

        #[test]
        fn exact_previous_azimuth_gives_the_right_sign_everywhere(
            yaw in -3.1f64..3.1, pitch in -1.2f64..1.2, roll in -1.2f64..1.2,
            incl in -1.3f64..1.3,
        ) {
            let field = earth_field_ned(40.0, incl);
            let att = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll };
            let m = AttitudeTruth { attitude: att, field_ned: field }.body_field();
            let rec = MzReconstruction::new(40.0, incl).unwrap();
            prop_assume!(m.z.abs() > 1e-6);
            prop_assert_eq!(rec.sign(&att.tilt(), yaw), m.z.signum());
        }
    }

    #[test]
    fn negative_root_is_a_typed_error() {
        let rec = MzReconstruction::new(10.0, 1.0).unwrap();
        assert_eq!(rec.magnitude(&Vector2::new(10.05, 0.0)).unwrap(), 0.0);
        assert!(matches!(
            rec.magnitude(&Vector2::new(12.0, 0.0)),
            Err(Error::OutOfRange { .. })
        ));
        assert!(rec.magnitude(&Vector2::new(f64::NAN, 0.0)).is_err());
        assert!(MzReconstruction::new(-1.0, 0.0).is_err());
        assert!(MzReconstruction::new(1.0, 2.0).is_err());
        assert!(rec.with_tolerance(-0.1).is_err());
        assert!(
            MzReconstruction::from_startup_reading(&Vector3::zeros(), &Tilt::default()).is_err()
        );
    }
}
