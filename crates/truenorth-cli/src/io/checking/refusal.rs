//! What the command does with a finding: refuses the data, naming the file, the row where
//! the evidence became clear and the fix, or, where the user accepts it (`--accept-units`,
//! `--accept-axes`), says it on stderr and goes on.

use std::path::Path;

use truenorth::checks::{Finding, FindingKind};

use super::fixes::say;
use crate::io::reading::options::InputOptions;
use crate::io::{CliError, CliResult, errln};

/// A finding in the command line's words.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refusal {
    /// What it is about, and so which `--accept-*` lets a run go on.
    pub kind: FindingKind,
    /// The evidence and the option that fixes it.
    pub message: String,
    /// The 1-based row of the input where the evidence became clear, if known.
    pub row: Option<usize>,
}

impl Refusal {
    /// `finding`, its fix said as options given after `opts` (those the file was read
    /// with).
    pub fn of(finding: &Finding, opts: &InputOptions) -> Self {
        Self {
            kind: finding.kind,
            message: say(finding, opts),
            row: finding.row,
        }
    }
}

/// Each of `findings` in the command line's words ([`Refusal::of`]).
pub fn refusals(findings: &[Finding], opts: &InputOptions) -> Vec<Refusal> {
    findings.iter().map(|f| Refusal::of(f, opts)).collect()
}

/// Acts on `refusals` about `input`: refuses on the first one not accepted (its message
/// and the `--accept-*` flag that would go on), says each accepted one on stderr.
pub fn refuse_or_warn(
    refusals: &[Refusal],
    input: &Path,
    accept_units: bool,
    accept_axes: bool,
) -> CliResult {
    for refusal in refusals {
        let (accepted, flag) = match refusal.kind {
            FindingKind::Units => (accept_units, "--accept-units"),
            FindingKind::Axes => (accept_axes, "--accept-axes"),
        };
        if accepted {
            errln!("warning: {}: {}", input.display(), refusal.message);
        } else {
            let message = format!("{} (or {flag} to go on)", refusal.message);
            return Err(match refusal.row {
                Some(row) => CliError::row(input, row, message),
                None => CliError::file(input, message),
            });
        }
    }
    Ok(())
}
