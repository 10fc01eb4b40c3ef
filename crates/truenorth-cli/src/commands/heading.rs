//! `truenorth heading`: apply a compass calibration to a recording and write the heading,
//! tilt-compensated when the recording has the accelerometer and the calibration is 3-D.

use std::path::{Path, PathBuf};

use nalgebra::{Vector2, Vector3};
use truenorth::accel::static_tilt;
use truenorth::core::{Declination, MagneticHeading, Tilt, rad_to_deg};

use super::field::Place;
use crate::io::errln;
use crate::io::log_input;
use crate::io::{
    CalibrationFile, CliError, CliResult, CompassCalibration, CsvOutput, InputOptions,
    OutputOptions, Precision, ReadSpec, RowReader, RowRef, check_distinct,
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
    pub place: Place,
    /// How to read the input.
    #[command(flatten)]
    pub input_options: InputOptions,
    /// How to write the numbers.
    #[command(flatten)]
    pub output_options: OutputOptions,
}

/// The declination that turns magnetic into true heading, if a place was given.
fn declination(args: &Args) -> CliResult<Option<Declination>> {
    if args.place.is_given() {
        Ok(Some(args.place.field()?.declination()))
    } else if args.place.date.is_some() || args.place.alt_km.is_some() {
        Err(CliError::msg(
            "heading: --date and --alt-km need --lat and --lon (the declination depends on the place)",
        ))
    } else {
        Ok(None)
    }
}

const ACC: [&str; 3] = ["acc_x", "acc_y", "acc_z"];

/// Runs the subcommand.
pub fn run(args: &Args) -> CliResult {
    check_inputs(args)?;
    let (_, cal) = CalibrationFile::read(&args.calibration)?;
    let declination = declination(args)?;
    let (needed, optional) = columns_read(&cal);
    let spec = ReadSpec::new(needed).optional(optional).increasing("t_s");
    let input = log_input::source(&args.input, &args.input_options, &spec, &[])?;
    let mut rows = RowReader::open(&input, &args.input_options, &spec)?;
    let cols = Columns::locate(&rows)?;
    let mut header = vec!["t_s", "heading_deg"];
    if cols.acc.is_some() {
        header.extend(["pitch_deg", "roll_deg"]);
    }
    let mut out = CsvOutput::create(&args.output, &header)?;
    let mut count = 0usize;
    let path = rows.path().to_path_buf();
    while let Some(block) = rows.next_rows()? {
        for row in block {
            let (magnetic, tilt) = cols.heading(&cal, &row, &path)?;
            let rad = match declination {
                Some(d) => magnetic.to_true(d).rad(),
                None => magnetic.rad(),
            };
            write_row(
                &mut out,
                args.output_options.precision,
                row[cols.t],
                rad,
                tilt,
            )?;
            count += 1;
        }
    }
    if count == 0 {
        return Err(CliError::row(&path, 2, "no data rows after the header"));
    }
    out.commit()?;
    let north = if declination.is_some() {
        "true"
    } else {
        "magnetic"
    };
    let how = tilt_summary(&cal, cols.acc.is_some());
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

/// The columns a calibration needs, and those it reads if present.
fn columns_read(cal: &CompassCalibration) -> (&'static [&'static str], &'static [&'static str]) {
    match cal {
        CompassCalibration::TwoD(_) => (&["t_s", "mag_x", "mag_y"], &[]),
        _ => (&["t_s", "mag_x", "mag_y", "mag_z"], &ACC),
    }
}

/// Where the columns are in a row.
struct Columns {
    t: usize,
    x: usize,
    y: usize,
    z: Option<usize>,
    acc: Option<[usize; 3]>,
}

impl Columns {
    /// Finds the columns; refuses an input with some of the accelerometer's but not all.
    fn locate(rows: &RowReader) -> CliResult<Self> {
        let ix = |n: &str| rows.index(n).unwrap_or(0);
        let acc = match ACC.map(|n| rows.index(n)) {
            [Some(a), Some(b), Some(c)] => Some([a, b, c]),
            [None, None, None] => None,
            _ => {
                return Err(CliError::row(
                    rows.path(),
                    1,
                    "the input has some of acc_x, acc_y, acc_z but not all three; give all three for tilt compensation, or none to assume a level sensor",
                ));
            }
        };
        Ok(Self {
            t: ix("t_s"),
            x: ix("mag_x"),
            y: ix("mag_y"),
            z: rows.index("mag_z"),
            acc,
        })
    }

    /// The magnetic heading of one row under `cal`, and the tilt when the accelerometer
    /// gives it; a row the calibration cannot use is an error naming it.
    fn heading(
        &self,
        cal: &CompassCalibration,
        row: &RowRef<'_>,
        path: &Path,
    ) -> CliResult<(MagneticHeading, Option<Tilt>)> {
        let (x, y) = (self.x, self.y);
        let mag3 = || Vector3::new(row[x], row[y], self.z.map_or(f64::NAN, |z| row[z]));
        let acc3 = self
            .acc
            .map(|[a, b, c]| Vector3::new(row[a], row[b], row[c]));
        let bad =
            |e: truenorth::core::Error| CliError::row(path, row.number, e.to_string()).kind_of(&e);
        Ok(match (cal, acc3) {
            (CompassCalibration::TwoD(c), _) => {
                (c.magnetic_heading(&Vector2::new(row[x], row[y])), None)
            }
            (CompassCalibration::ThreeD(c), Some(a)) => {
                let tilt = static_tilt(&a).map_err(bad)?;
                (c.magnetic_heading(&mag3(), &tilt), Some(tilt))
            }
            // Level: zero pitch and roll, i.e. the corrected x and y.
            (CompassCalibration::ThreeD(c), None) => {
                (c.magnetic_heading(&mag3(), &Tilt::default()), None)
            }
            (CompassCalibration::Joint(c), Some(a)) => {
                let (h, tilt) = c.attitude(&mag3(), &a).map_err(bad)?;
                (h, Some(tilt))
            }
            (CompassCalibration::Joint(c), None) => {
                let level = truenorth::compass::tilt_compensated_heading(
                    &c.field_body(&mag3()),
                    &Tilt::default(),
                );
                (MagneticHeading::new(level), None)
            }
        })
    }
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
