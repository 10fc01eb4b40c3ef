//! `truenorth calibrate`: fit a compass calibration to a recording and write it, with its
//! quality report, as JSON.
//!
//! Every 2-D method is a `Calibrator<Sample = Mag2Sample, Params = CompassCalibration2d>`,
//! so adding one is one arm in [`run`]; the 3-D method is the same with `Mag3Sample` and
//! `CompassCalibration3d`.

use std::path::PathBuf;

use nalgebra::{SMatrix, SVector, Vector2, Vector3};
use truenorth::calib::{
    BinnedEllipseCalibrator, EllipseCalibrator, EllipsoidCalibrator, MeritCircleCalibrator,
    OnlineEllipseCalibrator, OnlineEllipsoidCalibrator, TurnCompassCalibrator, quality,
};
use truenorth::compass::{CompassCalibration2d, CompassCalibration3d};
use truenorth::core::{Calibrator, CompassQuality, Mag2Sample, Mag3Sample, Solution};

use crate::field::Place;
use crate::io::{
    CALIBRATION_FORMAT, CALIBRATION_VERSION, CalibrationFile, CliError, CliResult, InputOptions,
    InputPath, ReadSpec, Table, check_distinct,
};

/// Calibration methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// Least-squares ellipse (2-D): direct fit refined geometrically; hard + symmetric soft iron.
    Ellipse,
    /// Least-squares ellipsoid (3-D, needs mag_z): hard iron + full symmetric soft iron.
    Ellipsoid,
    /// Online least-squares ellipse (2-D): the same direct fit from running sums, in
    /// constant memory, as a vehicle would run it while driving.
    OnlineEllipse,
    /// Online least-squares ellipsoid (3-D, needs mag_z), in constant memory.
    OnlineEllipsoid,
    /// Binned ellipse (EP 0634001): heading bins, origin iteration, ellipse phasors.
    BinnedEllipse,
    /// Merit circle (US 5,297,063): merit-weighted circumcentres; hard iron only.
    MeritCircle,
    /// One full turn (EP 0640207): centre and radii from the extrema.
    Turn,
}

impl Method {
    /// The name used on the command line and in the output file.
    fn name(self) -> &'static str {
        match self {
            Method::Ellipse => "ellipse",
            Method::Ellipsoid => "ellipsoid",
            Method::OnlineEllipse => "online-ellipse",
            Method::OnlineEllipsoid => "online-ellipsoid",
            Method::BinnedEllipse => "binned-ellipse",
            Method::MeritCircle => "merit-circle",
            Method::Turn => "turn",
        }
    }
}

/// Arguments of `truenorth calibrate`.
///
/// Input: CSV with a header row and columns `t_s,mag_x,mag_y` (plus `mag_z` for
/// `ellipsoid`); other columns are ignored; magnetometer in any unit; `turn` also accepts
/// `gyr_z` (rad/s) and ignores it (the method calibrates the compass). Time must increase strictly. The readings should cover a full turn (2-D, level) or
/// many orientations (3-D).
///
/// Output: JSON
/// `{"format": "truenorth-compass-calibration", "version": 1, "method": M,
///   "dimensions": 2|3, "hard_iron": [..], "soft_iron": [[..], ..] (row by row),
///   "field": F, "quality": {"points", "coverage", "residual_rms_rel", "condition",
///   "heading_error_bound_deg", "heading_error_3sigma_deg", "heading_error_systematic_deg",
///   "heading_noise_rms_deg", "field_magnitude", "field_ratio_to_expected"}, "input": FILE}`
/// with `corrected = soft_iron · (raw − hard_iron)`, a circle (sphere) of radius `field` in
/// the input unit. `coverage`: share of 10° heading bins (3-D: of 128 equal-area direction
/// cells) filled; `residual_rms_rel`: RMS of |corrected|/field − 1; `condition`: condition
/// number of the calibration's information matrix (2 = a full, even circle);
/// `heading_error_bound_deg`: bound on the heading error the calibration adds (3-D: on the
/// field direction error), the sum of `heading_error_3sigma_deg` (3-sigma, from the
/// uncertainty of the fitted parameters) and `heading_error_systematic_deg` (what the
/// method's model cannot remove, e.g. a rotated soft iron under `merit-circle` or `turn`);
/// `heading_noise_rms_deg`: the noise of each calibrated reading, which comes on top.
///
/// Exit status 1 with one line on stderr when the file is bad or the data cannot support a
/// calibration (too few points, too little of the circle, degenerate, not an ellipse).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Calibration method.
    #[arg(long, value_enum)]
    pub method: Method,
    /// Input CSV (`-`: standard input; `.gz` or gzip data read as such).
    #[arg(long)]
    pub input: PathBuf,
    /// Output JSON (`-`: standard output).
    #[arg(long)]
    pub output: PathBuf,
    /// Expected field in the input unit (horizontal for 2-D methods, total for
    /// `ellipsoid`), e.g. from `truenorth field`; the report then gives
    /// `field_ratio_to_expected`.
    #[arg(long, value_name = "FIELD")]
    pub expected_field: Option<f64>,
    /// Unit of the readings; with --lat/--lon the World Magnetic Model field there (horizontal
    /// for 2-D methods, total for `ellipsoid`) becomes the expected field. A fit more than
    /// 15 % away from it prints a warning on stderr.
    #[arg(long, value_enum, value_name = "UNIT")]
    pub mag_unit: Option<MagUnit>,
    /// Where and when the recording was made (for the expected field).
    #[command(flatten)]
    pub place: Place,
    /// How to read the input.
    #[command(flatten)]
    pub input_options: InputOptions,
}

/// Units a magnetometer may report in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MagUnit {
    /// Nanotesla.
    #[value(name = "nT")]
    NanoTesla,
    /// Microtesla.
    #[value(name = "uT")]
    MicroTesla,
    /// Milligauss (= 100 nT).
    #[value(name = "mG")]
    MilliGauss,
    /// Gauss (= 100 000 nT).
    #[value(name = "G")]
    Gauss,
}

impl MagUnit {
    fn nanotesla(self) -> f64 {
        match self {
            Self::NanoTesla => 1.0,
            Self::MicroTesla => 1e3,
            Self::MilliGauss => 1e2,
            Self::Gauss => 1e5,
        }
    }
}

/// The field the fit should find, in the input unit: given directly, or from the World
/// Magnetic Model at `--lat/--lon/--date` (horizontal for `dimensions` = 2, total for 3).
fn expected_field(args: &Args, dimensions: usize) -> CliResult<Option<f64>> {
    if !args.place.is_given() {
        return Ok(args.expected_field);
    }
    if args.expected_field.is_some() {
        return Err(CliError::msg(
            "give either --expected-field or --lat/--lon, not both",
        ));
    }
    let unit = args.mag_unit.ok_or_else(|| {
        CliError::msg(
            "--lat/--lon need --mag-unit (nT, uT, mG or G) to compare the fit with the WMM field",
        )
    })?;
    let f = args.place.field()?;
    let nt = if dimensions == 3 { f.f_nt } else { f.h_nt };
    Ok(Some(nt / unit.nanotesla()))
}

/// Runs the subcommand.
pub fn run(args: &Args) -> CliResult {
    check_distinct(&args.output, &[&args.input])?;
    if let Some(e) = args.expected_field
        && !(e.is_finite() && e > 0.0)
    {
        return Err(CliError::msg(format!(
            "--expected-field must be a positive number, got {e}"
        )));
    }
    let file = match args.method {
        Method::Ellipse => calibrate_2d(args, EllipseCalibrator::default())?,
        Method::Ellipsoid => calibrate_3d(args, EllipsoidCalibrator::default())?,
        Method::OnlineEllipse => calibrate_2d(
            args,
            OnlineEllipseCalibrator::new(Default::default()).map_err(library)?,
        )?,
        Method::OnlineEllipsoid => calibrate_3d(
            args,
            OnlineEllipsoidCalibrator::new(Default::default()).map_err(library)?,
        )?,
        Method::BinnedEllipse => calibrate_2d(args, BinnedEllipseCalibrator::default())?,
        Method::MeritCircle => calibrate_2d(args, MeritCircleCalibrator::default())?,
        // The compass half of the turn method (METHODS.md §A.4-5); `gyr_z` is accepted so
        // that one recording serves both halves, and ignored here.
        Method::Turn => calibrate_2d(args, TurnCompassCalibrator::default())?,
    };
    file.write(&args.output)?;
    eprintln!("truenorth: {}", summary(&file));
    Ok(())
}

/// The one line on stderr after a successful calibration.
fn summary(file: &CalibrationFile) -> String {
    let q = file.quality.as_ref();
    let num = |v: Option<f64>| v.map_or("unbounded".to_string(), |v| format!("{v:.3}"));
    format!(
        "calibrate: method {}, {} points, field {:.6} (input unit), heading error bound {} deg (3 sigma + systematic)",
        file.method,
        q.map_or(0, |q| q.points),
        file.field,
        num(q.and_then(|q| q.heading_error_bound_deg)),
    )
}

/// A library error outside any file (an invalid built-in configuration).
fn library(e: truenorth::core::Error) -> CliError {
    CliError::msg(e.to_string())
}

/// Reads the `columns` of the input, and `t_s` (strictly increasing) where present. Without
/// `t_s`, the rows are taken as one second apart (the batch methods do not use time).
fn read_input(args: &Args, columns: &[&str]) -> CliResult<(Table, Vec<f64>)> {
    let spec = ReadSpec::new(columns).optional(&["t_s"]).increasing("t_s");
    let table = Table::read_with(&InputPath::new(&args.input), &args.input_options, &spec)?;
    table.require_rows()?;
    let t = match table.col("t_s") {
        Some(t) => t.to_vec(),
        None => (0..table.len()).map(|k| k as f64).collect(),
    };
    Ok((table, t))
}

/// Reads the 2-D input.
fn read_2d(args: &Args) -> CliResult<Vec<Mag2Sample>> {
    let (table, t) = read_input(args, &["mag_x", "mag_y"])?;
    let (x, y) = (table.req("mag_x")?, table.req("mag_y")?);
    let samples = (0..table.len())
        .map(|k| Mag2Sample {
            t_s: t[k],
            mag: Vector2::new(x[k], y[k]),
        })
        .collect();
    Ok(samples)
}

/// Feeds every row to a 2-D calibrator, solves, and builds the output file.
fn calibrate_2d<C>(args: &Args, mut cal: C) -> CliResult<CalibrationFile>
where
    C: Calibrator<Sample = Mag2Sample, Params = CompassCalibration2d, Quality = CompassQuality>,
{
    let samples = read_2d(args)?;
    let sol = feed_and_solve(args, &mut cal, &samples, expected_field(args, 2)?)?;
    Ok(file_for(
        args,
        &sol.params.hard_iron,
        &sol.params.soft_iron,
        sol.quality,
    ))
}

/// Feeds every row to a 3-D calibrator, solves, and builds the output file.
fn calibrate_3d<C>(args: &Args, mut cal: C) -> CliResult<CalibrationFile>
where
    C: Calibrator<Sample = Mag3Sample, Params = CompassCalibration3d, Quality = CompassQuality>,
{
    let (table, t) = read_input(args, &["mag_x", "mag_y", "mag_z"])?;
    let x = table.req("mag_x")?;
    let (y, z) = (table.req("mag_y")?, table.req("mag_z")?);
    let samples: Vec<_> = (0..table.len())
        .map(|k| Mag3Sample {
            t_s: t[k],
            mag: Vector3::new(x[k], y[k], z[k]),
        })
        .collect();
    let sol = feed_and_solve(args, &mut cal, &samples, expected_field(args, 3)?)?;
    Ok(file_for(
        args,
        &sol.params.hard_iron,
        &sol.params.soft_iron,
        sol.quality,
    ))
}

/// Pushes the samples (a rejected one names its row) and solves; a refusal names the file
/// and the reason.
fn feed_and_solve<C: Calibrator<Quality = CompassQuality>>(
    args: &Args,
    cal: &mut C,
    samples: &[C::Sample],
    expected: Option<f64>,
) -> CliResult<Solution<C::Params>> {
    for (k, s) in samples.iter().enumerate() {
        cal.push(s)
            .map_err(|e| CliError::row(&args.input, k + 2, e.to_string()))?;
    }
    let mut sol = cal.solve().map_err(|e| {
        CliError::file(
            &args.input,
            format!(
                "cannot calibrate with method `{}`: {}",
                args.method.name(),
                e
            ),
        )
    })?;
    sol.quality = quality::with_expected_field(sol.quality, expected);
    if let Some(w) = expected.and_then(|e| quality::field_mismatch(&sol.quality, e)) {
        eprintln!("truenorth: warning: {}: {w}", args.input.display());
    }
    Ok(sol)
}

fn file_for<const D: usize>(
    args: &Args,
    hard_iron: &SVector<f64, D>,
    soft_iron: &SMatrix<f64, D, D>,
    q: CompassQuality,
) -> CalibrationFile {
    CalibrationFile {
        format: CALIBRATION_FORMAT.into(),
        version: CALIBRATION_VERSION,
        method: args.method.name().into(),
        dimensions: D,
        hard_iron: hard_iron.iter().copied().collect(),
        // Row by row, as the file format says.
        soft_iron: soft_iron
            .row_iter()
            .map(|r| r.iter().copied().collect())
            .collect(),
        field: q.field_magnitude,
        quality: Some(q.into()),
        input: args.input.display().to_string(),
    }
}
