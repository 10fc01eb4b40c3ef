//! `truenorth heading`: apply a compass calibration to a recording and write the heading.

use std::path::PathBuf;

use nalgebra::{Vector2, Vector3};
use truenorth::core::{Declination, MagneticHeading, Tilt, rad_to_deg};

use crate::field::Place;
use crate::io::{
    CalibrationFile, CliError, CliResult, CompassCalibration, CsvOutput, InputOptions, InputPath,
    ReadSpec, RowReader, check_distinct,
};

/// Arguments of `truenorth heading`.
///
/// Input: CSV with `t_s,mag_x,mag_y` (plus `mag_z` for a 3-D calibration), strictly
/// increasing time, other columns ignored. Output: CSV `t_s,heading_deg`, in degrees
/// clockwise in [0, 360): from magnetic north, or, with `--lat` and `--lon` (and optionally
/// `--date`, default today), from true north — magnetic heading plus the World Magnetic
/// Model 2025 declination at that place and date.
///
/// A 2-D calibration gives `heading = atan2(−y, x)` of the corrected (x, y). A 3-D
/// calibration corrects all three axes and takes the heading from the corrected x and y,
/// which is right for a level sensor only (body x forward, y right, z down); a tilted
/// sensor needs tilt compensation, which this command does not do.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Calibration JSON written by `truenorth calibrate`.
    #[arg(long)]
    pub calibration: PathBuf,
    /// Input CSV (`-`: standard input; `.gz` or gzip data read as such).
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

/// Runs the subcommand.
pub fn run(args: &Args) -> CliResult {
    check_distinct(&args.output, &[&args.input, &args.calibration])?;
    let (_, cal) = CalibrationFile::read(&args.calibration)?;
    let declination = declination(args)?;
    let needed: &[&str] = match cal {
        CompassCalibration::TwoD(_) => &["t_s", "mag_x", "mag_y"],
        CompassCalibration::ThreeD(_) => &["t_s", "mag_x", "mag_y", "mag_z"],
    };
    let spec = ReadSpec::new(needed).increasing("t_s");
    let mut rows = RowReader::open(&InputPath::new(&args.input), &args.input_options, &spec)?;
    let ix = |n: &str| rows.index(n).unwrap_or(0);
    let (t, x, y) = (ix("t_s"), ix("mag_x"), ix("mag_y"));
    let z = rows.index("mag_z");
    let mut out = CsvOutput::create(&args.output, &["t_s", "heading_deg"])?;
    let mut count = 0usize;
    while let Some(row) = rows.next_row()? {
        let magnetic = match (&cal, z) {
            (CompassCalibration::TwoD(c), _) => c.magnetic_heading(&Vector2::new(row[x], row[y])),
            // Level: zero pitch and roll, i.e. the corrected x and y.
            (CompassCalibration::ThreeD(c), Some(z)) => {
                c.magnetic_heading(&Vector3::new(row[x], row[y], row[z]), &Tilt::default())
            }
            (CompassCalibration::ThreeD(_), None) => MagneticHeading::new(f64::NAN),
        };
        let rad = match declination {
            Some(d) => magnetic.to_true(d).rad(),
            None => magnetic.rad(),
        };
        out.row(&[row[t], rad_to_deg(rad)])?;
        count += 1;
    }
    if count == 0 {
        return Err(CliError::row(
            rows.path(),
            2,
            "no data rows after the header",
        ));
    }
    out.commit()?;
    eprintln!("truenorth: heading: {count} rows");
    Ok(())
}
