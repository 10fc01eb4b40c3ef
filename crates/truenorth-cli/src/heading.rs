//! `truenorth heading` (not implemented yet).

use crate::io::{CliError, CliResult};

/// Arguments of `truenorth heading`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: &Args) -> CliResult {
    Err(CliError::msg("`heading` is not implemented yet"))
}
