//! `truenorth heading`: apply a compass calibration to a recording and write the heading.

use std::path::PathBuf;

use nalgebra::{Vector2, Vector3};
use truenorth::core::{Declination, MagneticHeading, Tilt, rad_to_deg};

use crate::field::Place;
use crate::io::{
    CalibrationFile, CliError, CliResult, CompassCalibration, Table, check_distinct, write_csv,
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
    /// Input CSV.
    #[arg(long)]
    pub input: PathBuf,
    /// Output CSV.
    #[arg(long)]
    pub output: PathBuf,
    /// Where and when the recording was made, for true heading.
    #[command(flatten)]
    pub place: Place,
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
    let table = Table::read(&args.input, needed, &[])?;
    table.require_rows()?;
    table.check_increasing_time()?;
    let (t, x, y) = (table.req("t_s")?, table.req("mag_x")?, table.req("mag_y")?);
    let z = match cal {
        CompassCalibration::ThreeD(_) => Some(table.req("mag_z")?),
        CompassCalibration::TwoD(_) => None,
    };
    let rows = (0..table.len()).map(|k| {
        let magnetic = match (&cal, z) {
            (CompassCalibration::TwoD(c), _) => c.magnetic_heading(&Vector2::new(x[k], y[k])),
            // Level: zero pitch and roll, i.e. the corrected x and y.
            (CompassCalibration::ThreeD(c), Some(z)) => {
                c.magnetic_heading(&Vector3::new(x[k], y[k], z[k]), &Tilt::default())
            }
            (CompassCalibration::ThreeD(_), None) => MagneticHeading::new(f64::NAN),
        };
        let rad = match declination {
            Some(d) => magnetic.to_true(d).rad(),
            None => magnetic.rad(),
        };
        vec![t[k], rad_to_deg(rad)]
    });
    write_csv(&args.output, &["t_s", "heading_deg"], rows)
}
