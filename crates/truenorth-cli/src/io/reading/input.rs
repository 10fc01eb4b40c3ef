//! One way for a command to open its input, whatever it is: a CSV (a file, gzip data or
//! standard input) or a PX4 ULog / ROS 2 MCAP log, found by its magic number. The command
//! says which options describe a CSV only and, for `drive`, how a log's odometry becomes
//! wheels; it gets back the rows of the columns it asked for, or its samples.

use std::path::Path;

use truenorth_logs::LogFormat;

use super::columns::SENSOR_COLUMNS;
use super::columns::{AxisConvention, ColumnMapping};
use super::logs::{self, AxleOf, AxleTrack, LogInput};
use super::options::InputOptions;
use super::reader::{ReadSpec, RowReader};
use super::records::Delimiter;
use super::samples::{SampleKind, Samples};
use super::source::InputPath;
use crate::io::closest_name::likely_meant;
use crate::io::{CliError, CliResult, errln};

/// An input named on the command line, with the options it is read with.
pub struct Input<'a> {
    path: &'a Path,
    options: &'a InputOptions,
    csv_only: &'a [(&'a str, bool)],
    axle: Option<AxleOf<'a>>,
}

impl<'a> Input<'a> {
    /// The input at `path` (`-`: standard input), read under `options`.
    pub fn new(path: &'a Path, options: &'a InputOptions) -> Self {
        Self {
            path,
            options,
            csv_only: &[],
            axle: None,
        }
    }

    /// The command's own options that describe a CSV (`("--gyro-unit", given)`): given with
    /// a log, each is refused, as are the shared CSV options.
    pub fn csv_only(self, flags: &'a [(&'a str, bool)]) -> Self {
        Self {
            csv_only: flags,
            ..self
        }
    }

    /// How a log's odometry becomes the wheel speeds of a rigid axle (`drive`), asked for
    /// only once the input is a log; its `Err` says why the vehicle's wheels are not one.
    pub fn axle(self, axle: impl FnOnce() -> CliResult<Result<AxleTrack, String>> + 'a) -> Self {
        Self {
            axle: Some(Box::new(axle)),
            ..self
        }
    }

    /// The samples of kind `kind`, one row at a time.
    pub fn samples<K: SampleKind>(self, mut kind: K) -> CliResult<Samples<K>> {
        let (required, optional) = kind.columns();
        let spec = ReadSpec::new(required).optional(optional).increasing("t_s");
        let (rows, _) = self.rows(&spec)?;
        kind.locate(&rows)?;
        Ok(Samples::new(rows, kind))
    }

    /// The rows of the columns of `spec`, and the log they came from if the input is one
    /// (its table handed to the rows).
    pub fn rows(self, spec: &ReadSpec<'_>) -> CliResult<(RowReader, Option<LogInput>)> {
        let input = InputPath::new(self.path);
        let name = input.display_path();
        let Some(format) = logs::detect(&input)? else {
            if let Some(flag) = self.options.log.given().first() {
                return Err(CliError::file(
                    &name,
                    format!(
                        "{flag} chooses a topic of a PX4 ULog or MCAP log, and this input is read as CSV (it does not start with either's magic number); leave it out"
                    ),
                ));
            }
            check_mappings(&self.options.columns, spec)?;
            return Ok((RowReader::open(&input, self.options, spec)?, None));
        };
        refuse_csv_options(&name, format, self.options, self.csv_only)?;
        let columns = (spec.required, spec.optional);
        let mut log = logs::read(&input, format, &self.options.log, columns, self.axle)?;
        let table = std::mem::take(&mut log.table);
        let rows = RowReader::from_log(log.path.clone(), table, spec)?;
        Ok((rows, Some(log)))
    }
}

/// Refuses a `--column NAME=HEADER` whose NAME no command reads (a misspelling, named with
/// the closest one this command reads), and says one this command does not read (a
/// script's mapping shared by several commands); says a NAME given twice with two headers,
/// of which the last is used (the contract: a fix is appended to the options already
/// given).
fn check_mappings(mappings: &[ColumnMapping], spec: &ReadSpec<'_>) -> CliResult {
    let known: Vec<&str> = spec.required.iter().chain(spec.optional).copied().collect();
    for (k, m) in mappings.iter().enumerate() {
        let is = |n: &&str| n.eq_ignore_ascii_case(&m.name);
        if !known.iter().any(is) {
            // A name some other command reads; outside them it is a misspelling.
            if std::iter::once(&"t_s").chain(SENSOR_COLUMNS.iter()).any(is) {
                errln!(
                    "truenorth: warning: --column {}={}: this command does not read `{}`; it reads {}",
                    m.name,
                    m.header,
                    m.name,
                    known.join(", ")
                );
                continue;
            }
            let hint = likely_meant(&m.name, &known)
                .map_or(String::new(), |n| format!(" (did you mean `{n}`?)"));
            return Err(CliError::msg(format!(
                "--column {}={}: `{}` is not a column this command reads{hint}; it reads {}",
                m.name,
                m.header,
                m.name,
                known.join(", ")
            )));
        }
        if let Some(earlier) = mappings[..k].iter().find(|e| {
            e.name.eq_ignore_ascii_case(&m.name) && (e.header != m.header || e.negate != m.negate)
        }) {
            errln!(
                "truenorth: warning: --column gives `{}` twice, from `{}{}` and from `{}{}`: the last is used",
                m.name,
                if earlier.negate { "-" } else { "" },
                earlier.header,
                if m.negate { "-" } else { "" },
                m.header
            );
        }
    }
    Ok(())
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
