//! `truenorth field` (not implemented yet).

use crate::io::{CliError, CliResult};

/// Arguments of `truenorth field`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: &Args) -> CliResult {
    Err(CliError::msg("`field` is not implemented yet"))
}
