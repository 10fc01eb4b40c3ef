//! The streaming CSV reader: opens a file or standard input (gzip or not), resolves the
//! requested columns through the header, the column mapping and the axis convention, and
//! yields one row at a time as numbers, so that memory does not grow with the file.
//!
//! ```ignore
//! let spec = ReadSpec::new(&["t_s", "mag_x", "mag_y"]).optional(&["gyr_z"]).increasing("t_s");
//! let mut rows = RowReader::open(&InputPath::new(path), &opts, &spec)?;
//! let (t, x) = (rows.index("t_s").unwrap(), rows.index("mag_x").unwrap());
//! while let Some(row) = rows.next_row()? {
//!     use_reading(row.number, row[t], row[x]);
//! }
//! ```

use std::path::{Path, PathBuf};

use super::chunks::ChunkCutter;
use super::columns::{ColumnSource, Header, Naming};
use super::logs::LogTable;
use super::logs::blocks::LogBlocks;
use super::options::InputOptions;
use super::plain_rows::PlainRows;
use super::records::{Delimiter, Records};
use super::row_blocks::{BLOCK_ROWS, RowBlocks};
use super::row_parser::RowParser;
use super::source::InputPath;
use crate::io::{CliError, CliResult, errln};

/// The columns a command reads.
#[derive(Debug, Clone, Copy, Default)]
pub struct ReadSpec<'a> {
    /// Columns that must be present; each cell must be a finite number within ±2^53
    /// (`number_parse::MOST_MAGNITUDE`).
    pub required: &'a [&'a str],
    /// Columns read when present; an empty cell (or `nan`) reads as NaN, any other within
    /// ±2^53 as for a required column.
    pub optional: &'a [&'a str],
    /// A column (required or optional) whose values must increase strictly, e.g. `t_s`.
    pub increasing: Option<&'a str>,
}

impl<'a> ReadSpec<'a> {
    /// Reads the `required` columns.
    pub fn new(required: &'a [&'a str]) -> Self {
        Self {
            required,
            ..Self::default()
        }
    }

    /// Also reads the `optional` columns that are present.
    pub fn optional(mut self, optional: &'a [&'a str]) -> Self {
        self.optional = optional;
        self
    }

    /// Requires the values of `column` to increase strictly from row to row.
    pub fn increasing(mut self, column: &'a str) -> Self {
        self.increasing = Some(column);
        self
    }
}

/// One data row: its number in the file (a header is row 1; comment lines count) and the
/// values of the columns read, in [`RowReader::names`] order.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The 1-based line of the file it was read from.
    pub number: usize,
    /// The values, in the reader's column order.
    pub values: Vec<f64>,
}

impl std::ops::Index<usize> for Row {
    type Output = f64;

    fn index(&self, i: usize) -> &f64 {
        &self.values[i]
    }
}

/// A data row seen where it lies in the reader's current block (see
/// [`RowReader::next_rows`]): a [`Row`] without the copy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RowRef<'a> {
    /// The 1-based line of the file it was read from.
    pub number: usize,
    /// The values, in the reader's column order.
    pub values: &'a [f64],
}

impl std::ops::Index<usize> for RowRef<'_> {
    type Output = f64;

    fn index(&self, i: usize) -> &f64 {
        &self.values[i]
    }
}

/// A streaming reader of the requested numeric columns of a CSV (see the module
/// documentation). It holds one row at a time; the file is read on a second thread and
/// parsed, in chunks, on two more, a few blocks of rows ahead (see the `row_blocks`
/// module), with the same numbers and errors as a read on one thread. The rows of a flight
/// or robot log come through it too ([`RowReader::from_log`]), with the same checks.
pub struct RowReader {
    path: PathBuf,
    names: Vec<String>,
    blocks: Blocks,
    row: Row,
    /// Rows handed out and not yet added to the process's count (added when dropped: one
    /// atomic addition a reader, not a row).
    handed: u64,
}

impl std::fmt::Debug for RowReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RowReader")
            .field("path", &self.path)
            .field("columns", &self.names)
            .finish_non_exhaustive()
    }
}

/// Where the rows come from: a CSV parsed on other threads, or a log's table.
enum Blocks {
    Csv(RowBlocks),
    Log(LogBlocks),
}

impl RowReader {
    /// Opens `input` and resolves the columns of `spec` through its header (or, with
    /// `--no-header`, through the column numbers) under `opts`. Errors name the file and
    /// row: a missing required column, a column named twice, a mapping to no column.
    ///
    /// A left-handed `--axes` (a mirror image of frd) is allowed, with a warning on stderr:
    /// it reverses every turn.
    pub fn open(input: &InputPath, opts: &InputOptions, spec: &ReadSpec<'_>) -> CliResult<Self> {
        Self::open_chunked(input, opts, spec, BLOCK_ROWS, None)
    }

    /// [`RowReader::open`] with chunks of at most `chunk_lines` lines and `workers`
    /// parsing threads (`None`: as many as the machine has cores, up to two), so that
    /// tests can put chunk boundaries anywhere.
    pub(crate) fn open_chunked(
        input: &InputPath,
        opts: &InputOptions,
        spec: &ReadSpec<'_>,
        chunk_lines: usize,
        workers: Option<usize>,
    ) -> CliResult<Self> {
        let path = input.display_path();
        let mut records = Records::new(input.open()?, Delimiter::Whitespace);
        let more = records
            .advance()
            .map_err(|e| CliError::row(&path, records.line().max(1), e.to_string()))?;
        if !more {
            return Err(CliError::row(&path, 1, "empty file: no header row"));
        }
        let delimiter = match opts.delimiter {
            Delimiter::Auto => Delimiter::detect(&records.text()),
            d => d,
        };
        records.resplit(delimiter);
        let header = if opts.no_header {
            // The first record is data: count its fields, and return it as the first row.
            Header::numbered(records.len())
        } else {
            Header::new(records.text_fields().iter().map(String::as_str))
        };
        let header_row = if opts.no_header {
            0
        } else {
            records.line().max(1)
        };
        let columns = resolve(&header, spec, opts.naming(), &path, header_row.max(1))?;
        if !opts.axes.is_right_handed() {
            errln!(
                "truenorth: warning: {}: --axes {} is a mirror image of frd (left-handed): every turn reads reversed",
                path.display(),
                opts.axes
            );
        }
        let increasing = increasing(&columns, spec);
        let n = columns.len();
        let names = columns.iter().map(|(c, _)| c.name.clone()).collect();
        let width = header.names().len();
        let plain = match delimiter {
            Delimiter::Byte(d) => PlainRows::new(d, width, columns.iter().map(|(c, _)| c.index)),
            _ => None,
        };
        let parser = RowParser {
            path: path.clone(),
            delimiter,
            columns,
            increasing,
            width,
            plain,
        };
        // With `--no-header` the first record is data: the parsers read it again.
        let (source, rest, lines, eof) = records.into_rest(opts.no_header);
        let cutter = ChunkCutter::new(source, rest, lines, eof, chunk_lines);
        let blocks = match workers {
            None => RowBlocks::spawn(cutter, parser, n),
            Some(w) => RowBlocks::spawn_with(cutter, std::sync::Arc::new(parser), n, w),
        }
        .map_err(|e| CliError::file(&path, format!("cannot start the reader: {e}")))?;
        Ok(Self {
            path,
            names,
            blocks: Blocks::Csv(blocks),
            row: Row {
                number: header_row,
                values: vec![0.0; n],
            },
            handed: 0,
        })
    }

    /// The rows of a flight or robot log's `table` (made by [`logs::read`](super::logs::read)
    /// from `path`) for the columns of `spec`: the same columns, numbers, row numbers and
    /// errors as a reader of the same samples written out as CSV, without that text.
    pub fn from_log(path: PathBuf, table: LogTable, spec: &ReadSpec<'_>) -> CliResult<Self> {
        let header = Header::new(table.header.iter().copied());
        // The header is row 1 of the CSV the log stands for.
        let columns = resolve(&header, spec, Naming::default(), &path, 1)?;
        let increasing = increasing(&columns, spec);
        let n = columns.len();
        let names = columns.iter().map(|(c, _)| c.name.clone()).collect();
        Ok(Self {
            blocks: Blocks::Log(LogBlocks::new(path.clone(), table, columns, increasing)),
            path,
            names,
            row: Row {
                number: 1,
                values: vec![0.0; n],
            },
            handed: 0,
        })
    }

    /// The file, for error messages (`<stdin>` for standard input).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The position of column `name` in each row's values; `None` for an optional column
    /// the file does not have.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|c| c == name)
    }

    /// The names of the columns read, in row order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.names.iter().map(String::as_str)
    }

    /// The next row, or `None` at the end of the file. The row is overwritten by the next
    /// call (nothing is allocated per row); see the `Iterator` impl for owned rows.
    pub fn next_row(&mut self) -> CliResult<Option<&Row>> {
        let next = match &mut self.blocks {
            Blocks::Csv(b) => b.next_into(&mut self.row.values)?,
            Blocks::Log(b) => b.next_into(&mut self.row.values)?,
        };
        match next {
            Some(number) => {
                self.row.number = number;
                self.handed += 1;
                Ok(Some(&self.row))
            }
            None => Ok(None),
        }
    }

    /// The next rows at once, in file order, or `None` at the end of the file: for a loop
    /// over every row, which then pays no call and no copy a row (the rows are where the
    /// reader parsed them). Rows handed out one way are not handed out the other.
    pub fn next_rows(&mut self) -> CliResult<Option<impl Iterator<Item = RowRef<'_>>>> {
        let width = self.row.values.len();
        let rows = match &mut self.blocks {
            Blocks::Csv(b) => b.next_rows()?,
            Blocks::Log(b) => b.next_rows()?,
        };
        Ok(rows.map(|(numbers, values)| {
            self.handed += numbers.len() as u64;
            numbers
                .iter()
                .zip(values.chunks_exact(width.max(1)))
                .map(|(&number, values)| RowRef { number, values })
        }))
    }
}

/// The columns of `spec` found in `header` under `naming`, each with whether it is required;
/// a missing required column, a column named twice or mapped to nothing is an error at
/// `header_row` of `path`.
fn resolve(
    header: &Header,
    spec: &ReadSpec<'_>,
    naming: Naming<'_>,
    path: &Path,
    header_row: usize,
) -> CliResult<Vec<(ColumnSource, bool)>> {
    let mut columns = Vec::new();
    for (names, required) in [(spec.required, true), (spec.optional, false)] {
        for &name in names {
            match header.resolve(name, naming) {
                Ok(Some(source)) => columns.push((source, required)),
                Ok(None) if required => {
                    return Err(CliError::row(
                        path,
                        header_row,
                        header.missing(name, naming),
                    ));
                }
                Ok(None) => {}
                Err(e) => return Err(CliError::row(path, header_row, e)),
            }
        }
    }
    Ok(columns)
}

/// The position among `columns` of the one `spec` says must increase, if read.
fn increasing(columns: &[(ColumnSource, bool)], spec: &ReadSpec<'_>) -> Option<usize> {
    spec.increasing
        .and_then(|n| columns.iter().position(|(c, _)| c.name == n))
}

/// Rows every [`RowReader`] of the process has handed to its command, for `batch`'s
/// results table.
static ROWS_READ: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

impl Drop for RowReader {
    fn drop(&mut self) {
        ROWS_READ.fetch_add(self.handed, std::sync::atomic::Ordering::Relaxed);
    }
}

/// How many rows the process's readers (those dropped) have handed to their commands.
pub fn rows_read() -> u64 {
    ROWS_READ.load(std::sync::atomic::Ordering::Relaxed)
}

impl Iterator for RowReader {
    type Item = CliResult<Row>;

    /// Owned rows (one small allocation each); stops after the first error.
    fn next(&mut self) -> Option<CliResult<Row>> {
        match self.next_row() {
            Ok(Some(r)) => Some(Ok(r.clone())),
            Ok(None) => None,
            Err(e) => Some(Err(e)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(tag: &str, text: &str) -> PathBuf {
        let p = std::env::temp_dir().join(format!(
            "truenorth-reader-{tag}-{}-{:?}",
            std::process::id(),
            std::thread::current().id()
        ));
        std::fs::write(&p, text).unwrap();
        p
    }

    fn read_all(text: &str, opts: &InputOptions, spec: &ReadSpec<'_>) -> CliResult<Vec<Row>> {
        let p = file("all", text);
        let out = RowReader::open(&InputPath::new(&p), opts, spec).and_then(|r| r.collect());
        std::fs::remove_file(&p).ok();
        out
    }

    #[test]
    fn streams_rows_with_their_line_numbers() {
        let text = "# exported by a logger\nT_S;Mag_X;other\n0;1;a\n# pause\n1;2;b\n\n2;3;c\n";
        let spec = ReadSpec::new(&["t_s", "mag_x"]).increasing("t_s");
        let rows = read_all(text, &InputOptions::default(), &spec).unwrap();
        let got: Vec<(usize, Vec<f64>)> = rows.into_iter().map(|r| (r.number, r.values)).collect();
        assert_eq!(
            got,
            vec![
                (3, vec![0.0, 1.0]),
                (5, vec![1.0, 2.0]),
                (7, vec![2.0, 3.0])
            ]
        );
    }

    #[test]
    fn whitespace_files_without_a_header() {
        let text = "-163 64 1\n  -168\t64 6\n";
        let opts = InputOptions {
            no_header: true,
            columns: ["mag_x=1", "mag_y=2", "mag_z=-3"]
                .iter()
                .map(|c| c.parse().unwrap())
                .collect(),
            ..InputOptions::default()
        };
        let rows = read_all(text, &opts, &ReadSpec::new(&["mag_x", "mag_y", "mag_z"])).unwrap();
        assert_eq!(rows[0].values, vec![-163.0, 64.0, -1.0]);
        assert_eq!((rows[1].number, rows[1][2]), (2, -6.0));
    }

    #[test]
    fn errors_name_the_row() {
        let spec = ReadSpec::new(&["t_s", "mag_x"])
            .optional(&["mag_z"])
            .increasing("t_s");
        let o = InputOptions::default();
        let e = read_all("t_s,mag_x\n0,1\n0,2\n", &o, &spec).unwrap_err();
        assert_eq!(e.row, Some(3));
        assert!(e.message.contains("does not come after"), "{e}");
        let e = read_all("t_s,mag_x\n0,x\n", &o, &spec).unwrap_err();
        assert!(
            e.row == Some(2) && e.message.contains("not a number"),
            "{e}"
        );
        let e = read_all("t_s,mag_x\n0,inf\n", &o, &spec).unwrap_err();
        assert!(e.message.contains("not finite"), "{e}");
        // A finite number no sensor reads, in a required or an optional column.
        let e = read_all("t_s,mag_x\n0,1e308\n", &o, &spec).unwrap_err();
        assert!(
            e.row == Some(2) && e.message.contains("beyond ±2^53"),
            "{e}"
        );
        let e = read_all("t_s,mag_x,mag_z\n0,1,-9007199254740994\n", &o, &spec).unwrap_err();
        assert!(
            e.row == Some(2) && e.message.contains("beyond ±2^53"),
            "{e}"
        );
        let e = read_all("t_s,mag_x,mag_z\n0,1,-inf\n", &o, &spec).unwrap_err();
        assert!(e.row == Some(2) && e.message.contains("not finite"), "{e}");
        // The largest magnitude held, and an optional column's NaN (no reading), are read.
        assert!(read_all("t_s,mag_x,mag_z\n0,9007199254740992,nan\n", &o, &spec).is_ok());
        let e = read_all("t_s,mag_x\n0\n", &o, &spec).unwrap_err();
        assert!(e.message.contains("no value for `mag_x`"), "{e}");
        let e = read_all("t_s,mag_y\n0,1\n", &o, &spec).unwrap_err();
        assert!(
            e.row == Some(1) && e.message.contains("missing column `mag_x`"),
            "{e}"
        );
        let e = read_all("t_s,mag_x,MAG_X\n0,1,2\n", &o, &spec).unwrap_err();
        assert!(e.message.contains("2 times"), "{e}");
        let e = read_all("", &o, &spec).unwrap_err();
        assert!(e.message.contains("empty file"), "{e}");
        // An empty optional cell is NaN.
        let rows = read_all("t_s,mag_x,mag_z\n0,1,\n", &o, &spec).unwrap();
        assert!(rows[0][2].is_nan());
    }

    #[test]
    fn the_axis_convention_turns_sensor_into_body_axes() {
        let text = "mag_x,mag_y,mag_z,acc_x,acc_y,acc_z\n1,2,3,4,5,6\n";
        let opts = InputOptions {
            axes: "flu".parse().unwrap(),
            ..InputOptions::default()
        };
        let names = ["mag_x", "mag_y", "mag_z", "acc_x", "acc_y", "acc_z"];
        let rows = read_all(text, &opts, &ReadSpec::new(&names)).unwrap();
        assert_eq!(rows[0].values, vec![1.0, -2.0, -3.0, 4.0, -5.0, -6.0]);
    }
}
