//! The command-line error: one line for stderr naming the file, the row and the problem.

use std::fmt;
use std::path::{Path, PathBuf};

/// What kind of error ended a command: the data refused, or something to fix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// The data cannot support the result (too little turn, too few points, a poor
    /// verdict, a locus that is no ellipse, …): a verdict on the recording, which more or
    /// better data would change.
    Refusal,
    /// Bad input, an I/O error, a wrong option: something to fix before the data can be
    /// judged.
    Failure,
}

impl ErrorKind {
    /// The kind of a library error ([`truenorth::core::Error::is_refusal`]).
    pub fn of(e: &truenorth::core::Error) -> Self {
        if e.is_refusal() {
            Self::Refusal
        } else {
            Self::Failure
        }
    }

    /// Its name as a batch child reports it (`refusal` or `failure`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Refusal => "refusal",
            Self::Failure => "failure",
        }
    }

    /// The kind a batch child reported by [`Self::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        match name.trim() {
            "refusal" => Some(Self::Refusal),
            "failure" => Some(Self::Failure),
            _ => None,
        }
    }
}

/// A command-line error: one line for stderr.
#[derive(Debug)]
pub struct CliError {
    /// The file concerned, if any.
    pub file: Option<PathBuf>,
    /// The 1-based row of the file (a header is row 1), if any.
    pub row: Option<usize>,
    /// What was wrong.
    pub message: String,
    /// Whether the data were refused or something failed; `None` where the code that made
    /// the error did not say (a batch then judges by the message's words).
    pub kind: Option<ErrorKind>,
}

impl CliError {
    /// An error not tied to a file.
    pub fn msg(message: impl Into<String>) -> Self {
        Self {
            file: None,
            row: None,
            message: message.into(),
            kind: None,
        }
    }

    /// An error about a file.
    pub fn file(file: &Path, message: impl Into<String>) -> Self {
        Self {
            file: Some(file.to_path_buf()),
            row: None,
            message: message.into(),
            kind: None,
        }
    }

    /// An error about one row of a file.
    pub fn row(file: &Path, row: usize, message: impl Into<String>) -> Self {
        Self {
            file: Some(file.to_path_buf()),
            row: Some(row),
            message: message.into(),
            kind: None,
        }
    }

    /// The same error, of kind `kind`.
    pub fn with_kind(self, kind: ErrorKind) -> Self {
        Self {
            kind: Some(kind),
            ..self
        }
    }

    /// The same error, a refusal of the data.
    pub fn refusal(self) -> Self {
        self.with_kind(ErrorKind::Refusal)
    }

    /// The same error, of the kind of the library error `e` it reports.
    pub fn kind_of(self, e: &truenorth::core::Error) -> Self {
        self.with_kind(ErrorKind::of(e))
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // One line, whatever a library or the operating system put into the message, and
        // no control character a file's header or name carried to the terminal (an escape
        // sequence would be obeyed, not shown): each is written as its escape.
        let one_line = self.message.replace(['\n', '\r'], " ");
        let message = printable(&one_line);
        match (&self.file, self.row) {
            (Some(p), Some(r)) => {
                write!(
                    f,
                    "{}: row {}: {}",
                    printable(&p.display().to_string()),
                    r,
                    message
                )
            }
            (Some(p), None) => write!(f, "{}: {}", printable(&p.display().to_string()), message),
            _ => write!(f, "{message}"),
        }
    }
}

/// `text` with each control character (an escape sequence's ESC, a bell, a tab) written
/// as its Rust escape, the rest as it is.
fn printable(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return std::borrow::Cow::Borrowed(text);
    }
    std::borrow::Cow::Owned(
        text.chars()
            .map(|c| {
                if c.is_control() {
                    c.escape_default().to_string()
                } else {
                    c.to_string()
                }
            })
            .collect(),
    )
}

/// A library error outside any file, its kind kept.
impl From<truenorth::core::Error> for CliError {
    fn from(e: truenorth::core::Error) -> Self {
        Self::msg(e.to_string()).kind_of(&e)
    }
}

/// Result with [`CliError`].
pub type CliResult<T = ()> = Result<T, CliError>;

#[cfg(test)]
mod tests {
    use super::*;
    use truenorth::core::Error;

    #[test]
    fn control_characters_reach_the_terminal_escaped() {
        let e = CliError::row(
            Path::new("a\u{1b}[2J.csv"),
            1,
            "missing column `\u{1b}]0;x\u{7}t_s`",
        );
        let shown = e.to_string();
        assert!(!shown.chars().any(char::is_control), "{shown:?}");
        assert!(
            shown.contains("\\u{1b}[2J") && shown.contains("\\u{7}t_s"),
            "{shown}"
        );
    }

    #[test]
    fn library_errors_keep_their_kind() {
        let refused = CliError::from(Error::IncompleteTurn {
            turned_deg: 90.0,
            need_deg: 360.0,
        });
        assert_eq!(refused.kind, Some(ErrorKind::Refusal));
        let bad = Error::NonIncreasingTime {
            prev_s: 2.0,
            t_s: 1.0,
        };
        let failed = CliError::row(Path::new("a.csv"), 3, bad.to_string()).kind_of(&bad);
        assert_eq!(failed.kind, Some(ErrorKind::Failure));
        assert_eq!(CliError::msg("x").kind, None);
        for kind in [ErrorKind::Refusal, ErrorKind::Failure] {
            assert_eq!(ErrorKind::from_name(kind.name()), Some(kind));
        }
        assert_eq!(ErrorKind::from_name("refused"), None);
    }
}
