//! CSV and JSON input/output shared by the subcommands, with errors that name the file, the
//! row and the problem.

use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};

/// A command-line error: one line for stderr.
#[derive(Debug)]
pub struct CliError {
    /// The file concerned, if any.
    pub file: Option<PathBuf>,
    /// The 1-based data row (header = row 1), if any.
    pub row: Option<usize>,
    /// What was wrong.
    pub message: String,
}

impl CliError {
    /// An error not tied to a file.
    pub fn msg(message: impl Into<String>) -> Self {
        Self {
            file: None,
            row: None,
            message: message.into(),
        }
    }

    /// An error about a file.
    pub fn file(file: &Path, message: impl Into<String>) -> Self {
        Self {
            file: Some(file.to_path_buf()),
            row: None,
            message: message.into(),
        }
    }

    /// An error about one row of a file.
    pub fn row(file: &Path, row: usize, message: impl Into<String>) -> Self {
        Self {
            file: Some(file.to_path_buf()),
            row: Some(row),
            message: message.into(),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (&self.file, self.row) {
            (Some(p), Some(r)) => write!(f, "{}: row {}: {}", p.display(), r, self.message),
            (Some(p), None) => write!(f, "{}: {}", p.display(), self.message),
            _ => write!(f, "{}", self.message),
        }
    }
}

/// Result with [`CliError`].
pub type CliResult<T = ()> = Result<T, CliError>;

/// A numeric CSV table read by column name. Extra columns are ignored.
#[derive(Debug, Clone)]
pub struct Table {
    /// The file it came from.
    pub path: PathBuf,
    columns: HashMap<String, Vec<f64>>,
    rows: usize,
}

impl Table {
    /// Reads `path`, keeping the `required` columns (error if missing) and any `optional`
    /// ones present. Every kept cell must parse as a number; an empty optional cell is NaN.
    pub fn read(path: &Path, required: &[&str], optional: &[&str]) -> CliResult<Self> {
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_path(path)
            .map_err(|e| CliError::file(path, format!("cannot open: {e}")))?;
        let headers = rdr
            .headers()
            .map_err(|e| CliError::row(path, 1, format!("cannot read the header: {e}")))?
            .clone();
        let index = |name: &str| headers.iter().position(|h| h == name);
        let mut wanted: Vec<(String, usize, bool)> = Vec::new();
        for &name in required {
            let i = index(name).ok_or_else(|| {
                CliError::row(
                    path,
                    1,
                    format!(
                        "missing column `{name}` (header has: {})",
                        headers.iter().collect::<Vec<_>>().join(",")
                    ),
                )
            })?;
            wanted.push((name.to_string(), i, true));
        }
        for &name in optional {
            if let Some(i) = index(name) {
                wanted.push((name.to_string(), i, false));
            }
        }
        let mut columns: HashMap<String, Vec<f64>> = wanted
            .iter()
            .map(|(n, _, _)| (n.clone(), Vec::new()))
            .collect();
        let mut rows = 0;
        for (k, rec) in rdr.records().enumerate() {
            let row = k + 2;
            let rec = rec.map_err(|e| CliError::row(path, row, format!("malformed CSV: {e}")))?;
            for (name, i, req) in &wanted {
                let cell = rec.get(*i).unwrap_or("");
                let v = if cell.is_empty() && !req {
                    f64::NAN
                } else {
                    cell.parse::<f64>().map_err(|_| {
                        CliError::row(
                            path,
                            row,
                            format!("column `{name}`: `{cell}` is not a number"),
                        )
                    })?
                };
                if *req && !v.is_finite() {
                    return Err(CliError::row(
                        path,
                        row,
                        format!("column `{name}`: `{cell}` is not finite"),
                    ));
                }
                if let Some(c) = columns.get_mut(name) {
                    c.push(v);
                }
            }
            rows += 1;
        }
        Ok(Self {
            path: path.to_path_buf(),
            columns,
            rows,
        })
    }

    /// Number of data rows.
    pub fn len(&self) -> usize {
        self.rows
    }

    /// Whether the table has no data rows.
    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }

    /// A column, if it was read.
    pub fn col(&self, name: &str) -> Option<&[f64]> {
        self.columns.get(name).map(Vec::as_slice)
    }

    /// A required column (read with [`Table::read`]'s `required`, so always present).
    pub fn req(&self, name: &str) -> CliResult<&[f64]> {
        self.col(name)
            .ok_or_else(|| CliError::file(&self.path, format!("missing column `{name}`")))
    }

    /// Refuses a table with a header but no data rows.
    pub fn require_rows(&self) -> CliResult {
        if self.is_empty() {
            Err(CliError::row(
                &self.path,
                2,
                "no data rows after the header",
            ))
        } else {
            Ok(())
        }
    }

    /// Checks that `t_s` increases strictly; names the first row where it does not.
    pub fn check_increasing_time(&self) -> CliResult {
        let t = self.req("t_s")?;
        for k in 1..t.len() {
            if t[k] <= t[k - 1] {
                return Err(CliError::row(
                    &self.path,
                    k + 2,
                    format!(
                        "t_s = {} does not come after the previous row's {}; sort by time and drop duplicates",
                        t[k],
                        t[k - 1]
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Writes a CSV with a header row and rows of numbers. The file appears whole or not at
/// all: it is written beside `path` under a temporary name and renamed over it at the end.
pub fn write_csv(
    path: &Path,
    header: &[&str],
    rows: impl IntoIterator<Item = Vec<f64>>,
) -> CliResult {
    write_atomically(path, |file| {
        let mut w = csv::Writer::from_writer(file);
        w.write_record(header)?;
        for r in rows {
            w.write_record(r.iter().map(|v| format!("{v}")))?;
        }
        w.flush()?;
        Ok(())
    })
}

/// Writes `path` through `fill` into a temporary file beside it, then renames it into
/// place, so a run that fails or is killed never leaves a truncated output and never
/// touches an existing file before it has the whole new one.
pub fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut std::fs::File) -> Result<(), Box<dyn std::error::Error>>,
) -> CliResult {
    let name = path
        .file_name()
        .ok_or_else(|| CliError::file(path, "not a file name"))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    let tmp = path.with_file_name(tmp_name);
    let result = std::fs::File::create(&tmp)
        .map_err(|e| CliError::file(path, format!("cannot create: {e}")))
        .and_then(|mut f| {
            fill(&mut f).map_err(|e| CliError::file(path, format!("cannot write: {e}")))?;
            f.sync_all()
                .map_err(|e| CliError::file(path, format!("cannot write: {e}")))
        })
        .and_then(|()| {
            std::fs::rename(&tmp, path)
                .map_err(|e| CliError::file(path, format!("cannot replace: {e}")))
        });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Refuses an output path that names one of the inputs (it would destroy the recording).
pub fn check_distinct(output: &Path, inputs: &[&Path]) -> CliResult {
    let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    };
    for input in inputs {
        if same(output, input) {
            return Err(CliError::file(
                output,
                format!(
                    "the output would overwrite the input {}; choose another output path",
                    input.display()
                ),
            ));
        }
    }
    Ok(())
}

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
            use std::io::Write as _;
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn temp_file(tag: &str, contents: &[u8]) -> PathBuf {
        let path = std::env::temp_dir().join(format!(
            "truenorth-io-{tag}-{}-{:?}",
            std::process::id(),
            std::thread::current().id()
        ));
        std::fs::write(&path, contents).expect("temp dir is writable");
        path
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// What write_csv writes, Table::read reads back exactly (Rust prints the shortest
        /// text that parses back to the same f64).
        #[test]
        fn write_then_read_round_trips(rows in proptest::collection::vec((-1e12f64..1e12, -1e6f64..1e6), 1..50)) {
            let path = temp_file("rt", b"");
            write_csv(&path, &["t_s", "mag_x"], rows.iter().map(|&(a, b)| vec![a, b])).unwrap();
            let t = Table::read(&path, &["t_s", "mag_x"], &["mag_z"]).unwrap();
            prop_assert_eq!(t.len(), rows.len());
            prop_assert!(t.col("mag_z").is_none());
            for (k, &(a, b)) in rows.iter().enumerate() {
                prop_assert_eq!(t.req("t_s").unwrap()[k], a);
                prop_assert_eq!(t.req("mag_x").unwrap()[k], b);
            }
            std::fs::remove_file(&path).ok();
        }

        /// Any bytes at all: a table or a one-line error naming the file, never a panic.
        #[test]
        fn any_file_reads_or_fails_with_one_line(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let path = temp_file("any", &bytes);
            match Table::read(&path, &["t_s"], &["mag_x"]) {
                Ok(t) => prop_assert!(t.req("t_s").unwrap().iter().all(|v| v.is_finite())),
                Err(e) => {
                    let line = e.to_string();
                    prop_assert!(!line.contains('\n'), "{}", line);
                    prop_assert!(line.contains("truenorth-io-any"), "{}", line);
                }
            }
            std::fs::remove_file(&path).ok();
        }
    }
}
