//! Compass calibration parameters and heading from a calibrated reading.

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_core::{
    AbsoluteHeadingSource, Calibration, Mag2Sample, MagneticHeading, Result, Tilt, check_finite2,
};

use crate::tilt_compensated_heading;

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Heading (radians, clockwise from magnetic north, (-π, π]) of a horizontal field vector in
/// body axes (x forward, y right): `ψ = atan2(−h_y, h_x)`.
#[inline]
pub fn heading_from_horizontal(h: &Vector2<f64>) -> f64 {
    (-h.y).atan2(h.x)
}

/// A two-axis compass calibration: `corrected = soft_iron · (raw − hard_iron)`.
///
/// `hard_iron` is the centre of the raw locus (the vehicle's permanent magnetisation plus
/// sensor offsets); `soft_iron` maps the raw ellipse onto a circle whose radius is the
/// horizontal field in the input unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CompassCalibration2d {
    /// Offset to subtract from raw readings, input unit.
    pub hard_iron: Vector2<f64>,
    /// Matrix that turns the centred ellipse into a circle.
    pub soft_iron: Matrix2<f64>,
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

    /// The corrected horizontal field.
    #[inline]
    pub fn correct(&self, raw: &Vector2<f64>) -> Vector2<f64> {
        self.soft_iron * (raw - self.hard_iron)
    }

    /// Heading of a raw reading, radians clockwise from magnetic north, (-π, π].
    #[inline]
    pub fn heading_rad(&self, raw: &Vector2<f64>) -> f64 {
        heading_from_horizontal(&self.correct(raw))
    }

    /// Heading of a raw reading as a [`MagneticHeading`]: the typed form that turns into a
    /// true heading only through [`MagneticHeading::to_true`], so declination is added once.
    #[inline]
    pub fn magnetic_heading(&self, raw: &Vector2<f64>) -> MagneticHeading {
        MagneticHeading::new(self.heading_rad(raw))
    }
}

impl Calibration for CompassCalibration2d {
    type Raw = Vector2<f64>;
    type Physical = Vector2<f64>;

    fn apply(&self, raw: &Vector2<f64>) -> Vector2<f64> {
        self.correct(raw)
    }
}

impl AbsoluteHeadingSource for CompassCalibration2d {
    type Sample = Mag2Sample;

    fn heading_rad(&self, sample: &Mag2Sample) -> Result<f64> {
        check_finite2("magnetometer reading", &sample.mag)?;
        Ok(CompassCalibration2d::heading_rad(self, &sample.mag))
    }
}

/// A three-axis magnetometer calibration: `corrected = soft_iron · (raw − hard_iron)`, with
/// `soft_iron` symmetric positive definite, mapping the raw ellipsoid onto a sphere whose
/// radius is the total field in the input unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CompassCalibration3d {
    /// Offset to subtract from raw readings, input unit.
    pub hard_iron: Vector3<f64>,
    /// Matrix that turns the centred ellipsoid into a sphere.
    pub soft_iron: Matrix3<f64>,
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

    /// The corrected field vector in body axes.
    #[inline]
    pub fn correct(&self, raw: &Vector3<f64>) -> Vector3<f64> {
        self.soft_iron * (raw - self.hard_iron)
    }

    /// Tilt-compensated heading of a raw reading on a body with the given pitch and roll,
    /// radians clockwise from magnetic north, (-π, π]. See [`crate::level_field`].
    #[inline]
    pub fn heading_rad(&self, raw: &Vector3<f64>, tilt: &Tilt) -> f64 {
        tilt_compensated_heading(&self.correct(raw), tilt)
    }

    /// Tilt-compensated heading as a [`MagneticHeading`] (see
    /// [`CompassCalibration2d::magnetic_heading`]).
    #[inline]
    pub fn magnetic_heading(&self, raw: &Vector3<f64>, tilt: &Tilt) -> MagneticHeading {
        MagneticHeading::new(self.heading_rad(raw, tilt))
    }
}

impl Calibration for CompassCalibration3d {
    type Raw = Vector3<f64>;
    type Physical = Vector3<f64>;

    fn apply(&self, raw: &Vector3<f64>) -> Vector3<f64> {
        self.correct(raw)
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
