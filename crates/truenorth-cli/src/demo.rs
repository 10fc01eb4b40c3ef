//! `truenorth demo`: the simulator and every method on it, with a results table.

use std::path::PathBuf;

use crate::io::CliResult;

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
pub fn run(_args: &Args) -> CliResult {
    Ok(())
}
