//! `truenorth heading`: apply a compass calibration to a recording and write the heading,
//! tilt-compensated when the recording has the accelerometer and the calibration is 3-D.

use std::path::PathBuf;

use clap::ValueEnum as _;
use truenorth::checks::calibration_fit::FieldFit;
use truenorth::core::{Tilt, rad_to_deg};
use truenorth::{CompassCalibration, TrueNorth};

use super::field::PlaceArgs;
use crate::io::checking::MagWatch;
use crate::io::errln;
use crate::io::reading::kinds::Compass;
use crate::io::{
    CalibrationFile, CliError, CliResult, CsvOutput, Input, InputOptions, OutputOptions, Precision,
    check_distinct,
};
use crate::registry::CalibrationMethod;

/// The long help of the command (after the options).
const AFTER_HELP: &str =
    "Input: CSV with `t_s,mag_x,mag_y` (plus `mag_z` for a 3-D calibration), strictly
increasing time, and optionally `acc_x,acc_y,acc_z` (accelerometer reading specific
force: about +1 g on the upward axis at rest, any unit); other columns are ignored.
Output: CSV `t_s,heading_deg`, in degrees clockwise in [0, 360): from magnetic north,
or, with `--lat` and `--lon` (and optionally `--date`, default today), from true north —
magnetic heading plus the World Magnetic Model 2025 declination at that place and date.

Tilt: with a 3-D calibration and `acc_x,acc_y,acc_z` in the input, the heading is that
of the body x axis tilt-compensated with the pitch and roll the accelerometer gives (the
sensor at rest or moving slowly), and the columns `pitch_deg,roll_deg` follow (pitch
nose up, roll right side down). A calibration from `ellipsoid-accel` calibrates the
accelerometer and aligns it with the magnetometer; with a plain `ellipsoid` calibration
the raw accelerometer is used, assumed to share the magnetometer's axes. Without the
accelerometer columns, or with a 2-D calibration, the heading ASSUMES A LEVEL SENSOR
(body x forward, y right, z down, horizontal): a tilt of a few degrees then errs by
several degrees where the field dips steeply; the summary line on stderr says so.

Examples: truenorth heading --calibration cal.json --input mag.csv --output heading.csv
(magnetic); truenorth heading --calibration cal.json --input mag.csv --output - --lat 51.5
--lon -0.13 --date 2026.4 (true north in London).";

/// Arguments of `truenorth heading` (the details are in `AFTER_HELP`, shown by `--help`).
#[derive(Debug, clap::Args)]
#[command(after_long_help = AFTER_HELP)]
pub struct Args {
    /// Calibration JSON written by `truenorth calibrate` (`-`: standard input).
    #[arg(long)]
    pub calibration: PathBuf,
    /// Input CSV, or a PX4 ULog / ROS 2 MCAP log (found by its magic number; its
    /// magnetometer and accelerometer) (`-`: standard input; `.gz` or gzip data read as such).
    #[arg(long)]
    pub input: PathBuf,
    /// Output CSV (`-`: standard output; `*.gz`: compressed).
    #[arg(long)]
    pub output: PathBuf,
    /// Where and when the recording was made, for true heading.
    #[command(flatten)]
    pub place: PlaceArgs,
    /// How to read the input.
    #[command(flatten)]
    pub input_options: InputOptions,
    /// How to write the numbers.
    #[command(flatten)]
    pub output_options: OutputOptions,
    /// Go on (with a warning on stderr, repeated in the summary) when the calibration does
    /// not fit the readings, or was edited, instead of refusing.
    #[arg(long)]
    pub accept_calibration: bool,
    /// Go on (with a warning) when the magnetometer's readings are ones no live sensor gives
    /// (an axis clipped at its range or frozen, a reading of exactly zero), instead of
    /// refusing.
    #[arg(long)]
    pub accept_sensor_faults: bool,
}

/// True north, if a place was given.
fn true_north(args: &Args) -> CliResult<Option<TrueNorth>> {
    if args.place.is_given() {
        args.place.true_north()
    } else if args.place.date.is_some() || args.place.alt_km.is_some() {
        Err(CliError::msg(
            "heading: --date and --alt-km need --lat and --lon (the declination depends on the place)",
        ))
    } else {
        Ok(None)
    }
}

/// Runs the subcommand.
pub fn run(args: &Args) -> CliResult {
    check_inputs(args)?;
    let (file, cal) = CalibrationFile::read(&args.calibration)?;
    let mut doubts = Vec::new();
    let mut found = calibration_doubts(&file);
    if let Some((dip, model)) = args.place.dip_of_the_other_sign(file.dip_deg)? {
        found.push((true, format!(
            "the calibration's dip is {dip:+.1}° where the World Magnetic Model gives {model:+.1}° at --lat/--lon: no field there dips the other way, so the calibration was fitted with an accelerometer giving gravity instead of specific force, or with swapped axes (or belongs to another hemisphere's recording); recalibrate"
        )));
    }
    for (refuse, doubt) in found {
        if refuse && !args.accept_calibration {
            return Err(CliError::file(
                &args.calibration,
                format!("{doubt} (or --accept-calibration to go on)"),
            ));
        }
        errln!("truenorth: heading: warning: {doubt}");
        doubts.push(doubt);
    }
    let mut fit = FieldFit::default();
    let true_north = true_north(args)?;
    let mut samples =
        Input::new(&args.input, &args.input_options).samples(Compass::new(cal.dimensions()))?;
    let acc = samples.kind().has_acc();
    let mut header = vec!["t_s", "heading_deg"];
    if acc {
        header.extend(["pitch_deg", "roll_deg"]);
    }
    let mut out = CsvOutput::create(&args.output, &header)?;
    let path = samples.path().to_path_buf();
    let mut watch = MagWatch::new(&path, args.accept_sensor_faults);
    let dimensions = cal.dimensions().min(3);
    let count = samples.for_each(|row, reading| {
        watch.push_cells(row, reading.t_s, &reading.mag.as_slice()[..dimensions])?;
        fit.push(cal.corrected_magnitude(&reading.mag), file.field, row);
        let (magnetic, tilt) = cal
            .heading(&reading.mag, reading.acc.as_ref())
            .map_err(|e| CliError::row(&path, row, e.to_string()).kind_of(&e))?;
        let rad = match true_north {
            Some(north) => north.heading(magnetic).rad(),
            None => magnetic.rad(),
        };
        write_row(
            &mut out,
            args.output_options.precision,
            reading.t_s,
            rad,
            tilt,
        )
    })?;
    watch.finish()?;
    if let Some((why, row)) = fit.misfit(cal.dimensions()) {
        if !args.accept_calibration {
            let why = format!("{why} (or --accept-calibration to go on)");
            return Err(match row {
                Some(r) => CliError::row(&path, r, why),
                None => CliError::file(&path, why),
            });
        }
        errln!("truenorth: heading: warning: {why}");
        doubts.push(why);
    }
    out.commit()?;
    let north = if true_north.is_some() {
        "true"
    } else {
        "magnetic"
    };
    let how = tilt_summary(&cal, acc);
    let accepted = if doubts.is_empty() {
        String::new()
    } else {
        format!(
            "; accepted with --accept-calibration: {}",
            doubts.join("; ")
        )
    };
    errln!("truenorth: heading: {count} rows, {north} north, {how}{accepted}");
    Ok(())
}

/// What in a calibration file says it should not be trusted as it is, each with whether it
/// refuses (unless accepted): a soft iron that is not symmetric (every fit writes a
/// symmetric one: an edited file) refuses; a method no build of `calibrate` writes (a
/// hand-written file) and a `poor` verdict (the calibration's own bound judged it) are said.
fn calibration_doubts(file: &CalibrationFile) -> Vec<(bool, String)> {
    let mut doubts = Vec::new();
    let known = CalibrationMethod::value_variants()
        .iter()
        .any(|m| m.name() == file.method);
    if !known {
        doubts.push((false, format!(
            "the calibration's method `{}` is none `truenorth calibrate` writes: an edited or foreign file, whose numbers may mean something else",
            file.method
        )));
    }
    if file.quality.as_ref().is_some_and(|q| q.verdict == "poor") {
        doubts.push((
            false,
            "the calibration's own verdict is `poor`: its headings may be off by more than its bound says; recalibrate with a fuller turn".into(),
        ));
    }
    let s = &file.soft_iron;
    let scale = s.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let asymmetry = (0..s.len())
        .flat_map(|i| (0..i).map(move |j| (i, j)))
        .fold(0.0f64, |m, (i, j)| m.max((s[i][j] - s[j][i]).abs()));
    if asymmetry > 1e-6 * scale {
        doubts.push((true, format!(
            "the calibration's soft_iron is not symmetric (entries differ by {asymmetry:.3e}): every fit writes a symmetric one, so the file was edited; recalibrate"
        )));
    }
    doubts
}

/// Refuses an output that is one of the inputs, and two inputs on standard input.
fn check_inputs(args: &Args) -> CliResult {
    check_distinct(&args.output, &[&args.input, &args.calibration])?;
    if args.input.as_os_str() == "-" && args.calibration.as_os_str() == "-" {
        return Err(CliError::msg(
            "heading: --input and --calibration cannot both be standard input",
        ));
    }
    Ok(())
}

/// One output row: time, heading (`rad`, written in degrees) and the tilt if any.
fn write_row(
    out: &mut CsvOutput,
    precision: Precision,
    t_s: f64,
    rad: f64,
    tilt: Option<Tilt>,
) -> CliResult {
    match tilt {
        Some(tilt) => out.row(
            &[
                t_s,
                rad_to_deg(rad),
                rad_to_deg(tilt.pitch_rad),
                rad_to_deg(tilt.roll_rad),
            ],
            precision,
        ),
        None => out.row(&[t_s, rad_to_deg(rad)], precision),
    }
}

/// How the heading was found, for the summary line.
fn tilt_summary(cal: &CompassCalibration, acc: bool) -> &'static str {
    match (cal, acc) {
        (CompassCalibration::TwoD(_), _) => {
            "level sensor assumed (a 2-axis calibration cannot compensate tilt)"
        }
        (CompassCalibration::ThreeD(_), true) => {
            "tilt-compensated with the raw accelerometer (assumed in the magnetometer's axes; calibrate with ellipsoid-accel to align them)"
        }
        (CompassCalibration::Joint(_), true) => {
            "tilt-compensated with the calibrated accelerometer"
        }
        (_, false) => "level sensor assumed (no acc_x,acc_y,acc_z in the input)",
    }
}
