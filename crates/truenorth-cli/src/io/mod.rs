//! Input and output shared by the subcommands, with errors that name the file, the row and
//! the problem, in three rooms on one floor of shared ground:
//!
//! * `reading`: a command's input (a CSV, gzip or not, a file or standard input, or a
//!   PX4 ULog / ROS 2 MCAP log) as rows of numbers and then as its samples, through
//!   [`Input`]; the input options ([`InputOptions`]) every file-reading command flattens
//!   into its arguments;
//! * `checking`: the data against what they were declared to be (units, the gyro's axes,
//!   a yaw gyro against the wheels): the physics is `truenorth::checks`, this room says
//!   each finding as the option that fixes it and refuses or warns by it;
//! * `writing`: outputs written whole or not at all (a temporary renamed over the
//!   target), CSV rows formatted on other threads, and the JSON formats the commands write
//!   and read back;
//! * underneath: `error` ([`CliError`]), `console` (`outln!` / `errln!`: a closed pipe
//!   ends the run quietly with status 141, a full disk is an error), `temporaries` (the
//!   outputs being written, removed when a signal or a closed pipe ends the run),
//!   `closest_name` (the name a misspelling meant) and `spill` (a calibrator's readings
//!   in memory up to a share, the rest in a temporary file).
//!
//! Imports point down: the ground uses no room; reading uses only the ground; writing
//! and checking stand on reading (an output is checked against the inputs, a fix is said
//! in the input options' terms) and not on each other.

pub mod checking;
pub(crate) mod closest_name;
pub(crate) mod console;
pub(crate) mod error;
pub mod reading;
#[cfg(test)]
mod scratch;
pub mod spill;
pub(crate) mod temporaries;
pub mod writing;

pub(crate) use console::{errln, out, outln};
pub use console::{write_stderr, write_stdout};
pub use error::{CliError, CliResult, ErrorKind};
pub use reading::{
    Input, InputOptions, InputPath, ReadSpec, Row, RowReader, RowRef, Table, rows_read,
};
pub use writing::formats::{
    AccelPart, CALIBRATION_FORMAT, CALIBRATION_VERSION, CalibrationFile, GyroPart, QualityReport,
    VehicleFile, finite, gyro_units, matrix_rows, read_learned, units_block, write_learned,
};
pub use writing::{
    CsvOutput, OutputOptions, Precision, check_distinct, write_atomically, write_csv,
};
