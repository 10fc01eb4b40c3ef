//! The command-line error: one line for stderr naming the file, the row and the problem.

use std::fmt;
use std::path::{Path, PathBuf};

/// A command-line error: one line for stderr.
#[derive(Debug)]
pub struct CliError {
    /// The file concerned, if any.
    pub file: Option<PathBuf>,
    /// The 1-based row of the file (a header is row 1), if any.
    pub row: Option<usize>,
    /// What was wrong.
    pub message: String,
}

impl CliError {
    /// An error not tied to a file.
    pub fn msg(message: impl Into<String>) -> Self {
        Self {
            file: None,
            row: None,
            message: message.into(),
        }
    }

    /// An error about a file.
    pub fn file(file: &Path, message: impl Into<String>) -> Self {
        Self {
            file: Some(file.to_path_buf()),
            row: None,
            message: message.into(),
        }
    }

    /// An error about one row of a file.
    pub fn row(file: &Path, row: usize, message: impl Into<String>) -> Self {
        Self {
            file: Some(file.to_path_buf()),
            row: Some(row),
            message: message.into(),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // One line, whatever a library or the operating system put into the message.
        let message = self.message.replace(['\n', '\r'], " ");
        match (&self.file, self.row) {
            (Some(p), Some(r)) => write!(f, "{}: row {}: {}", p.display(), r, message),
            (Some(p), None) => write!(f, "{}: {}", p.display(), message),
            _ => write!(f, "{message}"),
        }
    }
}

/// Result with [`CliError`].
pub type CliResult<T = ()> = Result<T, CliError>;
