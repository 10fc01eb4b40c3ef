//! The results table: one row per file (its path, content hash, status, exit code, the
//! one-line message of a run that did not succeed, samples read, seconds, output, and a
//! calibration's verdict), written as CSV or JSON, whole or not at all.

use std::io::Write;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::io::{CliResult, write_atomically};

/// What became of one file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Status {
    /// The command succeeded and wrote the output.
    Ok,
    /// The command ran to its end and declined the data with its reason (a calibration
    /// too poor to use, a field or unit that does not match): a verdict on the recording.
    Refused,
    /// The command could not use the file (unreadable, corrupt, empty), ended by a signal
    /// or a crash, or could not be started.
    Failed,
    /// Done by an earlier batch with the same bytes and the same command: not run again.
    SkippedDone,
}

impl Status {
    /// The name in the table.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::Refused => "refused",
            Self::Failed => "failed",
            Self::SkippedDone => "skipped-done",
        }
    }
}

/// One row of the table (and, with the command, one line of the journal).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// The input as the command was given it.
    pub path: String,
    /// SHA-256 of the input's bytes, hexadecimal (empty when it could not be read).
    pub hash: String,
    /// What became of it in this batch.
    pub status: Status,
    /// The status of the run that made the output: `status` itself, or for a file
    /// skipped as done, what its earlier run ended with.
    pub outcome: Status,
    /// The command's exit code (none: ended by a signal, or never started).
    pub exit_code: Option<i32>,
    /// The command's one-line message when it did not succeed (empty otherwise).
    pub message: String,
    /// Rows the command read (none when it did not say: a crash, or never started).
    pub samples: Option<u64>,
    /// Wall-clock seconds of the run (0 for a file not run).
    pub seconds: f64,
    /// The output file (empty when nothing was written).
    pub output: String,
    /// A calibration's verdict (`good`, `fair`, `poor`) from its output file.
    pub verdict: Option<String>,
}

/// The CSV columns, in order.
const HEADER: [&str; 10] = [
    "path",
    "hash",
    "status",
    "outcome",
    "exit_code",
    "message",
    "samples",
    "seconds",
    "output",
    "verdict",
];

/// Writes `rows` to `path`: JSON (an array of objects) for a name ending in `.json`, CSV
/// otherwise; atomically, so a kill leaves the previous table whole.
pub fn write(path: &Path, rows: &[Row]) -> CliResult {
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    write_atomically(path, |w| {
        if json {
            serde_json::to_writer_pretty(&mut *w, rows)?;
            w.write_all(b"\n")?;
        } else {
            write_csv(w, rows)?;
        }
        Ok(())
    })
}

fn write_csv(w: &mut dyn Write, rows: &[Row]) -> std::io::Result<()> {
    writeln!(w, "{}", HEADER.join(","))?;
    for r in rows {
        let cells = [
            quoted(&r.path),
            r.hash.clone(),
            r.status.name().to_string(),
            r.outcome.name().to_string(),
            r.exit_code.map(|c| c.to_string()).unwrap_or_default(),
            quoted(&r.message),
            r.samples.map(|s| s.to_string()).unwrap_or_default(),
            format!("{:.3}", r.seconds),
            quoted(&r.output),
            r.verdict.clone().unwrap_or_default(),
        ];
        writeln!(w, "{}", cells.join(","))?;
    }
    Ok(())
}

/// A CSV cell (RFC 4180): quoted when it holds a comma, a quote or a line break, quotes
/// doubled.
fn quoted(cell: &str) -> String {
    if cell.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", cell.replace('"', "\"\""))
    } else {
        cell.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_with_commas_and_quotes_are_quoted() {
        assert_eq!(quoted("a.csv"), "a.csv");
        assert_eq!(quoted("row 2: `x,y`"), "\"row 2: `x,y`\"");
        assert_eq!(quoted("say \"hi\""), "\"say \"\"hi\"\"\"");
    }

    #[test]
    fn statuses_are_named_as_in_the_table() {
        let json = serde_json::to_string(&Status::SkippedDone).unwrap();
        assert_eq!(json, "\"skipped-done\"");
        assert_eq!(Status::SkippedDone.name(), "skipped-done");
    }
}
