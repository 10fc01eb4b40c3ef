//! A stored compass calibration of any kind, and the heading it gives a raw reading:
//! [`CompassCalibration`], the one place where a calibration file's two-axis, three-axis or
//! joint magnetometer + accelerometer calibration becomes a heading, level or
//! tilt-compensated. The `truenorth heading` command and the Python package's
//! `Calibration.heading` both stand on it.
//!
//! ```
//! use nalgebra::{Matrix2, Vector2, Vector3};
//! use truenorth::CompassCalibration;
//! use truenorth::compass::CompassCalibration2d;
//!
//! let cal = CompassCalibration::TwoD(CompassCalibration2d {
//!     hard_iron: Vector2::new(8.0, -3.0),
//!     soft_iron: Matrix2::identity(),
//! });
//! // A level compass reads mag_x = H cos ψ, mag_y = −H sin ψ: here ψ = 90° (east).
//! let (heading, tilt) = cal.heading(&Vector3::new(8.0, -23.0, f64::NAN), None)?;
//! assert!((heading.rad() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
//! assert!(tilt.is_none());
//! # Ok::<(), truenorth::core::Error>(())
//! ```

use nalgebra::{Vector2, Vector3};
use truenorth_accel::static_tilt;
use truenorth_calib::MagAccelCalibration;
use truenorth_compass::{CompassCalibration2d, CompassCalibration3d, tilt_compensated_heading};
use truenorth_core::{MagneticHeading, Result, Tilt};

/// A compass calibration as a calibration file stores it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CompassCalibration {
    /// A two-axis compass.
    TwoD(CompassCalibration2d),
    /// A three-axis magnetometer.
    ThreeD(CompassCalibration3d),
    /// A magnetometer and an accelerometer calibrated together, with the rotation between
    /// them.
    Joint(MagAccelCalibration),
}

impl CompassCalibration {
    /// 2 or 3: the magnetometer axes it calibrates.
    pub fn dimensions(&self) -> usize {
        match self {
            Self::TwoD(_) => 2,
            Self::ThreeD(_) | Self::Joint(_) => 3,
        }
    }

    /// The magnitude of the raw reading `mag` corrected by the calibration (a two-axis
    /// calibration reads x and y only): near the calibration's field, whatever the
    /// heading, when the calibration describes the sensor.
    pub fn corrected_magnitude(&self, mag: &Vector3<f64>) -> f64 {
        match self {
            Self::TwoD(c) => c.correct(&Vector2::new(mag.x, mag.y)).norm(),
            Self::ThreeD(c) => c.correct(mag).norm(),
            Self::Joint(c) => c.field_body(mag).norm(),
        }
    }

    /// The magnetic heading of the raw reading `mag` (input unit; a two-axis calibration
    /// reads x and y only), and the tilt when a three-axis calibration is given `acc`
    /// (specific force, any unit; the joint calibration corrects and aligns it first):
    /// tilt-compensated then, else for a level sensor. A reading the calibration cannot
    /// use (an accelerometer that gives no tilt) is a typed error.
    pub fn heading(
        &self,
        mag: &Vector3<f64>,
        acc: Option<&Vector3<f64>>,
    ) -> Result<(MagneticHeading, Option<Tilt>)> {
        Ok(match (self, acc) {
            (Self::TwoD(c), _) => (c.magnetic_heading(&Vector2::new(mag.x, mag.y)), None),
            (Self::ThreeD(c), Some(a)) => {
                let tilt = static_tilt(a)?;
                (c.magnetic_heading(mag, &tilt), Some(tilt))
            }
            // Level: zero pitch and roll, i.e. the corrected x and y.
            (Self::ThreeD(c), None) => (c.magnetic_heading(mag, &Tilt::default()), None),
            (Self::Joint(c), Some(a)) => {
                let (h, tilt) = c.attitude(mag, a)?;
                (h, Some(tilt))
            }
            (Self::Joint(c), None) => {
                let level = tilt_compensated_heading(&c.field_body(mag), &Tilt::default());
                (MagneticHeading::new(level), None)
            }
        })
    }
}
