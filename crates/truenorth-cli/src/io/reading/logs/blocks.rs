//! A log's table handed to the reader in blocks of rows, as the CSV parser hands over the
//! rows of its chunks: each cell checked as the same number written in a CSV would be, the
//! increasing column checked row to row, the first error delivered after every row before
//! it, and row numbers those of that CSV (its header row 1, the first row 2).

use std::path::PathBuf;

use super::LogTable;
use crate::io::reading::columns::ColumnSource;
use crate::io::reading::number_parse::MOST_MAGNITUDE;
use crate::io::reading::row_blocks::{BLOCK_ROWS, Block};
use crate::io::{CliError, CliResult};

/// The requested columns of a log's table, handed out a block at a time.
#[derive(Debug)]
pub struct LogBlocks {
    path: PathBuf,
    table: LogTable,
    columns: Vec<(ColumnSource, bool)>,
    increasing: Option<usize>,
    /// The next row of the table to check.
    next_row: usize,
    block: Block,
    /// The next row of `block` to hand out.
    next: usize,
    /// The increasing column's last number.
    previous: Option<f64>,
}

impl LogBlocks {
    /// The rows of `table` (read from `path`), each the values of `columns` (required or
    /// not); the column at `increasing` (an index into `columns`) must increase strictly.
    pub fn new(
        path: PathBuf,
        table: LogTable,
        columns: Vec<(ColumnSource, bool)>,
        increasing: Option<usize>,
    ) -> Self {
        Self {
            path,
            table,
            columns,
            increasing,
            next_row: 0,
            block: Block::default(),
            next: 0,
            previous: None,
        }
    }

    /// See [`RowBlocks::next_into`](crate::io::reading::row_blocks::RowBlocks::next_into).
    pub fn next_into(&mut self, values: &mut [f64]) -> CliResult<Option<usize>> {
        if !self.fill()? {
            return Ok(None);
        }
        let (k, n) = (self.next, self.columns.len());
        self.next += 1;
        values.copy_from_slice(&self.block.values[k * n..(k + 1) * n]);
        Ok(Some(self.block.numbers[k]))
    }

    /// See [`RowBlocks::next_rows`](crate::io::reading::row_blocks::RowBlocks::next_rows).
    pub fn next_rows(&mut self) -> CliResult<Option<(&[usize], &[f64])>> {
        if !self.fill()? {
            return Ok(None);
        }
        let k = self.next;
        self.next = self.block.numbers.len();
        Ok(Some((
            &self.block.numbers[k..],
            &self.block.values[k * self.columns.len()..],
        )))
    }

    /// Makes the block one with rows not yet handed out, checking the next rows of the
    /// table as needed; `false` at the end of the table, the first error where it happened
    /// (and `false` after it).
    fn fill(&mut self) -> CliResult<bool> {
        loop {
            if self.next < self.block.numbers.len() {
                return Ok(true);
            }
            if let Some(end) = self.block.end.take() {
                self.block.end = Some(Ok(()));
                return end.map(|()| false);
            }
            self.block.numbers.clear();
            self.block.values.clear();
            self.next = 0;
            let rows = self.table.rows();
            while self.block.numbers.len() < BLOCK_ROWS && self.next_row < rows {
                let k = self.next_row;
                self.next_row += 1;
                let start = self.block.values.len();
                if let Err(e) = self.check_row(k) {
                    self.block.values.truncate(start);
                    self.block.end = Some(Err(e));
                    break;
                }
                // Row k of the table is line k + 2 of the CSV it stands for.
                self.block.numbers.push(k + 2);
            }
            if self.block.end.is_none() && self.next_row == rows {
                self.block.end = Some(Ok(()));
            }
        }
    }

    /// Appends the values of table row `k`, checked as its CSV cells would be.
    fn check_row(&mut self, k: usize) -> CliResult {
        let number = k + 2;
        let start = self.block.values.len();
        let row = self.table.row(k);
        for (c, required) in &self.columns {
            let v = row[c.index];
            let v = if v.abs() <= MOST_MAGNITUDE {
                // A number the CSV's shortest text would give back as it is.
                v
            } else {
                // The cell a CSV of the log would hold: empty for no reading (the time,
                // first, is always written), else the number's shortest text.
                let text = if v.is_nan() && c.index != 0 {
                    String::new()
                } else {
                    v.to_string()
                };
                c.read(text.as_bytes(), *required)
                    .map_err(|m| CliError::row(&self.path, number, m))?
            };
            self.block.values.push(c.sign * v);
        }
        if let Some(i) = self.increasing {
            let t = self.block.values[start + i];
            if let Some(previous) = self.previous
                && t.partial_cmp(&previous) != Some(std::cmp::Ordering::Greater)
            {
                return Err(self.columns[i].0.not_after(&self.path, number, t, previous));
            }
            if !t.is_nan() {
                self.previous = Some(t);
            }
        }
        Ok(())
    }
}
