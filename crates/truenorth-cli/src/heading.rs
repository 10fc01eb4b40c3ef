//! `truenorth heading`: apply a compass calibration to a recording and write the heading.

use std::path::PathBuf;

use nalgebra::{Vector2, Vector3};
use truenorth::core::{Tilt, rad_to_deg, wrap_two_pi};

use crate::io::{CalibrationFile, CliResult, CompassCalibration, Table, write_csv};

/// Arguments of `truenorth heading`.
///
/// Input: CSV with `t_s,mag_x,mag_y` (plus `mag_z` for a 3-D calibration), strictly
/// increasing time, other columns ignored. Output: CSV `t_s,heading_deg`, the magnetic
/// heading in degrees clockwise from magnetic north, in [0, 360).
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
    // Integrator: `--lat/--lon/--date` go here; see `reference_offset_rad`.
}

/// What to add to the magnetic heading to get the heading that is written: 0 (magnetic
/// north) for now.
///
/// Integrator: with `--lat/--lon/--date` this returns the World Magnetic Model declination
/// at that place and date (east positive), turning the output into true heading; the
/// header of the output stays `heading_deg` and `--help` must say which north it is.
fn reference_offset_rad(_args: &Args) -> CliResult<f64> {
    Ok(0.0)
}

/// Runs the subcommand.
pub fn run(args: &Args) -> CliResult {
    let (_, cal) = CalibrationFile::read(&args.calibration)?;
    let offset = reference_offset_rad(args)?;
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
            (CompassCalibration::TwoD(c), _) => c.heading_rad(&Vector2::new(x[k], y[k])),
            // Level: zero pitch and roll, i.e. the corrected x and y.
            (CompassCalibration::ThreeD(c), Some(z)) => {
                c.heading_rad(&Vector3::new(x[k], y[k], z[k]), &Tilt::default())
            }
            (CompassCalibration::ThreeD(_), None) => f64::NAN,
        };
        vec![t[k], rad_to_deg(wrap_two_pi(magnetic + offset))]
    });
    write_csv(&args.output, &["t_s", "heading_deg"], rows)
}
