//! The calibration file written by `truenorth calibrate` and read by `truenorth heading`:
//! its JSON layout, and the checks a file must pass before it is used.

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::{Matrix3, Vector2, Vector3};
use truenorth::CompassCalibration;
use truenorth::accel::AccelTriadCalibration;
use truenorth::calib::MagAccelCalibration;
use truenorth::checks::compass::check_compass;
use truenorth::compass::{CompassCalibration2d, CompassCalibration3d};
use truenorth::core::{CompassQuality, Validate};

use super::json::{parse_json, parse_value, read_json_text, version_of};
use crate::io::writing::atomic_write::write_atomically;
use crate::io::{CliError, CliResult};

/// The `format` tag of a calibration file written by `truenorth calibrate`.
pub const CALIBRATION_FORMAT: &str = "truenorth-compass-calibration";

/// The version of the calibration file layout written: 2 adds the units block, the verdict,
/// the predicted uncertainties and the accelerometer part, and drops
/// `quality.field_magnitude` (the same number as `field`). The optional `gyro` part came
/// later within version 2: a reader that does not know it skips it, and a file without it
/// reads as before.
pub const CALIBRATION_VERSION: u32 = 2;

/// The layout versions this build reads.
pub const READABLE_VERSIONS: [u32; 2] = [1, 2];

/// A compass calibration as stored on disk by `truenorth calibrate` and read by
/// `truenorth heading` (see `truenorth calibrate --help` for the layout).
///
/// Matrices are written row by row (`soft_iron[i][j]` is row i, column j) so the file reads
/// as printed maths; `corrected = soft_iron · (raw − hard_iron)`.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationFile {
    /// Always [`CALIBRATION_FORMAT`].
    pub format: String,
    /// Layout version, [`CALIBRATION_VERSION`].
    pub version: u32,
    /// The method that produced it (`ellipse`, `ellipsoid`, …).
    pub method: String,
    /// 2 (mag_x, mag_y) or 3 (mag_x, mag_y, mag_z).
    pub dimensions: usize,
    /// What every number is in and means.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub units: BTreeMap<String, String>,
    /// Offset subtracted from raw readings, input unit; `dimensions` values.
    pub hard_iron: Vec<f64>,
    /// Soft-iron matrix, `dimensions` rows of `dimensions` values.
    pub soft_iron: Vec<Vec<f64>>,
    /// Radius of the calibrated circle (2-D: horizontal field) or sphere (3-D: total
    /// field), input unit.
    pub field: f64,
    /// Rotation from the magnetometer's calibrated axes into the body axes (joint
    /// calibration only), 3 rows of 3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mag_to_body: Option<Vec<Vec<f64>>>,
    /// The accelerometer (joint calibration only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accelerometer: Option<AccelPart>,
    /// Inclination of the field measured by a joint calibration, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dip_deg: Option<f64>,
    /// How far the calibration can be trusted (written by `calibrate`; ignored by
    /// `heading`, so a hand-written file may leave it out).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quality: Option<QualityReport>,
    /// The yaw gyro calibrated by the same turn (`turn` with `gyr_z` only). Not used by
    /// `heading`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro: Option<GyroPart>,
    /// The recording it was fitted to (informational).
    #[serde(default)]
    pub input: String,
}

/// The accelerometer part of a joint calibration:
/// `specific_force_mps2 = matrix · (raw − bias)`, in body axes.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccelPart {
    /// Bias, accelerometer input unit.
    pub bias: Vec<f64>,
    /// Input unit → m/s² (scale, cross-axis, and the rotation onto the body axes), 3 rows
    /// of 3.
    pub matrix: Vec<Vec<f64>>,
    /// Gravity in the accelerometer's input unit (1 for g, 9.81 for m/s²).
    pub gravity: f64,
}

/// The yaw gyro's calibration from one turn (EP 0640207 claims 1, 6-9):
/// `rate_rps = (gyr_z − zero_rps) / scale`, positive turning right.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GyroPart {
    /// The gyro's reading at rest, rad/s: its mean over the standstill before the turn.
    pub zero_rps: f64,
    /// Raw rate per true rate (the conversion constant), from the integrated rate between
    /// compass extrema half a turn apart; measured in the direction turned.
    pub scale: f64,
    /// 1σ of `zero_rps`, rad/s, from the spread of the standstill.
    pub zero_sigma_rps: Option<f64>,
    /// 1σ of `scale` from the spread of the half-turn pairs (0 with one pair per axis).
    pub scale_sigma: Option<f64>,
    /// Length of the standstill the zero came from, s.
    pub rest_s: f64,
    /// Half-turn pairs behind the scale on the X and the Y axis.
    pub pairs: [usize; 2],
    /// Angle turned, degrees, positive right.
    pub turned_deg: f64,
}

/// The quality report as written to a calibration file: the library's
/// [`CompassQuality`], flattened, with its verdict and what the readings determine. A
/// number that is not finite (an unbounded condition or error bound) is written as `null`,
/// since JSON has no infinity.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QualityReport {
    /// `good`, `usable` or `poor`.
    #[serde(default)]
    pub verdict: String,
    /// Which number decided the verdict.
    #[serde(default)]
    pub verdict_reason: String,
    /// What kept the calibration from a better verdict: `none` (it is `good`),
    /// `calibration` (its own bound: a better recording helps) or `noise` (the per-reading
    /// noise alone: the calibration is within the grade's bound; averaging readings helps).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verdict_cause: Option<String>,
    /// Samples used in the solve.
    pub points: usize,
    /// 2-D: share of 10° heading bins that hold data; 3-D: information share of an evenly
    /// covered sphere, in [0, 1].
    pub coverage: f64,
    /// RMS of |corrected| / field − 1.
    pub residual_rms_rel: Option<f64>,
    /// Condition number of the calibration's information matrix.
    pub condition: Option<f64>,
    /// Dilution of the orientations seen, each direction once: heading error per unit of
    /// per-reading error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometry_dilution: Option<f64>,
    /// Bound on the heading (3-D: field direction) error the calibration itself adds,
    /// degrees: `heading_error_3sigma_deg + heading_error_systematic_deg`.
    pub heading_error_bound_deg: Option<f64>,
    /// Three standard deviations of the heading error from the uncertainty of the fitted
    /// parameters, degrees.
    #[serde(default)]
    pub heading_error_3sigma_deg: Option<f64>,
    /// Heading error the method's model leaves whatever the data, degrees.
    #[serde(default)]
    pub heading_error_systematic_deg: Option<f64>,
    /// RMS heading noise of one calibrated reading, degrees.
    #[serde(default)]
    pub heading_noise_rms_deg: Option<f64>,
    /// Predicted 1σ of each hard-iron component, input unit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hard_iron_sigma: Option<Vec<Option<f64>>>,
    /// Predicted 1σ of the least determined soft-iron entry, relative.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub soft_iron_sigma_rel: Option<f64>,
    /// Fitted field over the expected one, if one was given.
    pub field_ratio_to_expected: Option<f64>,
    /// Joint calibration: RMS of |specific force|/g − 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accel_residual_rms_rel: Option<f64>,
    /// Joint calibration: predicted 1σ of each accelerometer bias component, its input unit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accel_bias_sigma: Option<Vec<Option<f64>>>,
    /// Joint calibration: RMS spread of the dip over the readings, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dip_spread_deg: Option<f64>,
    /// Joint calibration: angle between the magnetometer's and the accelerometer's
    /// calibrated frames, degrees, and its predicted 1σ.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alignment_deg: Option<f64>,
    /// See `alignment_deg`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alignment_sigma_deg: Option<f64>,
    /// Joint calibration: runs of shots aimed at one target that were found, and their
    /// shots.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runs: Option<usize>,
    /// Layout version 1 only: the fitted field, the same number as the file's `field`
    /// (read so that version-1 files keep loading, never written).
    #[serde(default, skip_serializing)]
    pub field_magnitude: Option<f64>,
    /// See `runs`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub run_shots: Option<usize>,
    /// Joint calibration: angle between the pointing axis the runs found and the
    /// accelerometer's x axis, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pointing_offset_deg: Option<f64>,
    /// Joint calibration: RMS scatter of the runs' pointing directions, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aim_rms_deg: Option<f64>,
}

/// A number JSON can hold: `None` for infinity and NaN.
pub fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

impl QualityReport {
    /// The report of a 2-D or 3-D calibration, what its readings determine and its
    /// verdict, all as the calibrator computed them.
    pub fn new(q: &CompassQuality, dimensions: usize) -> Self {
        let (v, u) = (q.verdict(), &q.uncertainty);
        Self {
            verdict: v.grade.to_string(),
            verdict_reason: v.to_string(),
            verdict_cause: Some(v.cause.to_string()),
            points: q.fit.points,
            coverage: q.fit.coverage,
            residual_rms_rel: finite(q.fit.residual_rms_rel),
            condition: finite(q.fit.condition),
            geometry_dilution: finite(u.dilution),
            heading_error_bound_deg: finite(q.heading_error_bound_deg()),
            heading_error_3sigma_deg: finite(q.heading_error_3sigma_deg),
            heading_error_systematic_deg: finite(q.heading_error_systematic_deg),
            heading_noise_rms_deg: finite(q.heading_noise_rms_deg),
            hard_iron_sigma: Some(
                u.hard_iron_sigma[..dimensions]
                    .iter()
                    .map(|&s| finite(s))
                    .collect(),
            ),
            soft_iron_sigma_rel: finite(u.soft_iron_sigma_rel),
            field_ratio_to_expected: q.field_ratio_to_expected.and_then(finite),
            ..Self::default()
        }
    }
}

/// The units block written with every calibration: what each number is in and means.
pub fn units_block(joint: bool) -> BTreeMap<String, String> {
    let mut u: Vec<(&str, &str)> = vec![
        ("hard_iron", "magnetometer input unit"),
        (
            "soft_iron",
            "dimensionless: corrected = soft_iron * (raw - hard_iron), a circle (sphere) of radius field",
        ),
        (
            "field",
            "magnetometer input unit (2-D: horizontal field; 3-D: total field)",
        ),
        (
            "quality.coverage",
            "fraction in [0, 1] (2-D: of 10-degree heading bins filled; 3-D: information share of an evenly covered sphere)",
        ),
        ("quality.residual_rms_rel", "fraction of the field"),
        (
            "quality.condition",
            "dimensionless (2 for an even circle, 2.5 for an even sphere)",
        ),
        (
            "quality.geometry_dilution",
            "radians of heading per unit of per-reading error relative to the field, times the square root of the directions seen, each 0.5-degree (2-D) or equal-area (3-D) direction cell counted once (2 for an even circle, 3.67 for an even sphere)",
        ),
        (
            "quality.heading_error_bound_deg",
            "degrees: bound on the heading error the calibration itself adds to every heading, 3 sigma of the parameter uncertainty plus the method's systematic error; per-reading noise (heading_noise_rms_deg) comes on top",
        ),
        ("quality.heading_error_3sigma_deg", "degrees, 3 sigma"),
        (
            "quality.heading_error_systematic_deg",
            "degrees, worst over heading",
        ),
        ("quality.heading_noise_rms_deg", "degrees RMS per reading"),
        (
            "quality.hard_iron_sigma",
            "magnetometer input unit, 1 sigma",
        ),
        ("quality.soft_iron_sigma_rel", "fraction, 1 sigma"),
        ("quality.field_ratio_to_expected", "dimensionless"),
    ];
    if joint {
        u.extend([
            ("mag_to_body", "rotation matrix: field_body = mag_to_body * soft_iron * (raw - hard_iron)"),
            ("accelerometer.bias", "accelerometer input unit"),
            ("accelerometer.matrix", "m/s^2 per accelerometer input unit: specific_force_body = matrix * (raw - bias)"),
            ("accelerometer.gravity", "accelerometer input unit"),
            ("dip_deg", "degrees below the horizontal"),
            ("quality.heading_error_bound_deg", "degrees: 3 sigma bound on the heading error of the body x axis the calibration adds, from every parameter's uncertainty (both sensors, the alignment, the pointing axis), worst over pitch within 60 degrees and any roll and heading"),
            ("quality.accel_residual_rms_rel", "fraction of gravity"),
            ("quality.accel_bias_sigma", "accelerometer input unit, 1 sigma"),
            ("quality.dip_spread_deg", "degrees RMS"),
            ("quality.alignment_deg", "degrees"),
            ("quality.alignment_sigma_deg", "degrees, 1 sigma"),
            ("quality.pointing_offset_deg", "degrees"),
            ("quality.aim_rms_deg", "degrees RMS"),
        ]);
    }
    u.into_iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

/// The units block's entries for [`GyroPart`].
pub fn gyro_units() -> BTreeMap<String, String> {
    [
        ("gyro.zero_rps", "rad/s: the gyro's reading at rest"),
        (
            "gyro.scale",
            "raw rad/s per true rad/s: rate = (gyr_z - zero_rps) / scale, positive turning right",
        ),
        ("gyro.zero_sigma_rps", "rad/s, 1 sigma"),
        ("gyro.scale_sigma", "dimensionless, 1 sigma"),
        ("gyro.rest_s", "seconds of standstill behind zero_rps"),
        ("gyro.pairs", "half-turn pairs of compass extrema, X and Y"),
        ("gyro.turned_deg", "degrees turned, positive right"),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v.to_string()))
    .collect()
}

/// A matrix written row by row, checked to be `n` × `n`.
fn rows<const N: usize>(
    what: &str,
    m: &[Vec<f64>],
) -> Result<nalgebra::SMatrix<f64, N, N>, String> {
    if m.len() != N || m.iter().any(|r| r.len() != N) {
        return Err(format!("`{what}` must have {N} rows of {N} values"));
    }
    if m.iter().flatten().any(|v| !v.is_finite()) {
        return Err(format!("`{what}` must be finite numbers"));
    }
    Ok(nalgebra::SMatrix::<f64, N, N>::from_fn(|i, j| m[i][j]))
}

impl CalibrationFile {
    /// Writes the file as pretty-printed JSON (whole or not at all; `-`: standard output).
    pub fn write(&self, path: &Path) -> CliResult {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| CliError::file(path, format!("cannot encode the calibration: {e}")))?;
        write_atomically(path, |f| {
            f.write_all((text + "\n").as_bytes())?;
            Ok(())
        })
    }

    /// Reads and checks a calibration file (`-`: standard input, gzip or not; a
    /// byte-order mark is skipped): the layout version, no unknown key, and the values
    /// against physics ([`CalibrationFile::check`]).
    pub fn read(path: &Path) -> CliResult<(Self, CompassCalibration)> {
        let (text, name) = read_json_text(path)?;
        let not_one = "not a truenorth calibration file (write one with `truenorth calibrate`)";
        let value = parse_value(&text, not_one).map_err(|m| CliError::file(&name, m))?;
        match version_of(&value, &READABLE_VERSIONS, "calibration") {
            Ok(Some(_)) => {}
            Ok(None) => {
                return Err(CliError::file(
                    &name,
                    format!(
                        "{not_one}: it has no `version` (every calibration file carries one; this build reads versions {READABLE_VERSIONS:?})"
                    ),
                ));
            }
            Err(m) => return Err(CliError::file(&name, m)),
        }
        let file: Self = parse_json(value, not_one).map_err(|m| CliError::file(&name, m))?;
        let cal = file.check().map_err(|m| CliError::file(&name, m))?;
        Ok((file, cal))
    }

    /// The typed calibration, or what is wrong with the file.
    pub fn check(&self) -> Result<CompassCalibration, String> {
        if self.format != CALIBRATION_FORMAT {
            return Err(format!(
                "`format` is `{}`, expected `{CALIBRATION_FORMAT}`",
                self.format
            ));
        }
        if !READABLE_VERSIONS.contains(&self.version) {
            return Err(format!(
                "layout version {} is not supported (this build reads versions {READABLE_VERSIONS:?})",
                self.version
            ));
        }
        let n = self.dimensions;
        if n != 2 && n != 3 {
            return Err(format!("`dimensions` is {n}, must be 2 or 3"));
        }
        if self.hard_iron.len() != n {
            return Err(format!(
                "`hard_iron` must have {n} values and `soft_iron` {n} rows of {n} values"
            ));
        }
        if n == 2 {
            if self.mag_to_body.is_some() || self.accelerometer.is_some() {
                return Err("a 2-D calibration has no `mag_to_body` or `accelerometer`".into());
            }
            let s = rows::<2>("soft_iron", &self.soft_iron)?;
            check_compass(
                &self.hard_iron,
                s.determinant(),
                s.singular_values().as_slice(),
                self.field,
            )?;
            return Ok(CompassCalibration::TwoD(CompassCalibration2d {
                hard_iron: Vector2::new(self.hard_iron[0], self.hard_iron[1]),
                soft_iron: s,
            }));
        }
        let s: Matrix3<f64> = rows::<3>("soft_iron", &self.soft_iron)?;
        check_compass(
            &self.hard_iron,
            s.determinant(),
            s.singular_values().as_slice(),
            self.field,
        )?;
        let mag = CompassCalibration3d {
            hard_iron: Vector3::new(self.hard_iron[0], self.hard_iron[1], self.hard_iron[2]),
            soft_iron: s,
        };
        match (&self.mag_to_body, &self.accelerometer) {
            (None, None) => Ok(CompassCalibration::ThreeD(mag)),
            (Some(r), Some(a)) => {
                let r = rows::<3>("mag_to_body", r)?;
                let m = rows::<3>("accelerometer.matrix", &a.matrix)?;
                if a.bias.len() != 3 || a.bias.iter().any(|v| !v.is_finite()) {
                    return Err("`accelerometer.bias` must be 3 finite numbers".into());
                }
                let joint = MagAccelCalibration {
                    mag,
                    mag_to_body: r,
                    accel: AccelTriadCalibration {
                        bias: Vector3::new(a.bias[0], a.bias[1], a.bias[2]),
                        matrix: m,
                    },
                    field: self.field,
                    gravity: a.gravity,
                    dip_rad: self.dip_deg.unwrap_or(0.0).to_radians(),
                };
                joint
                    .validate()
                    .map_err(|e| format!("the joint calibration is invalid: {e}"))?;
                Ok(CompassCalibration::Joint(joint))
            }
            _ => Err("a joint calibration needs both `mag_to_body` and `accelerometer`".into()),
        }
    }
}

/// Rows of a matrix as nested vectors (the file's layout).
pub fn matrix_rows<const R: usize, const C: usize>(
    m: &nalgebra::SMatrix<f64, R, C>,
) -> Vec<Vec<f64>> {
    m.row_iter().map(|r| r.iter().copied().collect()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(dims: usize, soft: Vec<Vec<f64>>) -> CalibrationFile {
        CalibrationFile {
            format: CALIBRATION_FORMAT.into(),
            version: 1,
            method: "hand".into(),
            dimensions: dims,
            units: BTreeMap::new(),
            hard_iron: vec![0.0; dims],
            soft_iron: soft,
            field: 1.0,
            mag_to_body: None,
            accelerometer: None,
            dip_deg: None,
            gyro: None,
            quality: None,
            input: String::new(),
        }
    }

    /// Each way a soft iron can ruin the headings is refused on load, with the reason.
    #[test]
    fn useless_soft_irons_are_refused() {
        let cases = [
            (vec![vec![0.0, 0.0], vec![0.0, 0.0]], "determinant"),
            (vec![vec![1.0, 2.0], vec![2.0, 4.0]], "determinant"),
            (vec![vec![1.0, 0.0], vec![0.0, -1.0]], "determinant"),
            (vec![vec![1.0, 0.0], vec![0.0, 0.01]], "condition number"),
            (vec![vec![1.0, f64::NAN], vec![0.0, 1.0]], "finite"),
            (vec![vec![1.0, 0.0]], "rows"),
        ];
        for (soft, why) in cases {
            let e = file(2, soft.clone()).check().unwrap_err();
            assert!(e.contains(why), "{soft:?}: {e}");
        }
        assert!(
            file(2, vec![vec![1.1, 0.1], vec![0.1, 0.9]])
                .check()
                .is_ok()
        );
        let mut v9 = file(2, vec![vec![1.0, 0.0], vec![0.0, 1.0]]);
        v9.version = 9;
        assert!(v9.check().unwrap_err().contains("version 9"));
        let mut neg = file(
            3,
            vec![
                vec![1.0, 0.0, 0.0],
                vec![0.0, 1.0, 0.0],
                vec![0.0, 0.0, 1.0],
            ],
        );
        neg.field = -1.0;
        assert!(neg.check().unwrap_err().contains("field"));
    }
}
