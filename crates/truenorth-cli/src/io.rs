//! CSV and JSON input/output shared by the subcommands, with errors that name the file, the
//! row and the problem.

use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};

/// A command-line error: one line for stderr.
#[derive(Debug)]
pub struct CliError {
    /// The file concerned, if any.
    pub file: Option<PathBuf>,
    /// The 1-based data row (header = row 1), if any.
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
        match (&self.file, self.row) {
            (Some(p), Some(r)) => write!(f, "{}: row {}: {}", p.display(), r, self.message),
            (Some(p), None) => write!(f, "{}: {}", p.display(), self.message),
            _ => write!(f, "{}", self.message),
        }
    }
}

/// Result with [`CliError`].
pub type CliResult<T = ()> = Result<T, CliError>;

/// A numeric CSV table read by column name. Extra columns are ignored.
#[derive(Debug, Clone)]
pub struct Table {
    /// The file it came from.
    pub path: PathBuf,
    columns: HashMap<String, Vec<f64>>,
    rows: usize,
}

impl Table {
    /// Reads `path`, keeping the `required` columns (error if missing) and any `optional`
    /// ones present. Every kept cell must parse as a number; an empty optional cell is NaN.
    pub fn read(path: &Path, required: &[&str], optional: &[&str]) -> CliResult<Self> {
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_path(path)
            .map_err(|e| CliError::file(path, format!("cannot open: {e}")))?;
        let headers = rdr
            .headers()
            .map_err(|e| CliError::row(path, 1, format!("cannot read the header: {e}")))?
            .clone();
        let index = |name: &str| headers.iter().position(|h| h == name);
        let mut wanted: Vec<(String, usize, bool)> = Vec::new();
        for &name in required {
            let i = index(name).ok_or_else(|| {
                CliError::row(
                    path,
                    1,
                    format!(
                        "missing column `{name}` (header has: {})",
                        headers.iter().collect::<Vec<_>>().join(",")
                    ),
                )
            })?;
            wanted.push((name.to_string(), i, true));
        }
        for &name in optional {
            if let Some(i) = index(name) {
                wanted.push((name.to_string(), i, false));
            }
        }
        let mut columns: HashMap<String, Vec<f64>> = wanted
            .iter()
            .map(|(n, _, _)| (n.clone(), Vec::new()))
            .collect();
        let mut rows = 0;
        for (k, rec) in rdr.records().enumerate() {
            let row = k + 2;
            let rec = rec.map_err(|e| CliError::row(path, row, format!("malformed CSV: {e}")))?;
            for (name, i, req) in &wanted {
                let cell = rec.get(*i).unwrap_or("");
                let v = if cell.is_empty() && !req {
                    f64::NAN
                } else {
                    cell.parse::<f64>().map_err(|_| {
                        CliError::row(
                            path,
                            row,
                            format!("column `{name}`: `{cell}` is not a number"),
                        )
                    })?
                };
                if *req && !v.is_finite() {
                    return Err(CliError::row(
                        path,
                        row,
                        format!("column `{name}`: `{cell}` is not finite"),
                    ));
                }
                columns.get_mut(name).map(|c| c.push(v));
            }
            rows += 1;
        }
        Ok(Self {
            path: path.to_path_buf(),
            columns,
            rows,
        })
    }

    /// Number of data rows.
    pub fn len(&self) -> usize {
        self.rows
    }

    /// Whether the table has no data rows.
    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }

    /// A column, if it was read.
    pub fn col(&self, name: &str) -> Option<&[f64]> {
        self.columns.get(name).map(Vec::as_slice)
    }

    /// A required column (read with [`Table::read`]'s `required`, so always present).
    pub fn req(&self, name: &str) -> CliResult<&[f64]> {
        self.col(name)
            .ok_or_else(|| CliError::file(&self.path, format!("missing column `{name}`")))
    }

    /// Checks that `t_s` increases strictly; names the first row where it does not.
    pub fn check_increasing_time(&self) -> CliResult {
        let t = self.req("t_s")?;
        for k in 1..t.len() {
            if t[k] <= t[k - 1] {
                return Err(CliError::row(
                    &self.path,
                    k + 2,
                    format!(
                        "t_s = {} does not come after the previous row's {}; sort by time and drop duplicates",
                        t[k],
                        t[k - 1]
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Writes a CSV with a header row and rows of numbers.
pub fn write_csv(
    path: &Path,
    header: &[&str],
    rows: impl IntoIterator<Item = Vec<f64>>,
) -> CliResult {
    let mut w = csv::Writer::from_path(path)
        .map_err(|e| CliError::file(path, format!("cannot create: {e}")))?;
    w.write_record(header)
        .map_err(|e| CliError::file(path, format!("cannot write: {e}")))?;
    for r in rows {
        w.write_record(r.iter().map(|v| format!("{v}")))
            .map_err(|e| CliError::file(path, format!("cannot write: {e}")))?;
    }
    w.flush()
        .map_err(|e| CliError::file(path, format!("cannot write: {e}")))
}
