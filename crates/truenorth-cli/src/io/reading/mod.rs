//! Reading: a command's input as rows of numbers, then as its samples.
//!
//! From the bottom up:
//! * `source`: a file or `-` (standard input), gzip-compressed or not (found by the magic
//!   bytes); `records`: its lines as field spans, the [`Delimiter`]; `number_parse`:
//!   a cell's number from its bytes;
//! * `chunks`, `plain_rows`, `row_blocks`: the lines cut into chunks on one thread
//!   and parsed on two more, a few blocks of rows ahead;
//! * `columns`: the header looked up without regard to case, the column mapping
//!   (`NAME=HEADER`, `-HEADER` negates) and the sensor's axis convention (`--axes flu`);
//! * `logs`: a PX4 ULog or ROS 2 MCAP log as the table of numbers a CSV of it would
//!   hold, and the checks of its rows;
//! * `options`: [`InputOptions`], flattened into each command's arguments;
//! * `reader`: [`RowReader`], the requested columns row by row as `f64` with the row
//!   number for messages, time order checked on the way, memory not growing with the file;
//!   `table`: every row in memory;
//! * `samples`, `kinds`: a command's rows as its samples ([`SampleKind`]: `Mag2`,
//!   `Mag3`, `MagAccel`, `Turn`, `Compass`, `Imu`, `Vehicle`), with one error for a file
//!   without data rows; `wheels`: wheel speeds integrated into distances;
//! * `input`: [`Input`], the one way a command opens its input, a CSV or a log, as rows or
//!   as samples.

#[cfg(test)]
mod chunk_boundaries;
pub(crate) mod chunks;
pub(crate) mod columns;
pub(crate) mod input;
pub(crate) mod kinds;
pub(crate) mod logs;
pub(crate) mod number_parse;
pub(crate) mod options;
pub(crate) mod plain_rows;
pub(crate) mod reader;
pub(crate) mod records;
pub(crate) mod row_blocks;
pub(crate) mod row_parser;
pub(crate) mod samples;
pub(crate) mod source;
pub(crate) mod table;
pub(crate) mod wheels;

pub use input::Input;
pub use options::InputOptions;
pub use reader::{ReadSpec, Row, RowReader, RowRef, rows_read};
pub use records::Delimiter;
pub use samples::{SampleKind, Samples};
pub use source::InputPath;
pub use table::Table;
