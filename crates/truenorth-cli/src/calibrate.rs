//! `truenorth calibrate` (not implemented yet).

use crate::io::{CliError, CliResult};

/// Arguments of `truenorth calibrate`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: &Args) -> CliResult {
    Err(CliError::msg("`calibrate` is not implemented yet"))
}
