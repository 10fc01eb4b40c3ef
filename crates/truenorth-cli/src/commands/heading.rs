//! `truenorth heading`: apply a compass calibration to a recording and write the heading,
//! tilt-compensated when the recording has the accelerometer and the calibration is 3-D.

use std::path::PathBuf;

use truenorth::core::{Tilt, rad_to_deg};
use truenorth::{CompassCalibration, TrueNorth};

use super::field::PlaceArgs;
use crate::io::errln;
use crate::io::reading::kinds::Compass;
use crate::io::{
    CalibrationFile, CliError, CliResult, CsvOutput, Input, InputOptions, OutputOptions, Precision,
    check_distinct,
};

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
    let (_, cal) = CalibrationFile::read(&args.calibration)?;
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
    let count = samples.for_each(|row, reading| {
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
    out.commit()?;
    let north = if true_north.is_some() {
        "true"
    } else {
        "magnetic"
    };
    let how = tilt_summary(&cal, acc);
    errln!("truenorth: heading: {count} rows, {north} north, {how}");
    Ok(())
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
