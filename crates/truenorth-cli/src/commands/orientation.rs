//! `truenorth orientation`: run an orientation estimator over an IMU recording and write the
//! attitude.

use std::path::PathBuf;

use nalgebra::UnitQuaternion;
use truenorth::checks::{
    AccUnit, GyroUnit, Inertial, MagUnit, Reference, check_field, check_inertial, fit_gyro_axes,
    median, median_magnitude,
};
use truenorth::core::{
    AttitudeEstimate, EulerZyx, Fixed, ImuSample, Precise, ned_to_enu, rad_to_deg,
};

use crate::io::checking::{StuckWatch, refusals, refuse_or_warn, say};
use crate::io::errln;
use crate::io::reading::Samples;
use crate::io::reading::kinds::Imu;
use crate::io::{
    CliError, CliResult, CsvOutput, Input, InputOptions, OutputOptions, check_distinct,
};
use crate::plot::{Band, Envelope, Line, write_timeseries};
use crate::registry::{Orientation, OrientationMethod, Timing};

/// Reference frame of the output quaternion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Frame {
    /// North, east, down (the library's frame).
    Ned,
    /// East, north, up (e.g. the BROAD benchmark's frame).
    Enu,
}

/// Arguments of `truenorth orientation`.
///
/// Input: CSV with `t_s` (s, strictly increasing), `gyr_x,gyr_y,gyr_z` (rad/s) and
/// `acc_x,acc_y,acc_z` (m/s², specific force: about +9.81 on the upward axis at rest), and
/// optionally `mag_x,mag_y,mag_z` (any unit, calibrated). Rows whose three magnetometer
/// cells are empty have no magnetometer reading (a magnetometer slower than the gyro); other
/// columns are ignored.
///
/// Output: CSV `t_s,qw,qx,qy,qz,yaw_deg,pitch_deg,roll_deg`. The quaternion (Hamilton,
/// scalar first) rotates sensor-frame vectors into the reference frame chosen with
/// `--frame`: NED (north, east, down; default) or ENU (east, north, up). North is magnetic
/// north. Yaw, pitch and roll are always the Z-Y-X angles of the sensor relative to NED
/// (yaw clockwise from north, pitch nose up, roll right side down), whatever `--frame`.
/// With `--status` the columns `bias_x_rps,bias_y_rps,bias_z_rps,at_rest,mag_used,
/// mag_disturbed,mag_calibrating,gap` follow (estimated gyro bias; 1/0 flags;
/// mag_calibrating: a hard-iron offset learned online is being subtracted; gap: the time
/// since the previous row was longer than the gyro can bridge, 0.5 s, and the attitude was
/// taken anew from this row's accelerometer and magnetometer), and for the quaternion filter
/// `sigma_x_deg,sigma_y_deg,sigma_z_deg`: one standard deviation of the attitude's error
/// about the north, east and down axes (the last is heading's; with `--no-mag`, its drift
/// since the start). `--plot FILE.svg` draws yaw, pitch and roll over time with the samples
/// judged magnetically disturbed shaded.
///
/// The recording is read once, row by row, each output row written as it is estimated:
/// memory does not grow with the recording. The units (and the gyro's axes) are checked on
/// its first 131072 rows, all of a shorter recording; when a longer one shows too little
/// there to judge by, a line on stderr says that they went unchecked.
///
/// After a gap a line on stderr says how many there were and at which rows. Exit status 1
/// with one line on stderr naming the file and row of the first unusable sample
/// (non-finite value, time not increasing, a time base whose steps are mostly such gaps:
/// `t_s` in milliseconds).
///
/// Examples: `truenorth orientation --input imu.csv --output attitude.csv --status`;
/// a logger's file in deg/s and g with x forward, y left, z up:
/// `truenorth orientation --input log.csv.gz --output attitude.csv --gyro-unit deg/s
/// --acc-unit g --axes flu --column t_s=time,gyr_x=gx,gyr_y=gy,gyr_z=gz` (run
/// `truenorth inspect log.csv.gz` first to find the options).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Orientation method.
    #[arg(long, value_enum, default_value = "quaternion")]
    pub method: OrientationMethod,
    /// Input CSV, or a PX4 ULog / ROS 2 MCAP log (found by its magic number; its IMU with
    /// the magnetometer) (`-`: standard input; `.gz` or gzip data read as such).
    #[arg(long)]
    pub input: PathBuf,
    /// Output CSV.
    #[arg(long)]
    pub output: PathBuf,
    /// Reference frame of the output quaternion.
    #[arg(long, value_enum, default_value = "ned")]
    pub frame: Frame,
    /// Ignore the magnetometer (6-D: heading relative to the start, drifting).
    #[arg(long)]
    pub no_mag: bool,
    /// Append the estimated gyro bias, the rest / magnetometer / gap flags and (quaternion
    /// filter) the attitude's σ.
    #[arg(long)]
    pub status: bool,
    /// What a gyro sample's rate stands for (quaternion filter).
    #[arg(long, value_enum, default_value = "interval-mean")]
    pub gyro_timing: Timing,
    /// Also draw yaw, pitch and roll over time, disturbed samples shaded, to this SVG.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Unit of the gyro columns, e.g. `--gyro-unit deg/s`.
    #[arg(long, value_enum, value_name = "UNIT", default_value = "rad/s")]
    pub gyro_unit: GyroUnit,
    /// Unit of the accelerometer columns, e.g. `--acc-unit g`.
    #[arg(long, value_enum, value_name = "UNIT", default_value = "m/s2")]
    pub acc_unit: AccUnit,
    /// Unit of the magnetometer columns (nT, uT, mG or G): the median field the
    /// magnetometer reads must then be a plausible Earth field in it (as `calibrate
    /// --mag-unit` checks its fit), else the run is refused with the unit the data are
    /// probably in (or, with --accept-units, warned about).
    #[arg(long, value_enum, value_name = "UNIT")]
    pub mag_unit: Option<MagUnit>,
    /// Go on (with a warning on stderr) when the data contradict the declared units, instead
    /// of refusing.
    #[arg(long)]
    pub accept_units: bool,
    /// Go on (with a warning on stderr) when the gyro's axes contradict the accelerometer's
    /// and magnetometer's (a flipped, swapped or mirrored gyro axis), instead of refusing.
    #[arg(long)]
    pub accept_axes: bool,
    /// Go on (with a warning on stderr) when a sensor's readings are ones no live sensor
    /// gives (a gyro or magnetometer axis clipped at its range or frozen, a magnetometer
    /// reading exactly zero), instead of refusing.
    #[arg(long)]
    pub accept_sensor_faults: bool,
    /// How to read the file (delimiter, header, column names, axes).
    #[command(flatten)]
    pub input_options: InputOptions,
    /// How to write the numbers.
    #[command(flatten)]
    pub output_options: OutputOptions,
}

const HEADER: [&str; 8] = [
    "t_s",
    "qw",
    "qx",
    "qy",
    "qz",
    "yaw_deg",
    "pitch_deg",
    "roll_deg",
];
const STATUS_HEADER: [&str; 8] = [
    "bias_x_rps",
    "bias_y_rps",
    "bias_z_rps",
    "at_rest",
    "mag_used",
    "mag_disturbed",
    "mag_calibrating",
    "gap",
];
/// With `--status`, after [`STATUS_HEADER`], for an estimator that reports σ.
const SIGMA_HEADER: [&str; 3] = ["sigma_x_deg", "sigma_y_deg", "sigma_z_deg"];
/// Gaps listed by row in the summary line; more are counted.
const GAPS_LISTED: usize = 5;

/// Rows the unit and axis check reads: the first part of the recording, held in memory
/// (about 150 bytes a row, 20 MB), then run through the filter and dropped.
///
/// The check needs moments of near rest half a second apart (at least ten turns of
/// gravity's direction between them) and a median specific force; a recording shows them
/// within its first minutes when it shows them at all, and 2¹⁷ rows are 22 minutes at
/// 100 Hz, 2 minutes at 1 kHz. Every recording up to this length is checked whole, exactly
/// as the check was designed; a longer one is checked on its first part, and when that part
/// holds too little evidence to judge the units or axes, a warning on stderr says so
/// (never a silent pass).
pub const CHECKED_ROWS: usize = 1 << 17;

/// Most shaded bands in a plot: past this, bands closer than twice the joining gap are
/// joined (a plot 900 pixels wide cannot show more).
const MAX_BANDS: usize = 4096;

/// Disturbed stretches closer than this (s) are shaded as one band.
const BAND_JOIN_S: f64 = 0.2;

/// Runs the subcommand: read the recording, check its units on its first part, run the
/// method over it row by row while writing the rows (and gathering the plot's lines), and
/// say where the gyro could not bridge a gap. Memory does not grow with the recording past
/// [`CHECKED_ROWS`].
pub fn run(args: &Args) -> CliResult {
    check_distinct(&args.output, &[&args.input])?;
    if let Some(p) = &args.plot {
        check_distinct(p, &[&args.input, &args.output])?;
    }
    let mut samples = read_samples(args)?;
    if args.frame == Frame::Enu {
        // The columns' names do not say the frame: a reader taking yaw from an ENU file
        // would be off by the frames' difference.
        errln!(
            "truenorth: orientation: note: --frame enu turns the quaternion only; yaw_deg, pitch_deg, roll_deg{} stay relative to north-east-down (yaw clockwise from north)",
            if args.status {
                " and sigma_x/y/z_deg (about north, east, down)"
            } else {
                ""
            }
        );
    }
    let mag_columns = samples.samples.kind().mag_columns();
    let first = samples.first_part(CHECKED_ROWS)?;
    check_units(args, &first)?;
    if samples.peek()?.is_some() {
        check_evidence(args, &first);
    }
    let mut method = args
        .method
        .estimator(!args.no_mag, args.gyro_timing)
        .map_err(CliError::from)?;
    let mut header: Vec<&str> = HEADER.to_vec();
    if args.status {
        header.extend(STATUS_HEADER);
    }
    // Whether the method reports σ is known from its first estimate; the header waits for it.
    let mut run = Estimation::new(args);
    for sample in &first {
        run.step(&mut *method, sample, &header)?;
    }
    drop(first);
    while let Some(sample) = samples.next_sample()? {
        run.step(&mut *method, &sample, &header)?;
    }
    if !args.no_mag {
        say_unused_magnetometer(args, mag_columns, run.stuck.1.readings());
    }
    run.finish(args)
}

/// Refuses a recording whose accelerometer or gyro contradicts its declared unit, or whose
/// gyro axes contradict the other sensors' (or, with `--accept-units` / `--accept-axes`, says
/// so on stderr and goes on).
fn check_units(args: &Args, samples: &[ImuSample]) -> CliResult {
    let findings = check_inertial(samples, args.gyro_unit, args.acc_unit);
    let findings = refusals(&findings, &args.input_options);
    refuse_or_warn(&findings, &args.input, args.accept_units, args.accept_axes)?;
    let mut norms: Vec<f64> = samples
        .iter()
        .filter_map(|s| s.mag.as_xyz())
        .map(|m| m.norm())
        .filter(|n| n.is_finite())
        .collect();
    // The raw magnitude includes any hard iron; the Earth-field range is wide enough that
    // only a wrong unit (a factor of 100 or more) falls outside it.
    let problem = median(&mut norms)
        .and_then(|f| check_field(f, args.mag_unit, None, 3))
        .map(|f| say(&f, &args.input_options));
    match problem {
        Some(p) if args.accept_units => {
            errln!("warning: {}: magnetometer: {p}", args.input.display());
            Ok(())
        }
        Some(p) => Err(CliError::file(
            &args.input,
            format!("magnetometer: {p} (or --accept-units to go on)"),
        )),
        None => Ok(()),
    }
}

/// Says on stderr when magnetometer columns were given but none was used: some of the three
/// missing, or every row's cells empty. The heading is then relative to the start, as with
/// `--no-mag`, which the output's columns alone do not say.
fn say_unused_magnetometer(args: &Args, columns: usize, readings: usize) {
    let why = match (columns, readings) {
        (0, _) => return,
        (1 | 2, _) => format!(
            "only {columns} of mag_x, mag_y, mag_z are present and the magnetometer needs all three"
        ),
        (_, 0) => "mag_x, mag_y, mag_z are present but empty on every row".to_string(),
        _ => return,
    };
    errln!(
        "warning: {}: {why}: no magnetometer reading was used, so the heading is relative to the start heading and drifts (as with --no-mag)",
        args.input.display()
    );
}

/// Says on stderr when the first [`CHECKED_ROWS`] rows of a longer recording (`first`) hold
/// too little to judge the units and axes by: no median specific force, or fewer spans near
/// rest than the axis fit needs. The rest of the recording is not checked.
fn check_evidence(args: &Args, first: &[ImuSample]) {
    let rows = Inertial::from_samples(first);
    let judged = median_magnitude(&rows, Reference::Gravity).is_some()
        && fit_gyro_axes(&rows, 1.0).is_some();
    if !judged {
        errln!(
            "warning: {}: the first {CHECKED_ROWS} rows hold too few moments near rest to check the gyro's and accelerometer's units and the gyro's axes, and later rows are not checked: make sure --gyro-unit, --acc-unit and the axes are right",
            args.input.display()
        );
    }
}

/// The recording as IMU samples, one row at a time.
fn read_samples(args: &Args) -> CliResult<ImuRows> {
    let csv_only = [
        ("--gyro-unit", args.gyro_unit != GyroUnit::default()),
        ("--acc-unit", args.acc_unit != AccUnit::default()),
        (
            "--mag-unit",
            args.mag_unit.is_some_and(|u| u != MagUnit::MicroTesla),
        ),
    ];
    let kind = Imu::new(args.gyro_unit, args.acc_unit, !args.no_mag);
    let samples = Input::new(&args.input, &args.input_options)
        .csv_only(&csv_only)
        .samples(kind)?;
    Ok(ImuRows {
        samples,
        peeked: None,
    })
}

/// The samples of a recording, with one looked at ahead.
struct ImuRows {
    samples: Samples<Imu>,
    peeked: Option<ImuSample>,
}

impl ImuRows {
    /// The next sample, `None` at the end.
    fn next_sample(&mut self) -> CliResult<Option<ImuSample>> {
        if let Some(s) = self.peeked.take() {
            return Ok(Some(s));
        }
        Ok(self.samples.next_sample()?.map(|(_, s)| s))
    }

    /// The next sample, left to be returned by [`ImuRows::next_sample`].
    fn peek(&mut self) -> CliResult<Option<&ImuSample>> {
        if self.peeked.is_none() {
            self.peeked = self.next_sample()?;
        }
        Ok(self.peeked.as_ref())
    }

    /// The first `n` samples (all of a shorter recording); a recording without any is
    /// refused.
    fn first_part(&mut self, n: usize) -> CliResult<Vec<ImuSample>> {
        let mut first = Vec::new();
        while first.len() < n {
            match self.next_sample()? {
                Some(s) => first.push(s),
                None => break,
            }
        }
        Ok(first)
    }
}

/// The run in progress: the output written row by row, the gaps, the plot's lines.
struct Estimation {
    to_frame: UnitQuaternion<f64>,
    status: bool,
    precision: crate::io::Precision,
    input: PathBuf,
    output: PathBuf,
    out: Option<CsvOutput>,
    line: Vec<f64>,
    /// Rows done.
    k: usize,
    previous_t: Option<f64>,
    /// The first [`GAPS_LISTED`] gaps as (row, t_s, gap length), and how many in all.
    gaps: Vec<(usize, f64, f64)>,
    gap_count: usize,
    reports_sigma: bool,
    plot: Option<PlotLines>,
    /// The gyro (rad/s) and magnetometer watched for readings no live sensor gives.
    stuck: (StuckWatch<3>, StuckWatch<3>),
}

impl Estimation {
    fn new(args: &Args) -> Self {
        Self {
            to_frame: match args.frame {
                Frame::Ned => UnitQuaternion::identity(),
                Frame::Enu => ned_to_enu(),
            },
            status: args.status,
            precision: args.output_options.precision,
            input: args.input.clone(),
            output: args.output.clone(),
            out: None,
            line: Vec::with_capacity(HEADER.len() + STATUS_HEADER.len() + SIGMA_HEADER.len()),
            k: 0,
            previous_t: None,
            gaps: Vec::new(),
            gap_count: 0,
            reports_sigma: false,
            plot: args.plot.as_ref().map(|_| PlotLines::default()),
            stuck: (
                StuckWatch::new("gyro (rad/s)", &args.input, args.accept_sensor_faults),
                StuckWatch::magnetometer("magnetometer", &args.input, args.accept_sensor_faults),
            ),
        }
    }

    /// Runs `method` on the next sample and writes its row (the output is started, with
    /// `header` and the σ columns if the method reports σ, at the first).
    fn step(&mut self, method: &mut Orientation, sample: &ImuSample, header: &[&str]) -> CliResult {
        let k = self.k;
        // Row k + 2: the data rows counted after the header.
        let (gyro, mag) = &mut self.stuck;
        if let Some(g) = sample.gyr_rps.as_xyz() {
            gyro.push(k + 2, sample.t_s, &g.into())?;
        }
        if let Some(m) = sample.mag.as_xyz() {
            mag.push(k + 2, sample.t_s, &m.into())?;
        }
        let est = method
            .update(sample)
            .map_err(|e| CliError::row(&self.input, k + 2, e.to_string()).kind_of(&e))?;
        if est.status.gap {
            let since = self.previous_t.map_or(0.0, |p| sample.t_s - p);
            if self.gaps.len() < GAPS_LISTED {
                self.gaps.push((k + 2, sample.t_s, since));
            }
            self.gap_count += 1;
        }
        if k == 0 {
            self.reports_sigma = est.sigma_rad.is_some();
            let mut header = header.to_vec();
            if self.status && self.reports_sigma {
                header.extend(SIGMA_HEADER);
            }
            self.out = Some(CsvOutput::create(&self.output, &header)?);
        }
        self.fill_row(sample.t_s, &est);
        if let Some(out) = &mut self.out {
            out.row(&self.line, self.precision)?;
        }
        if let Some(p) = &mut self.plot {
            p.push(&self.line, est.status.mag_disturbed);
        }
        self.previous_t = Some(sample.t_s);
        self.k += 1;
        Ok(())
    }

    /// One output row at `t_s` into `self.line`: the attitude in the chosen frame, the Z-Y-X
    /// angles from NED, and with `--status` the flags and σ.
    fn fill_row(&mut self, t_s: f64, est: &AttitudeEstimate) {
        let q = self.to_frame * est.attitude;
        let e = EulerZyx::from_quaternion(&est.attitude);
        let row = &mut self.line;
        row.clear();
        row.extend([
            t_s,
            q.w,
            q.i,
            q.j,
            q.k,
            rad_to_deg(e.yaw_rad),
            rad_to_deg(e.pitch_rad),
            rad_to_deg(e.roll_rad),
        ]);
        if self.status {
            let flag = |b: bool| f64::from(u8::from(b));
            row.extend(est.gyro_bias_rps.iter());
            row.extend([
                flag(est.status.at_rest),
                flag(est.status.mag_used),
                flag(est.status.mag_disturbed),
                flag(est.status.mag_calibrating),
                flag(est.status.gap),
            ]);
            if let Some(sigma) = est.sigma_rad.filter(|_| self.reports_sigma) {
                row.extend(sigma.iter().map(|v| rad_to_deg(*v)));
            }
        }
    }

    /// Writes the plot, finishes the output and says where the gaps were.
    fn finish(mut self, args: &Args) -> CliResult {
        self.stuck.0.finish()?;
        self.stuck.1.finish()?;
        if let (Some(p), Some(lines)) = (&args.plot, self.plot) {
            lines.write(p)?;
        }
        if let Some(out) = self.out {
            out.commit()?;
        }
        if self.gap_count > 0 {
            errln!("{}", gap_summary(&args.input, &self.gaps, self.gap_count));
        }
        Ok(())
    }
}

/// One line: how many gaps, where, and what was done about them.
/// `gaps` holds the first [`GAPS_LISTED`] of `count`.
fn gap_summary(input: &std::path::Path, gaps: &[(usize, f64, f64)], count: usize) -> String {
    let listed: Vec<String> = gaps
        .iter()
        .take(GAPS_LISTED)
        .map(|(row, t, gap)| {
            format!(
                "row {row} (t_s {}, after {} s)",
                Precise(*t),
                Fixed(*gap, 3)
            )
        })
        .collect();
    let more = match count.saturating_sub(GAPS_LISTED) {
        0 => String::new(),
        n => format!(" and {n} more"),
    };
    format!(
        "truenorth orientation: {}: {} gap{} longer than the gyro can bridge at {}{more}; the attitude restarted there from the accelerometer and magnetometer (column gap with --status)",
        input.display(),
        count,
        if count == 1 { "" } else { "s" },
        listed.join(", "),
    )
}

/// What the plot draws, gathered row by row in bounded memory: yaw, pitch and roll
/// (columns 5–7 of the output rows) over time, and the bands of disturbed samples.
#[derive(Default)]
struct PlotLines {
    yaw: Envelope,
    pitch: Envelope,
    roll: Envelope,
    bands: Vec<Band>,
    /// Start of the disturbed stretch under way.
    start: Option<f64>,
    last_t: Option<f64>,
    /// Disturbed stretches closer than this (s) join ([`BAND_JOIN_S`], doubled each time
    /// the bands would exceed [`MAX_BANDS`]).
    join_s: f64,
}

impl PlotLines {
    /// Adds an output row and whether its sample was disturbed.
    fn push(&mut self, row: &[f64], disturbed: bool) {
        let t = row[0];
        self.yaw.push(t, row[5]);
        self.pitch.push(t, row[6]);
        self.roll.push(t, row[7]);
        if self.join_s == 0.0 {
            self.join_s = BAND_JOIN_S;
        }
        match (disturbed, self.start) {
            (true, None) => self.start = Some(t),
            (false, Some(t0)) => {
                // A gap shorter than a few samples joins the bands on either side.
                match self.bands.last_mut() {
                    Some(b) if t0 - b.to < self.join_s => b.to = t,
                    _ => self.bands.push(Band { from: t0, to: t }),
                }
                self.start = None;
                if self.bands.len() > MAX_BANDS {
                    self.join_s *= 2.0;
                    let bands = std::mem::take(&mut self.bands);
                    for b in bands {
                        match self.bands.last_mut() {
                            Some(last) if b.from - last.to < self.join_s => last.to = b.to,
                            _ => self.bands.push(b),
                        }
                    }
                }
            }
            _ => {}
        }
        self.last_t = Some(t);
    }

    /// Draws the lines and bands to `path`.
    fn write(mut self, path: &std::path::Path) -> CliResult {
        if let (Some(t0), Some(last)) = (self.start, self.last_t) {
            self.bands.push(Band { from: t0, to: last });
        }
        write_timeseries(
            path,
            "Orientation (shaded: magnetic field judged disturbed)",
            "t (s)",
            "angle (deg)",
            &[
                Line {
                    label: "yaw",
                    colour: "#1f77b4",
                    points: self.yaw.points(),
                },
                Line {
                    label: "pitch",
                    colour: "#2ca02c",
                    points: self.pitch.points(),
                },
                Line {
                    label: "roll",
                    colour: "#d62728",
                    points: self.roll.points(),
                },
            ],
            &self.bands,
        )
    }
}
