//! Compass calibration parameters and heading from a calibrated reading, in the float type
//! `T` (`f64` by default; `f32` for a single-precision FPU, through
//! [`CompassCalibration2d::to_precision`]). The parameters are fitted, saved and validated
//! in `f64`; the traits ([`Calibration`], [`AbsoluteHeadingSource`]) are for `f64`.

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_core::{
    AbsoluteHeading, AbsoluteHeadingSource, Calibration, Error, Mag2Sample, Mag3Sample,
    MagneticHeading, Real, Result, Tilt, Validate, check_finite, check_finite2, check_finite3,
};

use crate::{
    heading_from_horizontal, heading_from_horizontal_in, level_field, tilt_compensated_heading_in,
};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// A two-axis compass calibration in `f64`, the form every calibrator produces and every
/// file holds (see [`CompassCalibration2dIn`]).
pub type CompassCalibration2d = CompassCalibration2dIn<f64>;

/// A two-axis compass calibration in the float type `T`:
/// `corrected = soft_iron · (raw − hard_iron)`. [`CompassCalibration2d`] is the `f64` one;
/// [`CompassCalibration2d::to_precision`] gives it in `f32`, for readings in `f32`. (A
/// struct per type rather than a default type parameter keeps `T` known in a literal
/// `CompassCalibration2d { .. }` of `f64` numbers.)
///
/// `hard_iron` is the centre of the raw locus (the vehicle's permanent magnetisation plus
/// sensor offsets); `soft_iron` maps the raw ellipse onto a circle whose radius is the
/// horizontal field in the input unit.
///
/// Read from JSON (or any serde format), it is validated as [`Validate`] says, so a damaged
/// file is an error on load rather than wrong headings later.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Fields<Vector2<T>, Matrix2<T>>")]
// `Real` includes serde's bounds on `T`.
#[serde(bound = "")]
pub struct CompassCalibration2dIn<T: Real> {
    /// Offset to subtract from raw readings, input unit.
    pub hard_iron: Vector2<T>,
    /// Matrix that turns the centred ellipse into a circle.
    pub soft_iron: Matrix2<T>,
}

/// The serialised fields of a calibration, before validation.
#[derive(Deserialize)]
struct Fields<V, M> {
    hard_iron: V,
    soft_iron: M,
}

impl<T: Real> TryFrom<Fields<Vector2<T>, Matrix2<T>>> for CompassCalibration2dIn<T> {
    type Error = Error;

    fn try_from(f: Fields<Vector2<T>, Matrix2<T>>) -> Result<Self> {
        let c = Self {
            hard_iron: f.hard_iron,
            soft_iron: f.soft_iron,
        };
        c.validate()?;
        Ok(c)
    }
}

impl<T: Real> TryFrom<Fields<Vector3<T>, Matrix3<T>>> for CompassCalibration3dIn<T> {
    type Error = Error;

    fn try_from(f: Fields<Vector3<T>, Matrix3<T>>) -> Result<Self> {
        let c = Self {
            hard_iron: f.hard_iron,
            soft_iron: f.soft_iron,
        };
        c.validate()?;
        Ok(c)
    }
}

impl<T: Real> Validate for CompassCalibration2dIn<T> {
    /// A finite hard iron and a finite soft iron with a positive determinant (a singular one
    /// gives constant headings, a negative one mirrored headings).
    fn validate(&self) -> Result<()> {
        check_finite2("hard iron", &self.hard_iron.map(T::to_f64))?;
        check_soft_iron_det(self.soft_iron.iter(), self.soft_iron.determinant())
    }
}

impl<T: Real> Validate for CompassCalibration3dIn<T> {
    /// As for [`CompassCalibration2d`].
    fn validate(&self) -> Result<()> {
        check_finite3("hard iron", &self.hard_iron.map(T::to_f64))?;
        check_soft_iron_det(self.soft_iron.iter(), self.soft_iron.determinant())
    }
}

impl Default for CompassCalibration2d {
    fn default() -> Self {
        Self::identity()
    }
}

impl CompassCalibration2d {
    /// No correction.
    pub fn identity() -> Self {
        Self {
            hard_iron: Vector2::zeros(),
            soft_iron: Matrix2::identity(),
        }
    }

    /// The parameters in the float type `T` (rounded to nearest for `f32`), to apply them
    /// where the readings are in `T`: `cal.to_precision::<f32>()`.
    pub fn to_precision<T: Real>(&self) -> CompassCalibration2dIn<T> {
        CompassCalibration2dIn {
            hard_iron: self.hard_iron.map(T::of),
            soft_iron: self.soft_iron.map(T::of),
        }
    }
}

impl<T: Real> CompassCalibration2dIn<T> {
    /// The corrected horizontal field.
    #[inline]
    pub fn correct(&self, raw: &Vector2<T>) -> Vector2<T> {
        self.soft_iron * (raw - self.hard_iron)
    }

    /// Heading of a raw reading, radians clockwise from magnetic north, (-π, π].
    #[inline]
    pub fn heading_rad(&self, raw: &Vector2<T>) -> T {
        heading_from_horizontal_in(&self.correct(raw))
    }

    /// Heading of a raw reading as a [`MagneticHeading`]: the typed form that turns into a
    /// true heading only through [`MagneticHeading::to_true`], so declination is added once.
    #[inline]
    pub fn magnetic_heading(&self, raw: &Vector2<T>) -> MagneticHeading {
        MagneticHeading::new(self.heading_rad(raw).to_f64())
    }
}

impl Calibration for CompassCalibration2d {
    type Raw = Vector2<f64>;
    type Physical = Vector2<f64>;

    /// Refuses a non-finite reading, and parameters that are not finite or whose soft iron
    /// is singular or reflecting (it would give constant or mirrored headings).
    fn apply(&self, raw: &Vector2<f64>) -> Result<Vector2<f64>> {
        check_finite2("magnetometer reading", raw)?;
        self.validate()?;
        Ok(self.correct(raw))
    }
}

/// Tilts below this (radians) count as level for a two-axis compass: 0.01° keeps the
/// heading error of ignoring them under 2·10⁻⁴ rad even at a 70° dip.
const LEVEL_TILT_RAD: f64 = 1.745e-4;

impl AbsoluteHeadingSource for CompassCalibration2d {
    type Sample = Mag2Sample;

    /// A two-axis compass cannot compensate tilt: a tilt beyond 0.01° is refused with
    /// [`Error::Unsupported`] rather than silently ignored.
    fn heading(&self, sample: &Mag2Sample, tilt: Option<&Tilt>) -> Result<AbsoluteHeading> {
        if let Some(t) = tilt {
            check_finite("pitch", t.pitch_rad)?;
            check_finite("roll", t.roll_rad)?;
            if t.pitch_rad.abs() > LEVEL_TILT_RAD || t.roll_rad.abs() > LEVEL_TILT_RAD {
                return Err(Error::Unsupported {
                    reason: "a two-axis compass cannot compensate tilt; use a three-axis magnetometer (CompassCalibration3d) or pass no tilt to assume level",
                });
            }
        }
        let h = self.apply(&sample.mag)?;
        Ok(AbsoluteHeading {
            heading: MagneticHeading::new(heading_from_horizontal(&h)),
            field_norm: h.norm(),
            dip_rad: None,
        })
    }
}

/// Refuses soft-iron entries that are not finite and a determinant that is not positive: a
/// singular matrix collapses every reading onto a line, a negative one mirrors the heading.
fn check_soft_iron_det<'a, T: Real>(entries: impl Iterator<Item = &'a T>, det: T) -> Result<()> {
    for v in entries {
        check_finite("soft iron entry", v.to_f64())?;
    }
    if det > T::zero() {
        Ok(())
    } else {
        Err(Error::Degenerate {
            reason: "the soft-iron matrix is singular or reflecting (determinant not positive); recalibrate",
        })
    }
}

/// A three-axis magnetometer calibration in `f64` (see [`CompassCalibration3dIn`]).
pub type CompassCalibration3d = CompassCalibration3dIn<f64>;

/// A three-axis magnetometer calibration in the float type `T` (as
/// [`CompassCalibration2dIn`]): `corrected = soft_iron · (raw − hard_iron)`, with
/// `soft_iron` symmetric positive definite, mapping the raw ellipsoid onto a sphere whose
/// radius is the total field in the input unit.
///
/// Validated when read, as [`CompassCalibration2d`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Fields<Vector3<T>, Matrix3<T>>")]
// `Real` includes serde's bounds on `T`.
#[serde(bound = "")]
pub struct CompassCalibration3dIn<T: Real> {
    /// Offset to subtract from raw readings, input unit.
    pub hard_iron: Vector3<T>,
    /// Matrix that turns the centred ellipsoid into a sphere.
    pub soft_iron: Matrix3<T>,
}

impl Default for CompassCalibration3d {
    fn default() -> Self {
        Self::identity()
    }
}

impl CompassCalibration3d {
    /// No correction.
    pub fn identity() -> Self {
        Self {
            hard_iron: Vector3::zeros(),
            soft_iron: Matrix3::identity(),
        }
    }

    /// The parameters in the float type `T` (see [`CompassCalibration2d::to_precision`]).
    pub fn to_precision<T: Real>(&self) -> CompassCalibration3dIn<T> {
        CompassCalibration3dIn {
            hard_iron: self.hard_iron.map(T::of),
            soft_iron: self.soft_iron.map(T::of),
        }
    }
}

impl<T: Real> CompassCalibration3dIn<T> {
    /// The corrected field vector in body axes.
    #[inline]
    pub fn correct(&self, raw: &Vector3<T>) -> Vector3<T> {
        self.soft_iron * (raw - self.hard_iron)
    }

    /// Tilt-compensated heading of a raw reading on a body with the given pitch and roll,
    /// radians clockwise from magnetic north, (-π, π]. See [`crate::level_field`].
    #[inline]
    pub fn heading_rad(&self, raw: &Vector3<T>, tilt: &Tilt) -> T {
        tilt_compensated_heading_in(&self.correct(raw), tilt)
    }

    /// Tilt-compensated heading as a [`MagneticHeading`] (see
    /// [`CompassCalibration2d::magnetic_heading`]).
    #[inline]
    pub fn magnetic_heading(&self, raw: &Vector3<T>, tilt: &Tilt) -> MagneticHeading {
        MagneticHeading::new(self.heading_rad(raw, tilt).to_f64())
    }
}

impl Calibration for CompassCalibration3d {
    type Raw = Vector3<f64>;
    type Physical = Vector3<f64>;

    /// Refuses a non-finite reading, and parameters that are not finite or whose soft iron
    /// is singular or reflecting.
    fn apply(&self, raw: &Vector3<f64>) -> Result<Vector3<f64>> {
        check_finite3("magnetometer reading", raw)?;
        self.validate()?;
        Ok(self.correct(raw))
    }
}

impl AbsoluteHeadingSource for CompassCalibration3d {
    type Sample = Mag3Sample;

    /// Tilt-compensated heading; `None` assumes a level body. The dip is measured in the
    /// levelled frame, positive with the field pointing below the horizontal.
    fn heading(&self, sample: &Mag3Sample, tilt: Option<&Tilt>) -> Result<AbsoluteHeading> {
        let level = Tilt::default();
        let tilt = tilt.unwrap_or(&level);
        check_finite("pitch", tilt.pitch_rad)?;
        check_finite("roll", tilt.roll_rad)?;
        let m = level_field(&self.apply(&sample.mag)?, tilt);
        Ok(AbsoluteHeading {
            heading: MagneticHeading::new(heading_from_horizontal(&m.xy())),
            field_norm: m.norm(),
            dip_rad: Some(m.z.atan2(m.xy().norm())),
        })
    }
}

#[cfg(test)]
mod typed_heading_tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::{Declination, angle_diff};

    proptest! {
        #[test]
        fn true_heading_is_magnetic_plus_declination_once(
            heading in -3.0f64..3.0,
            decl in -0.5f64..0.5,
            hx in -50.0f64..50.0,
            hy in -50.0f64..50.0,
            field in 1.0f64..60.0,
        ) {
            let cal = CompassCalibration2d { hard_iron: Vector2::new(hx, hy), soft_iron: Matrix2::identity() };
            // A level compass at magnetic heading ψ reads (H cos ψ, −H sin ψ) + hard iron.
            let raw = Vector2::new(field * heading.cos() + hx, -field * heading.sin() + hy);
            let mag = cal.magnetic_heading(&raw);
            prop_assert!(angle_diff(mag.rad(), heading).abs() < 1e-9);
            let truth = mag.to_true(Declination(decl));
            prop_assert!(angle_diff(truth.rad(), heading + decl).abs() < 1e-9);
        }
    }
}

#[cfg(test)]
mod load_tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A calibration read back from JSON is the one written, and it is refused on load
        /// exactly when its soft iron does not keep the orientation (determinant ≤ 0) or a
        /// number is not finite.
        #[test]
        fn json_load_validates(
            h in prop::array::uniform2(-1e3f64..1e3),
            m in prop::array::uniform4(-2.0f64..2.0),
        ) {
            let c = CompassCalibration2d {
                hard_iron: Vector2::from(h),
                soft_iron: Matrix2::new(m[0], m[1], m[2], m[3]),
            };
            let json = serde_json::to_string(&c).unwrap();
            let back = serde_json::from_str::<CompassCalibration2d>(&json);
            if c.soft_iron.determinant() > 0.0 {
                prop_assert_eq!(back.unwrap(), c);
            } else {
                prop_assert!(back.is_err());
            }
        }
    }

    #[test]
    fn an_all_zero_soft_iron_is_refused_on_load_with_the_reason() {
        let json =
            r#"{"hard_iron":[0.0,0.0,0.0],"soft_iron":[0.0,0.0,0.0,0.0,0.0,0.0,0.0,0.0,0.0]}"#;
        let e = serde_json::from_str::<CompassCalibration3d>(json).unwrap_err();
        assert!(e.to_string().contains("singular or reflecting"), "{e}");
        let ok = serde_json::to_string(&CompassCalibration3d::identity()).unwrap();
        assert_eq!(
            serde_json::from_str::<CompassCalibration3d>(&ok).unwrap(),
            CompassCalibration3d::identity()
        );
    }
}

#[cfg(test)]
mod precision_tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::angle_diff;

    /// Heading error bound of the `f32` path, rad: the readings (up to 150 units) rounded to
    /// `f32` (6·10⁻⁸ relative, 9·10⁻⁶ units) against a horizontal field of at least 10 units
    /// is 9·10⁻⁷ rad, the soft iron's rounding as much again; 10⁻⁵ leaves a factor of 5.
    const F32_HEADING_TOL_RAD: f64 = 1e-5;

    proptest! {
        /// The `f32` calibration gives the `f64` heading to within `f32` rounding, in 2-D
        /// and tilt-compensated in 3-D.
        #[test]
        fn f32_heading_matches_f64(
            heading in -3.1f64..3.1,
            hard in prop::array::uniform3(-50.0f64..50.0),
            field in 10.0f64..60.0,
            stretch in 0.8f64..1.25,
            pitch in -0.5f64..0.5,
            roll in -0.5f64..0.5,
        ) {
            let cal = CompassCalibration2d {
                hard_iron: Vector2::new(hard[0], hard[1]),
                soft_iron: Matrix2::new(stretch, 0.05, 0.05, 1.0 / stretch),
            };
            let raw = cal.soft_iron.try_inverse().unwrap()
                * Vector2::new(field * heading.cos(), -field * heading.sin())
                + cal.hard_iron;
            let single = cal.to_precision::<f32>().heading_rad(&raw.cast::<f32>());
            prop_assert!(
                angle_diff(f64::from(single), cal.heading_rad(&raw)).abs() < F32_HEADING_TOL_RAD
            );

            let cal3 = CompassCalibration3d {
                hard_iron: Vector3::from(hard),
                soft_iron: Matrix3::from_diagonal(&Vector3::new(stretch, 1.0, 1.0 / stretch)),
            };
            let tilt = Tilt { pitch_rad: pitch, roll_rad: roll };
            // The body reading whose levelled field is (H cos ψ, −H sin ψ, H/2).
            let level = Vector3::new(field * heading.cos(), -field * heading.sin(), 0.5 * field);
            let undo_tilt = nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), pitch)
                * nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), roll);
            let raw3 = cal3.soft_iron.try_inverse().unwrap() * (undo_tilt.transpose() * level)
                + cal3.hard_iron;
            let double = cal3.heading_rad(&raw3, &tilt);
            let single = cal3.to_precision::<f32>().heading_rad(&raw3.cast::<f32>(), &tilt);
            prop_assert!(angle_diff(f64::from(single), double).abs() < F32_HEADING_TOL_RAD);
        }
    }
}
