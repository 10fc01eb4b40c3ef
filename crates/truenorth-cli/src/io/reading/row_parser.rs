//! The parsing of a CSV's rows after the header, shared by the parsing threads, each on
//! its own chunks of lines: a plain row (decimals between delimiters) split and parsed in
//! one pass, any other by the general splitter; each requested cell converted and checked,
//! the row's field count against the header's, the increasing column within the chunk.

use std::path::PathBuf;

use super::chunks::Chunk;
use super::columns::ColumnSource;
use super::plain_rows::{MOST_FIELDS, PlainRows};
use super::records::{Delimiter, MAX_LINE_BYTES, RecordError, record_bounds, split_fields};
use super::row_blocks::{Block, ChunkParser};
use crate::io::{CliError, CliResult};

/// The parsing of the rows after the header: split, convert, check (shared by the
/// parsing threads, each on its own chunks of lines).
pub(super) struct RowParser {
    pub(super) path: PathBuf,
    pub(super) delimiter: Delimiter,
    pub(super) columns: Vec<(ColumnSource, bool)>,
    pub(super) increasing: Option<usize>,
    /// The header's field count: a row with more fields is refused, as is a last line
    /// without a line break that has fewer.
    pub(super) width: usize,
    /// The one-pass reading of plain rows, where the delimiter allows it.
    pub(super) plain: Option<PlainRows>,
}

impl ChunkParser for RowParser {
    fn parse_chunk(&self, chunk: &Chunk, block: &mut Block, spans: &mut Vec<(usize, usize)>) {
        let bytes = chunk.lines();
        let mut number = chunk.line_before;
        let mut cells = [0.0; MOST_FIELDS];
        let mut at = 0;
        while at < bytes.len() {
            number += 1;
            let start = block.values.len();
            let row = if let Some(plain) = &self.plain
                && let Some(len) = plain.read(&bytes[at..], &mut cells)
            {
                at += len + 1;
                block
                    .values
                    .extend(self.columns.iter().map(|(c, _)| c.sign * cells[c.index]));
                self.check_increasing(number, &block.values[start..], &mut block.last_increasing)
            } else {
                let (line, unterminated) = match memchr::memchr(b'\n', &bytes[at..]) {
                    Some(i) => (&bytes[at..at + i], false),
                    None => (&bytes[at..], true),
                };
                at += line.len() + 1;
                if line.len() > MAX_LINE_BYTES {
                    block.end = Some(Err(self.record_error(number, &RecordError::TooLong)));
                    return;
                }
                let Some((a, b)) = record_bounds(line) else {
                    continue;
                };
                split_fields(line, a, b, self.delimiter, spans);
                self.parse_row(
                    number,
                    line,
                    spans,
                    unterminated,
                    &mut block.values,
                    &mut block.last_increasing,
                )
            };
            if let Err(e) = row {
                block.values.truncate(start);
                block.end = Some(Err(e));
                return;
            }
            block.numbers.push(number);
        }
        block.end = chunk.end.as_ref().map(|end| match end {
            Ok(()) => Ok(()),
            Err((row, e)) => Err(self.record_error(*row, e)),
        });
    }

    fn increasing(&self) -> Option<usize> {
        self.increasing
    }

    fn not_after(&self, number: usize, t: f64, previous: f64) -> CliError {
        let k = self.increasing.unwrap_or_default();
        self.columns[k].0.not_after(&self.path, number, t, previous)
    }
}

impl RowParser {
    /// Converts and checks the record of row `number` (its fields at `spans` in `line`),
    /// appending its values to `values` (some of them on an error); `previous` is the
    /// increasing column's last number in the chunk.
    fn parse_row(
        &self,
        number: usize,
        line: &[u8],
        spans: &[(usize, usize)],
        unterminated: bool,
        values: &mut Vec<f64>,
        previous: &mut Option<f64>,
    ) -> CliResult {
        let start = values.len();
        let fields = spans.len();
        if fields > self.width {
            return Err(CliError::row(
                &self.path,
                number,
                format!(
                    "has {fields} fields, the header {}: a decimal comma, or a delimiter inside an unquoted value, would shift the values (fix the row, or quote the value)",
                    self.width
                ),
            ));
        }
        if fields < self.width && unterminated {
            return Err(CliError::row(
                &self.path,
                number,
                format!(
                    "the last line has {fields} fields, the header {}, and no line break: the file looks truncated",
                    self.width
                ),
            ));
        }
        for (c, required) in &self.columns {
            let cell = spans
                .get(c.index)
                .map(|&(a, b)| &line[a..b])
                .ok_or_else(|| {
                    CliError::row(
                        &self.path,
                        number,
                        format!(
                            "has {fields} fields, the header {}: no value for `{}`",
                            self.width, c.name
                        ),
                    )
                })?;
            let v = c
                .read(cell, *required)
                .map_err(|m| CliError::row(&self.path, number, m))?;
            values.push(c.sign * v);
        }
        self.check_increasing(number, &values[start..], previous)
    }

    /// Checks that the increasing column of row `number` (its `values`) comes after
    /// `previous`, the column's last number in the chunk, which it then becomes. Inlined:
    /// it runs once a row, and its error path is a call.
    #[inline]
    fn check_increasing(
        &self,
        number: usize,
        values: &[f64],
        previous: &mut Option<f64>,
    ) -> CliResult {
        if let Some(k) = self.increasing {
            let t = values[k];
            if let Some(prev) = *previous
                && t.partial_cmp(&prev) != Some(std::cmp::Ordering::Greater)
            {
                return Err(self.not_after(number, t, prev));
            }
            if !t.is_nan() {
                *previous = Some(t);
            }
        }
        Ok(())
    }

    /// A record that could not be read at row `number`, as the error naming its row.
    fn record_error(&self, number: usize, e: &RecordError) -> CliError {
        let what = match e {
            RecordError::Io(_) => e.to_string(),
            RecordError::TooLong => format!("malformed CSV: {e}"),
        };
        CliError::row(&self.path, number.max(1), what)
    }
}
