//! `truenorth calibrate`: fit a compass calibration to a recording and write it, with its
//! quality report and verdict, as JSON; the turn method with a yaw rate calibrates the
//! gyro beside it.
//!
//! Every method comes from the registry ([`CalibrationMethod::calibrator`]) boxed behind the
//! `Calibrator` of its samples: every 2-D method is a `Calibrator<Sample = Mag2Sample,
//! Params = CompassCalibration2d>`, so adding one is one arm in the registry; the 3-D
//! methods are the same with `Mag3Sample` and `CompassCalibration3d`, and `ellipsoid-accel`
//! fits both sensors together.

use std::path::{Path, PathBuf};

use nalgebra::{SMatrix, SVector};
use truenorth::calib::MagAccelQuality;
use truenorth::calib::quality::{self, Cause, Grade, Verdict};
use truenorth::checks::{MagUnit, check_field};
use truenorth::core::{Calibrator, CompassQuality, Fixed, Mag2Sample, Solution};

use super::field::PlaceArgs;
use crate::io::checking::{MagCells, MagWatch, say};
use crate::io::errln;
use crate::io::reading::kinds::{Mag2, Mag3, MagAccel as MagAccelRows, Turn};
use crate::io::reading::{SampleKind, Samples};
use crate::io::spill::ReadingSpill;
use crate::io::{
    AccelPart, CALIBRATION_FORMAT, CALIBRATION_VERSION, CalibrationFile, CliError, CliResult,
    GyroPart, Input, InputOptions, InputPath, QualityReport, check_distinct, finite, gyro_units,
    matrix_rows, units_block,
};
use crate::registry::{
    CalibrationMethod, CompassCalibrator, MagAccel, Planar, Spatial, TurnWithGyro,
};

/// The long help of the command (after the options).
const AFTER_HELP: &str =
    "Input: CSV with a header row and columns `mag_x,mag_y` (plus `mag_z` for the 3-D
methods, and `acc_x,acc_y,acc_z` for `ellipsoid-accel`); `t_s` (strictly increasing) is
read where present and needed only by the online methods and by `turn` with `gyr_z`
(without it rows are one second apart); other columns are ignored. Magnetometer in any
unit; accelerometer in any unit, reading specific force (about +1 g on the upward axis at
rest: an accelerometer that reports gravity instead is negated with
`--column acc_x=-acc_x,...`). The readings should cover a full turn (2-D, level) or
orientations that determine the ellipsoid (3-D: a tumble, or a few dozen shots in
assorted directions and rolled about a target).

The input is read once, row by row, straight into the method: the online methods
(online-ellipse, online-ellipsoid, binned-ellipse, merit-circle) and `turn` without
`gyr_z` keep running state whose size does not depend on the file; the batch fits
(ellipse, ellipsoid, ellipsoid-accel, turn with `gyr_z`) keep the one copy of the
readings their fit needs (ellipse about 16 bytes per row, ellipsoid 24, ellipsoid-accel
48), nothing else. Ellipse, ellipsoid and ellipsoid-accel keep the first 32 MiB of it in
memory and the rest in a temporary file in TMPDIR (default /tmp), removed from the
directory as soon as it is made, so their memory stays bounded; point TMPDIR at a disk
with room for a long recording (a full disk is an error saying so). A line longer than 64 KiB, or a file without line
breaks, is refused with its row.

`turn` with a `gyr_z` column (yaw rate, rad/s, positive turning right; needs `t_s`)
calibrates the gyro too (EP 0640207): the record must start with the vehicle at rest for
at least 1 s (the gyro's zero is its mean there) and then turn one way through at least
one full revolution, with every compass maximum and minimum inside the record (a
quarter turn more); the scale comes from the integrated rate between compass extrema
half a turn apart. A record that does not qualify is refused with the reason; drop the
`gyr_z` column to calibrate the compass alone. Without `gyr_z` only the compass is
calibrated.

Output: JSON, version 2:
`{\"format\": \"truenorth-compass-calibration\", \"version\": 2, \"method\": M,
  \"dimensions\": 2|3, \"units\": {...}, \"hard_iron\": [..], \"soft_iron\": [[..], ..] (row by
  row), \"field\": F, [\"mag_to_body\": [[..]], \"accelerometer\": {\"bias\", \"matrix\",
  \"gravity\"}, \"dip_deg\"] (ellipsoid-accel), \"quality\": {\"verdict\", \"verdict_reason\",
  \"points\", \"coverage\", \"residual_rms_rel\", \"condition\", \"geometry_dilution\",
  \"heading_error_bound_deg\", \"heading_error_3sigma_deg\", \"heading_error_systematic_deg\",
  \"heading_noise_rms_deg\", \"hard_iron_sigma\", \"soft_iron_sigma_rel\",
  \"field_ratio_to_expected\", ...}, [\"gyro\": {\"zero_rps\", \"scale\", \"zero_sigma_rps\",
  \"scale_sigma\", \"rest_s\", \"pairs\", \"turned_deg\"}] (turn with gyr_z), \"input\": FILE}`
with `corrected = soft_iron · (raw − hard_iron)`, a circle (sphere) of radius `field` in
the input unit, and `rate = (gyr_z − zero_rps) / scale`. The `units` block says what
every number is in and means.
`heading_error_bound_deg` bounds the heading error the calibration itself adds to every
later heading (3-D: the field direction error; ellipsoid-accel: the heading of the body
x axis): 3 standard deviations of the parameters' uncertainty plus what the method's
model cannot remove; each reading's own noise (`heading_noise_rms_deg`) comes on top.
`verdict`: `good` (bound ≤ 1°, noise ≤ 2°), `usable` (both ≤ 5°) or `poor`, with the
number that decided it in `verdict_reason` and `verdict_cause`: `calibration` (its own
bound: record more readings, or a fuller turn or tumble) or `noise` (each reading
scatters more than the grade allows while the calibration itself is within it: a noisy
sensor, whose readings are worth averaging).

A `poor` calibration is refused (exit 1) unless `--accept-poor`. With `--mag-unit`, a
fitted field that is not a plausible Earth field in that unit (or, with --lat/--lon, more
than 15 % from the World Magnetic Model's) is refused with the unit the data are
probably in, unless `--accept-field-mismatch`. On success one summary line goes to
stderr. Exit status 1 with one line on stderr when the file is bad or the data cannot
support a calibration (too few points, too few headings (`binned-ellipse`: direction
bins filled), too little of the circle, orientations that do not determine it whatever
their count, too few readings for their noise, readings too noisy for their
orientations, not an ellipse, or with `turn` and `gyr_z` a gap between rows longer than
1 s, across which the rate cannot be integrated).

Example: a logger's file with columns `time;mx;my;mz;ax;ay;az`, sensor axes x forward,
y left, z up, field in µT, recorded in London:
`truenorth calibrate --method ellipsoid-accel --input log.csv.gz --output cal.json
 --column t_s=time,mag_x=mx,mag_y=my,mag_z=mz,acc_x=ax,acc_y=ay,acc_z=az --axes flu
 --mag-unit uT --lat 51.5 --lon -0.13`";

/// Arguments of `truenorth calibrate` (the details are in `AFTER_HELP`, shown by `--help`).
#[derive(Debug, clap::Args)]
#[command(after_long_help = AFTER_HELP)]
pub struct Args {
    /// Calibration method.
    #[arg(long, value_enum)]
    pub method: CalibrationMethod,
    /// Input CSV, or a PX4 ULog / ROS 2 MCAP log (found by its magic number; its
    /// magnetometer) (`-`: standard input; `.gz` or gzip data read as such).
    #[arg(long)]
    pub input: PathBuf,
    /// Output JSON (`-`: standard output).
    #[arg(long)]
    pub output: PathBuf,
    /// Expected field in the input unit (horizontal for 2-D methods, total for 3-D), e.g.
    /// from `truenorth field`; the report then gives `field_ratio_to_expected`.
    #[arg(long, value_name = "FIELD")]
    pub expected_field: Option<f64>,
    /// Unit of the magnetometer readings. Alone, the fitted field must be a plausible Earth
    /// field in it; with --lat/--lon, within 15 % of the World Magnetic Model's field there
    /// (horizontal for 2-D methods, total for 3-D).
    #[arg(long, value_enum, value_name = "UNIT")]
    pub mag_unit: Option<MagUnit>,
    /// Where and when the recording was made (for the expected field).
    #[command(flatten)]
    pub place: PlaceArgs,
    /// Write a `poor` calibration anyway (with a warning) instead of refusing it.
    #[arg(long)]
    pub accept_poor: bool,
    /// Write the calibration even when its field does not match --mag-unit or the World
    /// Magnetic Model (with a warning).
    #[arg(long)]
    pub accept_field_mismatch: bool,
    /// Go on (with a warning) when the magnetometer's readings are ones no live sensor gives
    /// (an axis clipped at its range or frozen, a reading of exactly zero), instead of
    /// refusing.
    #[arg(long)]
    pub accept_sensor_faults: bool,
    /// How to read the input.
    #[command(flatten)]
    pub input_options: InputOptions,
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

/// Why a joint calibration's dip `dip_deg` contradicts the place given (`--lat/--lon`): the
/// field dips down in the northern magnetic hemisphere and up in the southern, so a fitted
/// dip of the other sign is an accelerometer giving gravity rather than specific force, or
/// axes swapped — whatever the fit's own residuals say.
fn dip_against_place(args: &Args, dip_deg: Option<f64>) -> CliResult<Option<String>> {
    let Some((dip, model)) = args.place.dip_of_the_other_sign(dip_deg)? else {
        return Ok(None);
    };
    Ok(Some(format!(
        "the fitted dip is {dip:+.1}° where the World Magnetic Model gives {model:+.1}° at this place: the field cannot dip the other way, so the accelerometer gives gravity instead of specific force (negate it: --column acc_x=-HEADER,acc_y=-HEADER,acc_z=-HEADER) or its axes or the magnetometer's are swapped (`truenorth inspect` on the recording names them)"
    )))
}

/// A fitted calibration on its way to the file, with what the checks need.
struct Fitted {
    file: CalibrationFile,
    quality: CompassQuality,
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
    let expected = expected_field(args, args.method.dimensions())?;
    // The batch fits keep their readings in memory up to a share, the rest in a temporary
    // file; a disk that fails them is reported as such, not as what it made the fit say.
    let spill = ReadingSpill::from_env();
    let fitted = match args
        .method
        .calibrator_spilling(expected, &spill)
        .map_err(library)?
    {
        CompassCalibrator::Planar(cal) => calibrate_2d(args, cal),
        CompassCalibrator::Spatial(cal) => calibrate_3d(args, cal),
        CompassCalibrator::MagAccel(cal) => calibrate_joint(args, cal),
        CompassCalibrator::Turn { compass, with_gyro } => calibrate_turn(args, compass, with_gyro),
    };
    let fitted = fitted.map_err(|e| spill.take_failure().unwrap_or(e))?;
    let input = InputPath::new(&args.input).display_path();
    let warn = |w: &str| errln!("truenorth: warning: {}: {w}", input.display());
    // A field that does not fit the unit or the place: refused, or said under
    // --accept-field-mismatch.
    let mismatch = |problem: String| -> CliResult {
        if args.accept_field_mismatch {
            warn(&problem);
            Ok(())
        } else {
            Err(CliError::file(
                &input,
                format!("{problem} (write it anyway with --accept-field-mismatch)"),
            )
            .refusal())
        }
    };
    if let Some(problem) = check_field(
        fitted.quality.field_magnitude,
        args.mag_unit,
        expected.filter(|_| args.place.is_given()),
        args.method.dimensions(),
    )
    .map(|f| say(&f, &args.input_options))
    {
        mismatch(problem)?;
    } else if let Some(w) = expected.and_then(|e| quality::field_mismatch(&fitted.quality, e)) {
        // An expected field given directly: a warning, as the numbers are the user's.
        warn(&w.to_string());
    }
    if let Some(problem) = dip_against_place(args, fitted.file.dip_deg)? {
        mismatch(problem)?;
    }
    let verdict = fitted.quality.verdict();
    if verdict.grade == Grade::Poor {
        let what = format!(
            "the calibration with method `{}` is poor: {verdict}",
            args.method.name()
        );
        if args.accept_poor {
            warn(&what);
        } else {
            return Err(CliError::file(
                &input,
                format!("{what}; refused (write it anyway with --accept-poor)"),
            )
            .refusal());
        }
    }
    fitted.file.write(&args.output)?;
    errln!("truenorth: {}", summary(&fitted.file, &verdict));
    Ok(())
}

/// The one line on stderr after a successful calibration.
fn summary(file: &CalibrationFile, verdict: &Verdict) -> String {
    let q = file.quality.as_ref();
    let num = |v: Option<f64>| v.map_or("unbounded".to_string(), |v| Fixed(v, 2).to_string());
    let cause = match verdict.cause {
        Cause::None => String::new(),
        c => format!(" (decided by the {c})"),
    };
    let mut s = format!(
        "calibrate: method {}, {} points, verdict {}{cause}, field {} (input unit), heading error bound {} deg (3 sigma + systematic), per-reading noise {} deg RMS",
        file.method,
        q.map_or(0, |q| q.points),
        verdict.grade,
        Fixed(file.field, 6),
        num(q.and_then(|q| q.heading_error_bound_deg)),
        num(q.and_then(|q| q.heading_noise_rms_deg)),
    );
    if let Some(g) = &file.gyro {
        s += &format!(
            ", gyro zero {} deg/s, scale {} ({} pairs X, {} Y)",
            Fixed(g.zero_rps.to_degrees(), 4),
            Fixed(g.scale, 5),
            g.pairs[0],
            g.pairs[1]
        );
    }
    if let (Some(q), Some(d)) = (q, file.dip_deg) {
        s += &format!(
            ", dip {} deg (spread {} deg), {} runs",
            Fixed(d, 2),
            num(q.dip_spread_deg),
            q.runs.unwrap_or(0)
        );
    }
    s
}

/// A library error outside any file (an invalid built-in configuration).
fn library(e: truenorth::core::Error) -> CliError {
    CliError::from(e)
}

/// Opens the input for the samples of `kind` (`t_s` read where present, strictly
/// increasing).
fn open_input<K: SampleKind>(args: &Args, kind: K) -> CliResult<Samples<K>> {
    let csv_only = [(
        "--mag-unit",
        args.mag_unit.is_some_and(|u| u != MagUnit::MicroTesla),
    )];
    Input::new(&args.input, &args.input_options)
        .csv_only(&csv_only)
        .samples(kind)
}

/// Reads the input once, row by row, pushing each sample into `cal` (a rejected sample
/// names its row) and the magnetometer's readings past the watch for readings no live
/// sensor gives. Nothing is kept here: a batch method keeps its own one copy of the
/// readings it fits, an online one its running state.
fn push_rows<K, C>(args: &Args, samples: &mut Samples<K>, cal: &mut C) -> CliResult
where
    K: SampleKind<Sample = C::Sample>,
    C: Calibrator + ?Sized,
    C::Sample: MagCells,
{
    let path = samples.path().to_path_buf();
    let mut watch = MagWatch::new(&path, args.accept_sensor_faults);
    samples.for_each(|row, sample| {
        watch.push(row, &sample)?;
        cal.push(&sample)
            .map_err(|e| CliError::row(&path, row, e.to_string()).kind_of(&e))?;
        Ok(())
    })?;
    watch.finish()
}

/// Feeds every row to a 2-D calibrator, solves, and builds the output file.
fn calibrate_2d(args: &Args, mut cal: Box<Planar>) -> CliResult<Fitted> {
    let mut samples = open_input(args, Mag2::default())?;
    push_rows(args, &mut samples, &mut *cal)?;
    let sol = solve(args, samples.path(), &mut *cal)?;
    Ok(fitted(
        args,
        &sol.params.hard_iron,
        &sol.params.soft_iron,
        sol.quality,
    ))
}

/// The turn method (EP 0640207). With `gyr_z`, the whole calibration of one
/// turn ([`TurnCalibrator`](truenorth::calib::TurnCalibrator)): the gyro's zero and scale, and the compass from the same
/// extrema (placed by the sinusoid fit the gyro's relative heading allows). Without it, the
/// compass half alone ([`TurnCompassCalibrator`](truenorth::calib::TurnCompassCalibrator)).
fn calibrate_turn(
    args: &Args,
    mut compass: Box<Planar>,
    mut with_gyro: Box<TurnWithGyro>,
) -> CliResult<Fitted> {
    let mut samples = open_input(args, Turn::default())?;
    if !samples.kind().has_gyro() {
        let path = samples.path().to_path_buf();
        let mut watch = MagWatch::new(&path, args.accept_sensor_faults);
        samples.for_each(|row, s| {
            let sample = Mag2Sample {
                t_s: s.t_s,
                mag: s.mag,
            };
            watch.push(row, &sample)?;
            compass
                .push(&sample)
                .map_err(|e| CliError::row(&path, row, e.to_string()).kind_of(&e))?;
            Ok(())
        })?;
        watch.finish()?;
        let sol = solve(args, &path, &mut *compass)?;
        return Ok(fitted(
            args,
            &sol.params.hard_iron,
            &sol.params.soft_iron,
            sol.quality,
        ));
    }
    push_rows(args, &mut samples, &mut *with_gyro)?;
    let sol = solve(args, samples.path(), &mut *with_gyro)?;
    let (c, q) = (sol.params, sol.quality);
    let mut f = fitted(args, &c.compass.hard_iron, &c.compass.soft_iron, q.compass);
    f.file.units.extend(gyro_units());
    // One turn measures the gain of the direction turned; it stands for both.
    f.file.gyro = Some(GyroPart {
        zero_rps: c.gyro.zero_rps,
        scale: c.gyro.gain_pos,
        zero_sigma_rps: finite(q.gyro_zero_sigma_rps),
        scale_sigma: finite(q.gyro_gain_sigma),
        rest_s: q.rest_s,
        pairs: [q.pairs.0, q.pairs.1],
        turned_deg: q.turned_rad.to_degrees(),
    });
    Ok(f)
}

/// Feeds every row to a 3-D calibrator, solves, and builds the output file.
fn calibrate_3d(args: &Args, mut cal: Box<Spatial>) -> CliResult<Fitted> {
    let mut samples = open_input(args, Mag3::default())?;
    push_rows(args, &mut samples, &mut *cal)?;
    let sol = solve(args, samples.path(), &mut *cal)?;
    Ok(fitted(
        args,
        &sol.params.hard_iron,
        &sol.params.soft_iron,
        sol.quality,
    ))
}

/// The joint magnetometer + accelerometer calibration.
fn calibrate_joint(args: &Args, mut cal: Box<MagAccel>) -> CliResult<Fitted> {
    let mut samples = open_input(args, MagAccelRows::default())?;
    push_rows(args, &mut samples, &mut *cal)?;
    let sol = solve(args, samples.path(), &mut *cal)?;
    let (c, q) = (sol.params, sol.quality);
    let mut f = fitted(args, &c.mag.hard_iron, &c.mag.soft_iron, q.mag);
    f.file.units = units_block(true);
    f.file.mag_to_body = Some(matrix_rows(&c.mag_to_body));
    f.file.accelerometer = Some(AccelPart {
        bias: c.accel.bias.iter().copied().collect(),
        matrix: matrix_rows(&c.accel.matrix),
        gravity: c.gravity,
    });
    f.file.dip_deg = Some(q.dip_deg);
    if let Some(r) = f.file.quality.as_mut() {
        joint_report(r, &q);
    }
    Ok(f)
}

/// The joint calibration's own figures in the report.
fn joint_report(r: &mut QualityReport, q: &MagAccelQuality) {
    r.accel_residual_rms_rel = finite(q.accel_residual_rms_rel);
    r.accel_bias_sigma = Some(q.accel_bias_sigma.iter().map(|&s| finite(s)).collect());
    r.dip_spread_deg = finite(q.dip_spread_deg);
    r.alignment_deg = finite(q.alignment_deg);
    r.alignment_sigma_deg = finite(q.alignment_sigma_deg);
    r.runs = Some(q.runs);
    r.run_shots = Some(q.run_shots);
    r.pointing_offset_deg = finite(q.pointing_offset_deg);
    r.aim_rms_deg = finite(q.aim_rms_deg);
}

/// Solves a calibrator fed with every row; a refusal names the file and the reason.
fn solve<C>(args: &Args, path: &Path, cal: &mut C) -> CliResult<Solution<C::Params, C::Quality>>
where
    C: Calibrator + ?Sized,
{
    cal.solve().map_err(|e| {
        CliError::file(
            path,
            format!(
                "cannot calibrate with method `{}`: {}",
                args.method.name(),
                e
            ),
        )
        .kind_of(&e)
    })
}

/// The output file of a magnetometer calibration and its report.
fn fitted<const D: usize>(
    args: &Args,
    hard_iron: &SVector<f64, D>,
    soft_iron: &SMatrix<f64, D, D>,
    q: CompassQuality,
) -> Fitted {
    let file = CalibrationFile {
        format: CALIBRATION_FORMAT.into(),
        version: CALIBRATION_VERSION,
        method: args.method.name().into(),
        dimensions: D,
        units: units_block(false),
        hard_iron: hard_iron.iter().copied().collect(),
        // Row by row, as the file format says.
        soft_iron: matrix_rows(soft_iron),
        field: q.field_magnitude,
        mag_to_body: None,
        accelerometer: None,
        dip_deg: None,
        gyro: None,
        quality: Some(QualityReport::new(&q, D)),
        input: InputPath::new(&args.input)
            .display_path()
            .display()
            .to_string(),
    };
    Fitted { file, quality: q }
}
