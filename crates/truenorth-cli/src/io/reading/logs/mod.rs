//! Flight and robot logs as a command's input: a PX4 ULog or ROS 2 MCAP file, found by its
//! magic number, is read through `truenorth-logs` and handed to the command as the rows its
//! own reader takes, so that every check, message and number downstream is the CSV path's.
//!
//! The log's streams become columns in the library's frames and units (body x forward,
//! y right, z down; rad/s, m/s², µT; seconds), with the names of the CSV contract: a command
//! gives bit-identical results from a log and from the same samples written out as CSV
//! (each number as the shortest text that parses back to it), without that text being made.
//! Which rows there are follows from the columns the command asks for:
//! * the magnetometer alone (`calibrate` 2-D and 3-D): the magnetometer's own readings;
//! * the gyro or accelerometer (`orientation`, and `calibrate`/`heading` beside the
//!   magnetometer): the IMU's rows, each magnetometer reading on the first row at or after
//!   it (`Recording::imu_with_mag`), rows without one dropped where the magnetometer is
//!   required;
//! * wheels (`drive`) or everything (`inspect`): every stream at its own times, merged, an
//!   empty cell where a stream has no reading; odometry becomes the wheel speeds of a rigid
//!   axle of the vehicle's track (forward speed ± yaw rate × track / 2).
//!
//! The whole file is read into memory (the log crate reads from a byte slice).

pub(crate) mod blocks;
pub(crate) mod options;
pub(crate) mod rows;
pub(crate) mod summary;

use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};

use truenorth_logs::{LogError, LogFormat, LogReader, Recording};

use super::source::InputPath;
use crate::io::{CliError, CliResult, errln};
use options::LogOptions;
pub use rows::{AxleTrack, LogTable};

/// A log read for a command: the recording and the table made of it.
#[derive(Debug, Clone)]
pub struct LogInput {
    /// The file it came from (`<stdin>` for standard input).
    pub path: PathBuf,
    /// The log's format.
    pub format: LogFormat,
    /// What the log crate read.
    pub recording: Recording,
    /// The rows the command reads.
    pub table: LogTable,
}

/// The rigid axle a log's odometry is read as, asked for only once the input is a log (its
/// `Err` says why the vehicle's wheels are not one, and refuses the log).
pub type AxleOf<'a> = Box<dyn FnOnce() -> CliResult<Result<AxleTrack, String>> + 'a>;

/// Reads the log `input` (of `format`, found by [`detect`]) with `options` into the rows
/// of a command that needs the columns `required` and reads `optional` ones where present;
/// `axle` turns its odometry into wheels (`drive`).
pub fn read(
    input: &InputPath,
    format: LogFormat,
    options: &LogOptions,
    (required, optional): (&[&str], &[&str]),
    axle: Option<AxleOf<'_>>,
) -> CliResult<LogInput> {
    let name = input.display_path();
    let bytes = read_all(input)?;
    let reader = LogReader::new(options.config()).map_err(|e| refused(&name, e))?;
    let recording = reader.read_bytes(&bytes).map_err(|e| refused(&name, e))?;
    drop(bytes);
    let axle = axle.map(|f| f()).transpose()?;
    if !recording.complete {
        let read: usize = recording.streams.iter().map(|s| s.samples).sum();
        errln!(
            "truenorth: warning: {}: the {format} file ends early or is damaged; read the {read} samples before the damage (--accept-incomplete)",
            name.display()
        );
    }
    let table = rows::table(&name, &recording, required, optional, axle)?;
    Ok(LogInput {
        path: name,
        format,
        recording,
        table,
    })
}

/// The log crate's error as the command's one line, naming the command-line option where
/// the crate names its configuration field.
fn refused(name: &Path, e: LogError) -> CliError {
    match e {
        LogError::Incomplete {
            format,
            messages,
            detail,
        } => CliError::file(
            name,
            format!(
                "{format} file is incomplete after {messages} messages ({detail}): cut off or damaged; --accept-incomplete reads the messages before the damage"
            ),
        ),
        LogError::InvalidConfig { field, reason } => {
            CliError::file(name, format!("--{} {reason}", field.replace('_', "-")))
        }
        other => CliError::file(name, other.to_string()),
    }
}

/// The log format announced by the input's first bytes, if any (gzip-compressed files are
/// looked into; standard input only when not compressed). A FIFO or a device is not looked
/// into: its bytes cannot be read twice, and it is read as CSV.
pub fn detect(input: &InputPath) -> CliResult<Option<LogFormat>> {
    if let InputPath::File(p) = input
        && !std::fs::metadata(p).is_ok_and(|m| m.is_file())
    {
        return Ok(None);
    }
    let head =
        match input {
            // Peeking at standard input's own buffer consumes nothing: the CSV reader that
            // follows reads the same bytes.
            InputPath::Stdin => {
                let mut stdin = std::io::stdin().lock();
                let head = stdin.fill_buf().map_err(|e| {
                    CliError::file(&input.display_path(), format!("cannot read: {e}"))
                })?;
                head.get(..8).unwrap_or(head).to_vec()
            }
            _ => {
                let mut head = Vec::with_capacity(8);
                input.open()?.take(8).read_to_end(&mut head).map_err(|e| {
                    CliError::file(&input.display_path(), format!("cannot read: {e}"))
                })?;
                head
            }
        };
    Ok(LogReader::detect(&head).ok())
}

/// The whole input, decompressed.
fn read_all(input: &InputPath) -> CliResult<Vec<u8>> {
    let mut bytes = Vec::new();
    input
        .open()?
        .read_to_end(&mut bytes)
        .map_err(|e| CliError::file(&input.display_path(), format!("cannot read: {e}")))?;
    Ok(bytes)
}
