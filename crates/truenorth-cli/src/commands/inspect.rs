//! `truenorth inspect`: what a recording holds and how to read it — each column's rate,
//! gaps and range, each sensor's likely unit and the gyro's axes against the other
//! sensors', and the options that read it right.

use std::path::PathBuf;

use crate::inspect::report::JsonReport;
use crate::inspect::{COLUMNS, Scan, analyse};
use crate::io::reading::logs::summary;
use crate::io::{CliError, CliResult, Input, InputOptions, ReadSpec};
use crate::io::{out, outln};

/// Arguments of `truenorth inspect`.
///
/// Input: a CSV with `t_s` and any of `gyr_x,gyr_y,gyr_z`, `acc_x,acc_y,acc_z`,
/// `mag_x,mag_y,mag_z`, `dist_l_m,dist_r_m`, `speed_l_mps,speed_r_mps` (read through the
/// same options as the other commands; empty or non-finite cells are counted, not refused).
///
/// Output (stdout): per column its readings, rate (one over the median step of `t_s`), gaps
/// (steps over five median steps: count, the longest and where it ends), range and
/// non-finite cells; per sensor its likely unit (accelerometer: one gravity at rest in m/s2,
/// g or mg; gyro: rad/s or deg/s, by how gravity's and the magnetic field's directions turn;
/// magnetometer: the unit that makes its magnitude an Earth field), the gyro's axes (the
/// best of the 48 signed permutations, with the runner-up and the margin) and the line of
/// options that reads the file right. `--json`: the same as one JSON object.
///
/// Examples: `truenorth inspect imu.csv`; `truenorth inspect log.csv.gz --json --column
/// t_s=time,gyr_x=gx,gyr_y=gy,gyr_z=gz,acc_x=ax,acc_y=ay,acc_z=az`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The recording: a CSV, or a PX4 ULog / ROS 2 MCAP log (its topics are listed)
    /// (`-`: standard input; `.gz` or gzip data read as such).
    pub file: PathBuf,
    /// Write the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// How to read the file (delimiter, header, column names, axes).
    #[command(flatten)]
    pub input_options: InputOptions,
}

/// Runs the subcommand: read the columns, analyse them, print the report.
pub fn run(args: &Args) -> CliResult {
    let spec = ReadSpec::new(&["t_s"]).optional(&COLUMNS);
    let (rows, log) = Input::new(&args.file, &args.input_options).rows(&spec)?;
    let name = rows.path().display().to_string();
    let scan = Scan::read(rows)?;
    let report = analyse(&name, &scan, &args.input_options);
    let failed =
        |e: serde_json::Error| CliError::msg(format!("inspect: cannot write the report: {e}"));
    if args.json {
        // A log's units and axes are its format's: no CSV option reads it otherwise.
        let options = if log.is_some() {
            Vec::new()
        } else {
            report.options()
        };
        let json = JsonReport {
            options,
            report: &report,
        };
        let text = match &log {
            // The report's keys, then the log's (a JSON value would sort them).
            Some(log) => {
                let text = serde_json::to_string_pretty(&json).map_err(failed)?;
                let summary =
                    serde_json::to_string_pretty(&summary::summary_json(log)).map_err(failed)?;
                format!(
                    "{},\n  \"log\": {}\n}}",
                    text.trim_end().trim_end_matches('}').trim_end(),
                    summary.replace('\n', "\n  ")
                )
            }
            None => serde_json::to_string_pretty(&json).map_err(failed)?,
        };
        outln!("{text}")?;
    } else {
        for line in log.iter().flat_map(summary::summary) {
            outln!("{line}")?;
        }
        let table = report.to_table();
        if log.is_some() {
            for line in table.lines().filter(|l| !l.starts_with("options: ")) {
                outln!("{line}")?;
            }
        } else {
            out!("{table}")?;
        }
    }
    Ok(())
}
