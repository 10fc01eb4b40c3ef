//! Input and output shared by the subcommands, with errors that name the file, the row and
//! the problem.
//!
//! Reading (the same for every command, and for any that reads a CSV later):
//! * [`InputPath`]: a file or `-` (standard input), gzip-compressed or not (found by the
//!   magic bytes);
//! * [`InputOptions`] (flatten into a command's arguments): the delimiter, a file without a
//!   header, the column mapping `NAME=HEADER` (`-HEADER` negates) and the sensor's axis
//!   convention (`--axes flu`); headers match without regard to case, and a requested
//!   column named twice is an error;
//! * [`RowReader`]: the streaming read, one row at a time, the requested columns by name as
//!   `f64` with the row number for messages, time order checked on the way; memory does not
//!   grow with the file; the reading runs on a second thread and the splitting and parsing
//!   on two more, a few blocks of rows ahead, so that they overlap the command's own work;
//! * [`Table`]: the whole-table read built on it;
//! * [`log_input`]: a PX4 ULog or ROS 2 MCAP input, found by its magic number, read as the
//!   CSV the command takes (the topic options flatten into [`InputOptions`]).
//!
//! Checking (the data against what they were declared to be): [`check_inertial`] (the
//! accelerometer's and gyro's units, the gyro's axes against gravity's and the magnetic
//! field's turns) and [`YawRateCheck`] (a vehicle's yaw gyro against its wheels), shared by
//! the commands that refuse and by `inspect`, which reports.
//!
//! Writing: `AtomicOutput` / [`CsvOutput`] / [`write_csv`] / [`write_atomically`] write a
//! temporary file beside the target, sync it and rename it over the target (through a
//! symbolic link, the file it points to; `-`, a device or a FIFO: written into directly;
//! `*.gz`: compressed); the temporaries of a run stopped by a signal are removed, those a
//! killed run left by the next run writing the same output; [`check_distinct`] refuses an
//! output that is one of the inputs before anything is read. Console text goes through
//! `outln!` / `errln!`: a closed pipe ends the run quietly (status 141), a full disk is an
//! error.

mod atomic_write;
mod calibration_file;
#[cfg(test)]
mod chunk_boundaries;
mod chunks;
mod closest_name;
mod columns;
mod compass_physics;
mod console;
mod csv_output;
mod direction_spans;
mod error;
mod gyro_axes;
mod inertial_units;
mod json_input;
mod learned_file;
pub mod log_input;
mod log_rows;
mod number_format;
mod number_parse;
mod output_target;
mod plain_rows;
mod reader;
pub mod reading_spill;
mod records;
mod row_blocks;
#[cfg(test)]
mod scratch;
mod source;
mod table;
mod temporaries;
mod unit_check;
mod vehicle_file;
mod wheel_columns;
mod write_behind;
mod yaw_rate_check;

pub use atomic_write::{check_distinct, write_atomically};
pub use calibration_file::{
    AccelPart, CALIBRATION_FORMAT, CALIBRATION_VERSION, CalibrationFile, CompassCalibration,
    GyroPart, QualityReport, finite, gyro_units, matrix_rows, units_block,
};
pub use columns::InputOptions;
pub(crate) use console::{errln, out, outln};
pub use console::{write_stderr, write_stdout};
pub use csv_output::{CsvOutput, write_csv};
pub use direction_spans::{Inertial, Reference, median, median_magnitude};
pub use error::{CliError, CliResult, ErrorKind};
pub use gyro_axes::{
    AxisFit, SignedPermutation, axes_are_wrong, fit_gyro_axes, fix_columns, fix_pair, shell_word,
};
pub use inertial_units::{AccUnit, GyroUnit};
pub use learned_file::{read_learned, write_learned};
pub use number_format::{OutputOptions, Precision};
pub use reader::{ReadSpec, Row, RowReader, RowRef, rows_read};
pub use source::InputPath;
pub use table::Table;
pub use unit_check::{
    Finding, FindingKind, acc_unit_name, check_inertial, gyro_unit_name, likely_acc_unit,
    refuse_or_warn,
};
pub use vehicle_file::VehicleFile;
pub use wheel_columns::WheelColumns;
pub use yaw_rate_check::{Turns, YawRateCheck};
