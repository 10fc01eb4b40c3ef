//! The calibration file written by `truenorth calibrate` and read by `truenorth heading`:
//! its JSON layout, and the checks a file must pass before it is used.

use std::path::Path;

use super::atomic_write::write_atomically;
use super::{CliError, CliResult};

/// The `format` tag of a calibration file written by `truenorth calibrate`.
pub const CALIBRATION_FORMAT: &str = "truenorth-compass-calibration";

/// The version of the calibration file layout.
pub const CALIBRATION_VERSION: u32 = 1;

/// A compass calibration as stored on disk by `truenorth calibrate` and read by
/// `truenorth heading` (see `truenorth calibrate --help` for the layout).
///
/// Matrices are written row by row (`soft_iron[i][j]` is row i, column j) so the file reads
/// as printed maths; `corrected = soft_iron · (raw − hard_iron)`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct CalibrationFile {
    /// Always [`CALIBRATION_FORMAT`].
    pub format: String,
    /// Layout version, [`CALIBRATION_VERSION`].
    pub version: u32,
    /// The method that produced it (`ellipse`, `ellipsoid`, …).
    pub method: String,
    /// 2 (mag_x, mag_y) or 3 (mag_x, mag_y, mag_z).
    pub dimensions: usize,
    /// Offset subtracted from raw readings, input unit; `dimensions` values.
    pub hard_iron: Vec<f64>,
    /// Soft-iron matrix, `dimensions` rows of `dimensions` values.
    pub soft_iron: Vec<Vec<f64>>,
    /// Radius of the calibrated circle (2-D: horizontal field) or sphere (3-D: total
    /// field), input unit.
    pub field: f64,
    /// How far the calibration can be trusted (written by `calibrate`; ignored by
    /// `heading`, so a hand-written file may leave it out).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quality: Option<QualityReport>,
    /// The recording it was fitted to (informational).
    #[serde(default)]
    pub input: String,
}

/// The quality report as written to a calibration file: the library's
/// [`truenorth::core::CompassQuality`], flattened, with a number that is not finite (an
/// unbounded condition or error bound) written as `null`, since JSON has no infinity.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct QualityReport {
    /// Samples used in the solve.
    pub points: usize,
    /// Share of heading bins (3-D: direction cells) that hold data, in [0, 1].
    pub coverage: f64,
    /// RMS of |corrected| / field − 1.
    pub residual_rms_rel: Option<f64>,
    /// Condition number of the calibration's information matrix.
    pub condition: Option<f64>,
    /// Bound on the heading (3-D: field direction) error the calibration itself adds,
    /// degrees: `heading_error_3sigma_deg + heading_error_systematic_deg`. Per-reading
    /// noise (`heading_noise_rms_deg`) comes on top.
    pub heading_error_bound_deg: Option<f64>,
    /// Three standard deviations of the heading error from the uncertainty of the fitted
    /// parameters, degrees.
    #[serde(default)]
    pub heading_error_3sigma_deg: Option<f64>,
    /// Heading error the method's model leaves whatever the data (e.g. a rotated soft iron
    /// under a circle-only method), degrees.
    #[serde(default)]
    pub heading_error_systematic_deg: Option<f64>,
    /// RMS heading noise of one calibrated reading, from the residuals, degrees.
    #[serde(default)]
    pub heading_noise_rms_deg: Option<f64>,
    /// Fitted field, input unit.
    pub field_magnitude: Option<f64>,
    /// Fitted field over the expected one, if `--expected-field` was given.
    pub field_ratio_to_expected: Option<f64>,
}

impl From<truenorth::core::CompassQuality> for QualityReport {
    fn from(q: truenorth::core::CompassQuality) -> Self {
        let finite = |v: f64| v.is_finite().then_some(v);
        Self {
            points: q.fit.points,
            coverage: q.fit.coverage,
            residual_rms_rel: finite(q.fit.residual_rms_rel),
            condition: finite(q.fit.condition),
            heading_error_bound_deg: finite(q.heading_error_bound_deg()),
            heading_error_3sigma_deg: finite(q.heading_error_3sigma_deg),
            heading_error_systematic_deg: finite(q.heading_error_systematic_deg),
            heading_noise_rms_deg: finite(q.heading_noise_rms_deg),
            field_magnitude: finite(q.field_magnitude),
            field_ratio_to_expected: q.field_ratio_to_expected.and_then(finite),
        }
    }
}

/// A calibration read from a [`CalibrationFile`], checked and typed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CompassCalibration {
    /// Two-axis compass.
    TwoD(truenorth::compass::CompassCalibration2d),
    /// Three-axis magnetometer.
    ThreeD(truenorth::compass::CompassCalibration3d),
}

impl CalibrationFile {
    /// Writes the file as pretty-printed JSON (whole or not at all, see
    /// [`write_atomically`]).
    pub fn write(&self, path: &Path) -> CliResult {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| CliError::file(path, format!("cannot encode the calibration: {e}")))?;
        write_atomically(path, |f| {
            f.write_all((text + "\n").as_bytes())?;
            Ok(())
        })
    }

    /// Reads and checks a calibration file.
    pub fn read(path: &Path) -> CliResult<(Self, CompassCalibration)> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| CliError::file(path, format!("cannot read: {e}")))?;
        let file: Self = serde_json::from_str(&text).map_err(|e| {
            CliError::file(
                path,
                format!(
                    "not a truenorth calibration file (write one with `truenorth calibrate`): {e}"
                ),
            )
        })?;
        let cal = file.check().map_err(|m| CliError::file(path, m))?;
        Ok((file, cal))
    }

    /// The typed calibration, or what is wrong with the file.
    fn check(&self) -> Result<CompassCalibration, String> {
        use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
        if self.format != CALIBRATION_FORMAT {
            return Err(format!(
                "`format` is `{}`, expected `{CALIBRATION_FORMAT}`",
                self.format
            ));
        }
        if self.version != CALIBRATION_VERSION {
            return Err(format!(
                "layout version {} is not supported (this build reads version {CALIBRATION_VERSION})",
                self.version
            ));
        }
        let n = self.dimensions;
        if n != 2 && n != 3 {
            return Err(format!("`dimensions` is {n}, must be 2 or 3"));
        }
        if self.hard_iron.len() != n
            || self.soft_iron.len() != n
            || self.soft_iron.iter().any(|r| r.len() != n)
        {
            return Err(format!(
                "`hard_iron` must have {n} values and `soft_iron` {n} rows of {n} values"
            ));
        }
        let all = self.hard_iron.iter().chain(self.soft_iron.iter().flatten());
        if all.clone().any(|v| !v.is_finite()) {
            return Err("`hard_iron` and `soft_iron` must be finite numbers".into());
        }
        let s = &self.soft_iron;
        Ok(if n == 2 {
            CompassCalibration::TwoD(truenorth::compass::CompassCalibration2d {
                hard_iron: Vector2::new(self.hard_iron[0], self.hard_iron[1]),
                soft_iron: Matrix2::new(s[0][0], s[0][1], s[1][0], s[1][1]),
            })
        } else {
            CompassCalibration::ThreeD(truenorth::compass::CompassCalibration3d {
                hard_iron: Vector3::new(self.hard_iron[0], self.hard_iron[1], self.hard_iron[2]),
                soft_iron: Matrix3::new(
                    s[0][0], s[0][1], s[0][2], s[1][0], s[1][1], s[1][2], s[2][0], s[2][1], s[2][2],
                ),
            })
        })
    }
}
