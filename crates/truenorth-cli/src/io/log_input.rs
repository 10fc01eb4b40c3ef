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

use std::fmt::Write as _;
use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use truenorth_logs::{LogConfig, LogError, LogFormat, LogReader, Recording};

use super::columns::{AxisConvention, Delimiter, InputOptions};
use super::errln;
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

/// How the odometry of a log becomes the wheels `drive` reads: the speeds of a rigid axle
/// with this track, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxleTrack {
    /// The odometer wheels' track, m.
    pub track_m: f64,
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
/// looked into; standard input only when not compressed).
fn detect(input: &InputPath) -> CliResult<Option<LogFormat>> {
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

/// The columns a log can give, by stream.
const IMU: [&str; 6] = ["gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z"];
const MAG: [&str; 3] = ["mag_x", "mag_y", "mag_z"];
const WHEELS: [&str; 2] = ["speed_l_mps", "speed_r_mps"];

/// The CSV made of `recording` for the columns of `spec` (see the module documentation).
fn render(
    name: &Path,
    recording: &Recording,
    spec: &ReadSpec<'_>,
    axle: Option<Result<AxleTrack, String>>,
) -> CliResult<String> {
    let wanted = |names: &[&str]| {
        spec.required
            .iter()
            .chain(spec.optional)
            .any(|c| names.contains(c))
    };
    let required = |names: &[&str]| spec.required.iter().any(|c| names.contains(c));
    if required(&MAG) && recording.mag.is_empty() {
        return Err(CliError::file(
            name,
            format!(
                "this command needs the magnetometer and the log gives none ({}); name its topic with --mag-topic (`truenorth inspect` lists them)",
                match recording.stream("mag") {
                    Some(s) => format!("topic `{}` has no usable reading", s.topic),
                    None => "--mag-topic none".to_string(),
                }
            ),
        ));
    }
    if let Some(axle) = axle {
        let axle = axle.map_err(|why| CliError::file(name, why))?;
        if recording.odometry.is_empty() {
            return Err(CliError::file(
                name,
                format!(
                    "drive needs the wheels' speeds and this {} file has no odometry: give a ROS 2 MCAP log with a nav_msgs/msg/Odometry topic (--odometry-topic), or a CSV",
                    recording.format
                ),
            ));
        }
        return Ok(merged(recording, Some(axle)));
    }
    if wanted(&WHEELS) {
        return Ok(merged(recording, None));
    }
    if wanted(&IMU) {
        return Ok(imu_rows(recording, required(&MAG)));
    }
    Ok(mag_rows(recording))
}

/// Appends `,v` for each value (an empty cell for NaN, a reading the row does not have).
fn cells(text: &mut String, values: impl IntoIterator<Item = f64>) {
    for v in values {
        text.push(',');
        if !v.is_nan() {
            // Display writes the shortest text that parses back to the same f64.
            let _ = write!(text, "{v}");
        }
    }
}

fn header(text: &mut String, columns: &[&[&str]]) {
    text.push_str("t_s");
    for c in columns.iter().flat_map(|c| c.iter()) {
        text.push(',');
        text.push_str(c);
    }
    text.push('\n');
}

/// The magnetometer's own readings.
fn mag_rows(r: &Recording) -> String {
    let mut text = String::with_capacity(64 * (r.mag.len() + 1));
    header(&mut text, &[&MAG]);
    for m in &r.mag {
        let _ = write!(text, "{}", m.t_s);
        cells(&mut text, m.mag.iter().copied());
        text.push('\n');
    }
    text
}

/// The IMU's rows with the magnetometer laid on them (only those carrying a reading when
/// `mag_only`).
fn imu_rows(r: &Recording, mag_only: bool) -> String {
    let rows = r.imu_with_mag();
    let has_mag = !r.mag.is_empty();
    let mut text = String::with_capacity(128 * (rows.len() + 1));
    if has_mag {
        header(&mut text, &[&IMU, &MAG]);
    } else {
        header(&mut text, &[&IMU]);
    }
    for s in &rows {
        let mag = s.mag.as_xyz();
        if mag_only && mag.is_none() {
            continue;
        }
        let (g, a) = (s.gyr_rps.as_xyz(), s.acc_mps2.as_xyz());
        let _ = write!(text, "{}", s.t_s);
        for v in [g, a] {
            cells(&mut text, v.map_or([f64::NAN; 3], |v| [v.x, v.y, v.z]));
        }
        if has_mag {
            cells(&mut text, mag.map_or([f64::NAN; 3], |v| [v.x, v.y, v.z]));
        }
        text.push('\n');
    }
    text
}

/// Every stream at its own times: one row per distinct time, an empty cell where a stream
/// has no reading then; the odometry as wheel speeds when an axle is given.
fn merged(r: &Recording, axle: Option<AxleTrack>) -> String {
    // (time, stream, index), ordered by time and then by stream, so that readings at the
    // same instant share a row.
    let mut events: Vec<(f64, u8, usize)> = Vec::new();
    events.extend(r.imu.iter().enumerate().map(|(k, s)| (s.t_s, 0, k)));
    events.extend(r.mag.iter().enumerate().map(|(k, s)| (s.t_s, 1, k)));
    if axle.is_some() {
        events.extend(r.odometry.iter().enumerate().map(|(k, s)| (s.t_s, 2, k)));
    }
    events.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut columns: Vec<&[&str]> = vec![&IMU];
    if !r.mag.is_empty() {
        columns.push(&MAG);
    }
    if axle.is_some() {
        columns.push(&WHEELS);
    }
    let mut text = String::with_capacity(160 * (events.len() + 1));
    header(&mut text, &columns);
    let mut k = 0;
    while k < events.len() {
        let t = events[k].0;
        let (mut imu, mut mag, mut odo) = ([f64::NAN; 6], [f64::NAN; 3], [f64::NAN; 2]);
        while k < events.len() && events[k].0 == t {
            let (_, stream, i) = events[k];
            match stream {
                0 => {
                    let s = &r.imu[i];
                    let (g, a) = (s.gyr_rps.as_xyz(), s.acc_mps2.as_xyz());
                    if let (Some(g), Some(a)) = (g, a) {
                        imu = [g.x, g.y, g.z, a.x, a.y, a.z];
                    }
                }
                1 => mag = [r.mag[i].mag.x, r.mag[i].mag.y, r.mag[i].mag.z],
                _ => {
                    if let Some(AxleTrack { track_m }) = axle {
                        // A right turn (positive yaw rate about z down) drives the left
                        // wheel, on the outside, faster.
                        let o = &r.odometry[i];
                        let half = o.yaw_rate_rps * track_m / 2.0;
                        odo = [o.velocity_mps.x + half, o.velocity_mps.x - half];
                    }
                }
            }
            k += 1;
        }
        let _ = write!(text, "{t}");
        cells(&mut text, imu);
        if !r.mag.is_empty() {
            cells(&mut text, mag);
        }
        if axle.is_some() {
            cells(&mut text, odo);
        }
        text.push('\n');
    }
    text
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
            format!(", {:.1} Hz mean", t.messages as f64 / span_s)
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
            "  {}: {}, {} samples, {:.2} Hz (median step), {} left out",
            s.role, s.topic, s.samples, s.rate_hz, s.dropped
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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use truenorth::core::{ImuSample, Mag3Sample};
    use truenorth_logs::OdometrySample;

    fn recording() -> Recording {
        Recording {
            format: LogFormat::Mcap,
            time_origin_s: 0.0,
            complete: true,
            topics: Vec::new(),
            streams: Vec::new(),
            imu: (0..4)
                .map(|k| {
                    ImuSample::new_6d(
                        f64::from(k) * 0.1,
                        Vector3::new(0.1, -0.2, 1.0 / 3.0),
                        Vector3::new(0.0, 0.0, -9.81),
                    )
                })
                .collect(),
            mag: vec![Mag3Sample::new(0.15, 20.0, -1e-7, 45.5)],
            attitude: Vec::new(),
            odometry: vec![OdometrySample {
                t_s: 0.2,
                velocity_mps: Vector3::new(1.0, 0.0, 0.0),
                yaw_rate_rps: 0.5,
            }],
        }
    }

    #[test]
    fn rows_follow_the_columns_asked_for() {
        let r = recording();
        let name = Path::new("x.mcap");
        let mag = render(name, &r, &ReadSpec::new(&MAG), None).unwrap();
        assert_eq!(mag, "t_s,mag_x,mag_y,mag_z\n0.15,20,-0.0000001,45.5\n");
        let joint = render(name, &r, &ReadSpec::new(&["mag_x", "acc_x"]), None).unwrap();
        assert_eq!(joint.lines().count(), 2, "{joint}");
        assert!(joint.starts_with("t_s,gyr_x"), "{joint}");
        let all = render(name, &r, &ReadSpec::new(&["gyr_x"]), None).unwrap();
        let lines: Vec<&str> = all.lines().collect();
        assert_eq!(lines.len(), 5);
        assert!(
            lines[1].ends_with(",,,"),
            "no magnetometer yet: {}",
            lines[1]
        );
        assert!(lines[2].contains("0.3333333333333333"), "{}", lines[2]);
        let drive = render(
            name,
            &r,
            &ReadSpec::new(&["t_s"]).optional(&WHEELS),
            Some(Ok(AxleTrack { track_m: 0.4 })),
        )
        .unwrap();
        let lines: Vec<&str> = drive.lines().collect();
        assert_eq!(
            lines.len(),
            6,
            "4 IMU rows, one magnetometer, one odometry at 0.2 s (shared)"
        );
        assert!(
            lines[4].starts_with("0.2,") && lines[4].ends_with(",1.1,0.9"),
            "{}",
            lines[4]
        );
    }

    #[test]
    fn missing_streams_are_one_line_errors() {
        let mut r = recording();
        r.odometry.clear();
        let name = Path::new("x.mcap");
        let spec = ReadSpec::new(&["t_s"]);
        let e = render(name, &r, &spec, Some(Ok(AxleTrack { track_m: 1.0 }))).unwrap_err();
        assert!(e.to_string().contains("no odometry"), "{e}");
        let e = render(name, &r, &spec, Some(Err("steering wheels".to_string()))).unwrap_err();
        assert!(e.to_string().contains("steering"), "{e}");
        r.mag.clear();
        let e = render(name, &r, &ReadSpec::new(&MAG), None).unwrap_err();
        assert!(e.to_string().contains("--mag-topic"), "{e}");
    }
}
