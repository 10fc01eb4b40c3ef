//! A command's rows as its samples: a [`SampleKind`] names the columns it reads and makes the
//! sample of a row; [`Samples`] hands them out in file order, with their row numbers, and
//! gives every command the same error for a file without data rows.

use std::path::{Path, PathBuf};

use super::reader::{RowReader, RowRef};
use crate::io::{CliError, CliResult};

/// A kind of sample a command reads: its columns and how a row becomes one.
pub trait SampleKind {
    /// What a row becomes.
    type Sample;

    /// The columns needed and those read where present (`t_s`, wherever it is, must
    /// increase strictly).
    fn columns(&self) -> (&'static [&'static str], &'static [&'static str]);

    /// Finds its columns among those `rows` read; an error for a set of columns the kind
    /// cannot use (a vector with some of its axes, no sensor at all).
    fn locate(&mut self, rows: &RowReader) -> CliResult<()>;

    /// The sample of `row` of the file at `path` (an error names the row).
    fn sample(&mut self, row: &RowRef<'_>, path: &Path) -> CliResult<Self::Sample>;
}

/// The samples of an input, in file order.
pub struct Samples<K> {
    rows: RowReader,
    path: PathBuf,
    kind: K,
    /// Samples handed out.
    count: usize,
}

impl<K: SampleKind> Samples<K> {
    /// The samples of kind `kind` (its columns located) of `rows`.
    pub(super) fn new(rows: RowReader, kind: K) -> Self {
        Self {
            path: rows.path().to_path_buf(),
            rows,
            kind,
            count: 0,
        }
    }

    /// The file, for messages (`<stdin>` for standard input).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The kind, with what it found among the columns.
    pub fn kind(&self) -> &K {
        &self.kind
    }

    /// Hands every sample, with its row number, to `f` in file order; the number of
    /// samples. The first error ends it: a row that cannot be read, or `f`'s own.
    pub fn for_each(
        &mut self,
        mut f: impl FnMut(usize, K::Sample) -> CliResult,
    ) -> CliResult<usize> {
        while let Some(block) = self.rows.next_rows()? {
            for row in block {
                f(row.number, self.kind.sample(&row, &self.path)?)?;
                self.count += 1;
            }
        }
        self.end()
    }

    /// The next sample and its row number; `None` at the end.
    pub fn next_sample(&mut self) -> CliResult<Option<(usize, K::Sample)>> {
        let Some(row) = self.rows.next_row()? else {
            self.end()?;
            return Ok(None);
        };
        let row = RowRef {
            number: row.number,
            values: &row.values,
        };
        let sample = self.kind.sample(&row, &self.path)?;
        self.count += 1;
        Ok(Some((row.number, sample)))
    }

    /// The end of the rows: the number of samples, or, without any, the error of a file
    /// that has no data rows.
    fn end(&self) -> CliResult<usize> {
        if self.count == 0 {
            return Err(CliError::row(
                &self.path,
                2,
                "no data rows after the header",
            ));
        }
        Ok(self.count)
    }
}
