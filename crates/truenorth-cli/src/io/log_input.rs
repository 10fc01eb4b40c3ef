//! Flight and robot logs as a command's input: a PX4 ULog or ROS 2 MCAP file, found by its
//! magic number, is read through `truenorth-logs` and handed to the command as the CSV its
//! own reader takes, so that every check, message and number downstream is the CSV path's.
//!
//! The log's streams become the CSV columns in the library's frames and units (body x
//! forward, y right, z down; rad/s, m/s², µT; seconds), each number written as the shortest
//! text that parses back to the same `f64`: a command gives bit-identical results from a
//! log and from the same samples written out as CSV. Which rows the CSV has follows from the
//! columns the command asks for:
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

use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use truenorth::core::Fixed;
use truenorth_logs::{LogConfig, LogError, LogFormat, LogReader, Recording};

use super::columns::{AxisConvention, Delimiter, InputOptions};
use super::errln;
pub use super::log_rows::AxleTrack;
use super::log_rows::render;
use super::reader::ReadSpec;
use super::source::InputPath;
use super::{CliError, CliResult};

/// The options that choose what is read from a ULog or MCAP input (flattened into
/// [`InputOptions`]).
#[derive(Debug, Clone, Default, PartialEq, Eq, clap::Args)]
pub struct LogOptions {
    /// ULog/MCAP input: the gyro + accelerometer topic, as named in the file (ULog
    /// `NAME:INSTANCE` for another instance; default `sensor_combined`, or MCAP's
    /// `sensor_msgs/msg/Imu` topic with the most messages). `truenorth inspect` lists them.
    #[arg(long, value_name = "TOPIC")]
    pub imu_topic: Option<String>,
    /// ULog/MCAP input: the magnetometer topic, or `none` for no magnetometer (default:
    /// ULog `sensor_combined`, `vehicle_magnetometer` or `sensor_mag`, the first present;
    /// MCAP's `sensor_msgs/msg/MagneticField` topic with the most messages).
    #[arg(long, value_name = "TOPIC")]
    pub mag_topic: Option<String>,
    /// ULog/MCAP input: the logger's own attitude topic, listed by `inspect` (default ULog
    /// `vehicle_attitude`; MCAP none).
    #[arg(long, value_name = "TOPIC")]
    pub attitude_topic: Option<String>,
    /// MCAP input: the `nav_msgs/msg/Odometry` topic `drive` reads the speed and turn from
    /// (default: the one with the most messages).
    #[arg(long, value_name = "TOPIC")]
    pub odometry_topic: Option<String>,
    /// ULog/MCAP input: read the messages before a truncated or damaged end (with a warning)
    /// instead of refusing the file.
    #[arg(long)]
    pub accept_incomplete: bool,
}

impl LogOptions {
    /// The log crate's configuration.
    fn config(&self) -> LogConfig {
        LogConfig {
            imu_topic: self.imu_topic.clone(),
            mag_topic: self.mag_topic.clone(),
            attitude_topic: self.attitude_topic.clone(),
            odometry_topic: self.odometry_topic.clone(),
            accept_incomplete: self.accept_incomplete,
        }
    }

    /// The options given, by flag, for the message refusing them with a CSV.
    /// Refuses, in one line, any of these options given to `command`, which reads CSV files
    /// only (e.g. `eval broad`, whose trials are CSV).
    pub fn refuse_for_csv_only(&self, command: &str) -> CliResult {
        match self.given().first() {
            Some(flag) => Err(CliError::msg(format!(
                "{command} reads CSV files only, and {flag} applies to a PX4 ULog or MCAP log; leave it out"
            ))),
            None => Ok(()),
        }
    }

    fn given(&self) -> Vec<&'static str> {
        let mut given = Vec::new();
        for (flag, set) in [
            ("--imu-topic", self.imu_topic.is_some()),
            ("--mag-topic", self.mag_topic.is_some()),
            ("--attitude-topic", self.attitude_topic.is_some()),
            ("--odometry-topic", self.odometry_topic.is_some()),
            ("--accept-incomplete", self.accept_incomplete),
        ] {
            if set {
                given.push(flag);
            }
        }
        given
    }
}

/// A log read for a command: the recording and the CSV made of it.
#[derive(Debug, Clone)]
pub struct LogInput {
    /// The file it came from (`<stdin>` for standard input).
    pub path: PathBuf,
    /// What the log crate read.
    pub recording: Recording,
    /// The CSV the command reads, as an input under the log's name.
    pub csv: InputPath,
}

/// The input of a command that reads the columns of `spec`: the file itself when it is a
/// CSV, or the CSV made from it when it is a ULog or MCAP log. `csv_only` lists the
/// command's own options that describe a CSV (`("--gyro-unit", given)`): given with a log,
/// each is refused, as are the shared CSV options; the log options given with a CSV are
/// refused likewise.
pub fn source(
    path: &Path,
    opts: &InputOptions,
    spec: &ReadSpec<'_>,
    csv_only: &[(&str, bool)],
) -> CliResult<InputPath> {
    Ok(open(path, opts, spec, csv_only, None)?.map_or_else(|| InputPath::new(path), |l| l.csv))
}

/// [`source`] for `drive`: a log's odometry becomes the wheel speeds of the rigid axle
/// `axle` gives (called only for a log; its `Err` says why the vehicle's wheels are not one,
/// and refuses the log).
pub fn drive_source(
    path: &Path,
    opts: &InputOptions,
    spec: &ReadSpec<'_>,
    csv_only: &[(&str, bool)],
    axle: impl FnOnce() -> CliResult<Result<AxleTrack, String>>,
) -> CliResult<InputPath> {
    let log = open(path, opts, spec, csv_only, Some(Box::new(axle)))?;
    Ok(log.map_or_else(|| InputPath::new(path), |l| l.csv))
}

/// The rigid axle a log's odometry is read as, asked for only once the input is a log.
pub type AxleOf<'a> = Box<dyn FnOnce() -> CliResult<Result<AxleTrack, String>> + 'a>;

/// The log at `path` read for the columns of `spec`, or `None` when it is not a log.
pub fn open(
    path: &Path,
    opts: &InputOptions,
    spec: &ReadSpec<'_>,
    csv_only: &[(&str, bool)],
    axle: Option<AxleOf<'_>>,
) -> CliResult<Option<LogInput>> {
    let input = InputPath::new(path);
    let name = input.display_path();
    let Some(format) = detect(&input)? else {
        let given = opts.log.given();
        if let Some(flag) = given.first() {
            return Err(CliError::file(
                &name,
                format!(
                    "{flag} chooses a topic of a PX4 ULog or MCAP log, and this input is read as CSV (it does not start with either's magic number); leave it out"
                ),
            ));
        }
        return Ok(None);
    };
    refuse_csv_options(&name, format, opts, csv_only)?;
    let bytes = read_all(&input)?;
    let reader = LogReader::new(opts.log.config()).map_err(|e| refused(&name, e))?;
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
    let csv = render(&name, &recording, spec, axle)?;
    Ok(Some(LogInput {
        csv: InputPath::Memory {
            name: name.clone(),
            bytes: Arc::from(csv.into_bytes()),
        },
        path: name,
        recording,
    }))
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
fn detect(input: &InputPath) -> CliResult<Option<LogFormat>> {
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

/// Refuses, in one line, an option that describes a CSV given with a log.
fn refuse_csv_options(
    name: &Path,
    format: LogFormat,
    opts: &InputOptions,
    csv_only: &[(&str, bool)],
) -> CliResult {
    let shared = [
        (
            "--delimiter",
            opts.delimiter != Delimiter::Auto,
            "a log has no delimiter",
        ),
        ("--no-header", opts.no_header, "a log names its own fields"),
        (
            "--column",
            !opts.columns.is_empty(),
            "a log's fields are read by their names in the format (choose streams with --imu-topic, --mag-topic)",
        ),
        (
            "--axes",
            opts.axes != AxisConvention::default(),
            "a log's readings are turned onto body axes x forward, y right, z down by the reader",
        ),
    ];
    let own = csv_only
        .iter()
        .filter(|(_, given)| *given)
        .map(|(flag, _)| {
            (
                *flag,
                true,
                "a log's units are the format's (rad/s, m/s², µT once read)",
            )
        });
    if let Some((flag, _, why)) = shared.into_iter().chain(own).find(|(_, given, _)| *given) {
        return Err(CliError::file(
            name,
            format!(
                "{flag} applies to CSV input, and this is a {format} file: {why}; leave it out"
            ),
        ));
    }
    Ok(())
}

/// The lines `inspect` prints about a log before its report: the format, every topic with
/// its messages (and its mean rate over the recording), the streams read and the options
/// that choose others.
pub fn summary(log: &LogInput) -> Vec<String> {
    let r = &log.recording;
    let mut lines = vec![format!(
        "log: {} ({}), {}",
        log.path.display(),
        r.format,
        if r.complete {
            "complete"
        } else {
            "incomplete: read up to the damage"
        }
    )];
    let span_s = span_s(r);
    lines.push(format!("topics ({}):", r.topics.len()));
    for t in &r.topics {
        let rate = if span_s > 0.0 && t.messages > 1 {
            format!(", {} Hz mean", Fixed(t.messages as f64 / span_s, 1))
        } else {
            String::new()
        };
        lines.push(format!(
            "  {} ({}, {} messages{rate})",
            t.name, t.kind, t.messages
        ));
    }
    lines.push("streams read:".to_string());
    for s in &r.streams {
        lines.push(format!(
            "  {}: {}, {} samples, {} Hz (median step), {} left out",
            s.role,
            s.topic,
            s.samples,
            Fixed(s.rate_hz, 2),
            s.dropped
        ));
    }
    let options = match r.format {
        LogFormat::Ulog => {
            "--imu-topic NAME[:INSTANCE], --mag-topic NAME[:INSTANCE] or none, --attitude-topic NAME[:INSTANCE]"
        }
        LogFormat::Mcap => {
            "--imu-topic TOPIC, --mag-topic TOPIC or none, --attitude-topic TOPIC, --odometry-topic TOPIC"
        }
    };
    lines.push(format!("other streams: {options} (names as listed above)"));
    lines
}

/// [`summary`] as JSON: `format`, `complete`, `topics` (name, kind, messages) and `streams`
/// (role, topic, samples, rate_hz, dropped).
pub fn summary_json(log: &LogInput) -> serde_json::Value {
    let r = &log.recording;
    serde_json::json!({
        "format": r.format.to_string(),
        "complete": r.complete,
        "topics": r.topics.iter().map(|t| serde_json::json!({
            "name": t.name, "kind": t.kind, "messages": t.messages,
        })).collect::<Vec<_>>(),
        "streams": r.streams.iter().map(|s| serde_json::json!({
            "role": s.role, "topic": s.topic, "samples": s.samples,
            "rate_hz": s.rate_hz, "dropped": s.dropped,
        })).collect::<Vec<_>>(),
    })
}

/// The time the selected streams cover, s.
fn span_s(r: &Recording) -> f64 {
    let times = r
        .imu
        .iter()
        .map(|s| s.t_s)
        .chain(r.mag.iter().map(|s| s.t_s))
        .chain(r.attitude.iter().map(|s| s.t_s))
        .chain(r.odometry.iter().map(|s| s.t_s));
    let (lo, hi) = times.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
        (lo.min(t), hi.max(t))
    });
    if hi > lo { hi - lo } else { 0.0 }
}
