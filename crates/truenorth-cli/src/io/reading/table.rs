//! The whole-table read, built on the streaming [`RowReader`]: every requested column in
//! memory, for commands that need all the readings at once (a batch calibration).

use std::collections::HashMap;
use std::path::PathBuf;

use super::options::InputOptions;
use super::reader::{ReadSpec, RowReader};
use super::source::InputPath;
use crate::io::{CliError, CliResult};

/// A numeric CSV table read by column name. Extra columns are ignored.
#[derive(Debug, Clone)]
pub struct Table {
    /// The file it came from (`<stdin>` for standard input).
    pub path: PathBuf,
    columns: HashMap<String, Vec<f64>>,
    /// The file row of each data row (a header is row 1).
    row_numbers: Vec<usize>,
}

impl Table {
    /// Reads every row of `input` under `opts` (delimiter, column mapping, axis convention)
    /// and `spec` (see [`RowReader::open`]): the required columns (error if missing) and any
    /// optional ones present. Every kept cell must parse as a number; an empty optional cell
    /// is NaN.
    pub fn read_with(
        input: &InputPath,
        opts: &InputOptions,
        spec: &ReadSpec<'_>,
    ) -> CliResult<Self> {
        Self::read(RowReader::open(input, opts, spec)?)
    }

    /// Every row `reader` has left.
    pub fn read(mut reader: RowReader) -> CliResult<Self> {
        let names: Vec<String> = reader.names().map(String::from).collect();
        let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
        let mut row_numbers = Vec::new();
        while let Some(row) = reader.next_row()? {
            for (c, &v) in cols.iter_mut().zip(&row.values) {
                c.push(v);
            }
            row_numbers.push(row.number);
        }
        Ok(Self {
            path: reader.path().to_path_buf(),
            columns: names.into_iter().zip(cols).collect(),
            row_numbers,
        })
    }

    /// Number of data rows.
    pub fn len(&self) -> usize {
        self.row_numbers.len()
    }

    /// Whether the table has no data rows.
    pub fn is_empty(&self) -> bool {
        self.row_numbers.is_empty()
    }

    /// The file row of data row `k` (for error messages).
    pub fn row_number(&self, k: usize) -> usize {
        self.row_numbers.get(k).copied().unwrap_or(k + 2)
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

    /// Refuses a table with a header but no data rows.
    pub fn require_rows(&self) -> CliResult {
        if self.is_empty() {
            Err(CliError::row(
                &self.path,
                2,
                "no data rows after the header",
            ))
        } else {
            Ok(())
        }
    }

    /// Checks that `t_s` increases strictly; names the first row where it does not.
    pub fn check_increasing_time(&self) -> CliResult {
        let t = self.req("t_s")?;
        for k in 1..t.len() {
            if t[k] <= t[k - 1] {
                return Err(CliError::row(
                    &self.path,
                    self.row_number(k),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{Precision, write_csv};
    use proptest::prelude::*;
    use std::path::Path;

    /// The table under the default input options.
    fn read(path: &Path, required: &[&str], optional: &[&str]) -> CliResult<Table> {
        let spec = ReadSpec::new(required).optional(optional);
        Table::read_with(&InputPath::new(path), &InputOptions::default(), &spec)
    }

    /// A file holding `contents`, removed when dropped (also when a case fails).
    fn temp_file(tag: &str, contents: &[u8]) -> tempfile::NamedTempFile {
        let file = tempfile::Builder::new()
            .prefix(&format!("truenorth-io-{tag}-"))
            .tempfile()
            .expect("temp dir is writable");
        std::fs::write(file.path(), contents).expect("temp dir is writable");
        file
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// What write_csv writes, Table::read reads back exactly (Rust prints the shortest
        /// text that parses back to the same f64).
        #[test]
        fn write_then_read_round_trips(rows in proptest::collection::vec((-1e12f64..1e12, -1e6f64..1e6), 1..50)) {
            let file = temp_file("rt", b"");
            let path = file.path();
            write_csv(path, &["t_s", "mag_x"], rows.iter().map(|&(a, b)| vec![a, b]), Precision::default()).unwrap();
            let t = read(path, &["t_s", "mag_x"], &["mag_z"]).unwrap();
            prop_assert_eq!(t.len(), rows.len());
            prop_assert!(t.col("mag_z").is_none());
            for (k, &(a, b)) in rows.iter().enumerate() {
                prop_assert_eq!(t.req("t_s").unwrap()[k], a);
                prop_assert_eq!(t.req("mag_x").unwrap()[k], b);
            }
        }

        /// Any bytes at all: a table or a one-line error naming the file, never a panic.
        #[test]
        fn any_file_reads_or_fails_with_one_line(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let file = temp_file("any", &bytes);
            let path = file.path();
            match read(path, &["t_s"], &["mag_x"]) {
                Ok(t) => prop_assert!(t.req("t_s").unwrap().iter().all(|v| v.is_finite())),
                Err(e) => {
                    let line = e.to_string();
                    prop_assert!(!line.contains('\n'), "{}", line);
                    prop_assert!(line.contains("truenorth-io-any"), "{}", line);
                }
            }
        }
    }
}
