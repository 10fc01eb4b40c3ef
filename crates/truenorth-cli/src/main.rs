//! `truenorth`: calibrate compasses, compute heading, and run the simulator demo from the
//! command line. The CSV/JSON contract is in ARCHITECTURE.md, section "CLI contract", and in
//! each subcommand's `--help`. Errors exit non-zero with one line on stderr naming the file, the row and the
//! problem.

use truenorth_cli::{commands, demo, eval, io};

use std::io::IsTerminal as _;
use std::process::ExitCode;

use clap::error::ErrorKind;
use clap::{Parser, Subcommand};

use commands::{batch, calibrate, drive, field, heading, inspect as inspect_cmd, orientation};

/// Calibrated heading, orientation and dead reckoning from low-cost navigation sensors.
///
/// Frames: body x forward, y right, z down; heading clockwise from north; a level compass
/// reads mag_x = H cos(heading), mag_y = -H sin(heading).
#[derive(Debug, Parser)]
#[command(name = "truenorth", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run every method on a simulated drive and print a results table.
    Demo(demo::Args),
    /// Fit a compass calibration (or magnetometer and accelerometer together) to a
    /// recording, with a verdict on its quality.
    Calibrate(calibrate::Args),
    /// Apply a compass calibration to a recording and output heading (from magnetic north;
    /// from true north with --lat/--lon), tilt-compensated when the input has
    /// acc_x,acc_y,acc_z and the calibration is 3-D; otherwise for a level sensor.
    Heading(heading::Args),
    /// The World Magnetic Model 2025 field at a place and date.
    Field(field::Args),
    /// Estimate orientation from an IMU recording (gyro, accelerometer, optional
    /// magnetometer).
    Orientation(orientation::Args),
    /// Vehicle heading and dead reckoning from wheels, an optional yaw gyro and an
    /// uncalibrated compass, every sensor calibrated from the drive itself.
    Drive(drive::Args),
    /// What a recording holds: each column's rate, gaps and range, each sensor's likely
    /// unit, the gyro's axes against the other sensors', and the options that read it.
    Inspect(inspect_cmd::Args),
    /// Run calibrate, heading, orientation, drive or inspect over folders of recordings,
    /// one process per file on every core, with a results table; a rerun skips what is
    /// done.
    Batch(batch::Args),
    /// Evaluate an orientation method on a benchmark with ground truth.
    #[command(subcommand)]
    Eval(EvalCommand),
}

#[derive(Debug, Subcommand)]
enum EvalCommand {
    /// The BROAD benchmark (its trial folder, BROAD's own error metric).
    Broad(eval::broad::Args),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return help_or_usage_error(&e),
    };
    let result = match cli.command {
        Command::Demo(a) => demo::run(&a),
        Command::Calibrate(a) => calibrate::run(&a),
        Command::Heading(a) => heading::run(&a),
        Command::Field(a) => field::run(&a),
        Command::Orientation(a) => orientation::run(&a),
        Command::Drive(a) => drive::run(&a),
        Command::Inspect(a) => inspect_cmd::run(&a),
        Command::Eval(EvalCommand::Broad(a)) => eval::broad::run(&a),
        Command::Batch(a) => match batch::run(&a) {
            Ok(code) => return ExitCode::from(code),
            Err(e) => Err(e),
        },
    };
    if std::env::var_os(batch::child::CHILD_ENV).is_some() {
        // For the batch that started this run: the rows read, on the last line.
        io::write_stderr(format_args!(
            "{}{}\n",
            batch::child::STATS_PREFIX,
            io::rows_read()
        ));
        // And whether an error refused the data or failed, where the code that made it
        // said (the batch judges by the message's words otherwise).
        if let Err(io::CliError {
            kind: Some(kind), ..
        }) = &result
        {
            io::write_stderr(format_args!(
                "{}{}\n",
                batch::child::KIND_PREFIX,
                kind.name()
            ));
        }
    }
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Never panics, whatever stderr is (a closed pipe, a full disk).
            io::write_stderr(format_args!("truenorth: {e}\n"));
            ExitCode::FAILURE
        }
    }
}

/// The help or version text that `e` carries, on standard output; a usage error as clap
/// reports it. clap's own printing ignores a failed write (`--help >/dev/full` would succeed),
/// so the text goes through [`io::write_stdout`] as every other output does; a terminal
/// keeps clap's printing, with its colours.
fn help_or_usage_error(e: &clap::Error) -> ExitCode {
    let shown = matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion);
    if !shown || std::io::stdout().is_terminal() {
        e.exit();
    }
    match io::write_stdout(format_args!("{}", e.render())) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            io::write_stderr(format_args!("truenorth: {err}\n"));
            ExitCode::FAILURE
        }
    }
}
