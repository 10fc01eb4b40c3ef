//! `truenorth demo`: the simulator and every method on it, with a results table.
//!
//! The sections in the order they print, one private module each: the scenarios
//! (`scenarios`), each sensor alone (`sensors`), compass calibration (`compass`), vehicle
//! dead reckoning (`drive`) and orientation (`orientation`).

mod compass;
mod drive;
mod orientation;
mod scenarios;
mod sensors;

use std::path::PathBuf;

use crate::io::outln;
use crate::io::{CliError, CliResult};

/// Arguments of `truenorth demo`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder for plots and CSV artefacts.
    #[arg(long, default_value = "truenorth-demo")]
    pub out: PathBuf,
    /// Random seed of the simulation.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// Runs the demo.
pub fn run(args: &Args) -> CliResult {
    std::fs::create_dir_all(&args.out)
        .map_err(|e| CliError::file(&args.out, format!("cannot create the output folder: {e}")))?;
    outln!("truenorth demo (seed {})\n", args.seed)?;
    scenarios::scenario_table()?;
    let drive = sensors::DemoDrive::new(args.seed)?;
    sensors::sensor_table(&drive)?;
    compass::compass_section(&drive, &args.out)?;
    drive::drive_section(args.seed, &args.out)?;
    orientation::orientation_section(args.seed, &args.out)?;
    Ok(())
}
