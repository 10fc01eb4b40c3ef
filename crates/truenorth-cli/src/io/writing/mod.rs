//! Writing: a command's outputs, whole or not at all, and the files it reads back.
//!
//! * `atomic_write`: `AtomicOutput` / `write_atomically` write a temporary file beside
//!   the target, sync it and rename it over the target (through a symbolic link, the file it
//!   points to; `-`, a device or a FIFO: written into directly; `*.gz`: compressed), with
//!   `output_target` saying which and `write_behind` syncing behind the writes;
//!   `check_distinct` refuses an output that is one of the inputs before anything is read;
//! * `csv_output`: [`CsvOutput`] / `write_csv`, rows formatted on two threads and
//!   written in order by a third; `number_format`: `--precision`;
//! * `formats`: the JSON files the commands write and read back (a compass calibration,
//!   a vehicle, what a drive learned), versioned, refusing unknown keys.
//!
//! It stands on reading (an output is checked against the inputs, a format is read as an
//! input), never the other way round.

pub(crate) mod atomic_write;
pub(crate) mod csv_output;
pub(crate) mod formats;
pub(crate) mod number_format;
pub(crate) mod output_target;
pub(crate) mod write_behind;

pub use atomic_write::{check_distinct, write_atomically};
pub use csv_output::{CsvOutput, write_csv};
pub use number_format::{OutputOptions, Precision};
