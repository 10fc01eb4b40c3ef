//! `truenorth orientation`: run an orientation estimator over an IMU recording and write the
//! attitude.

use std::path::PathBuf;

use nalgebra::{UnitQuaternion, Vector3};
use truenorth::core::{AttitudeEstimate, Axes, EulerZyx, ImuSample, ned_to_enu, rad_to_deg};

use super::mag_unit::{MagUnit, check_field};
use crate::io::errln;
use crate::io::log_input;
use crate::io::{
    AccUnit, CliError, CliResult, GyroUnit, InputOptions, OutputOptions, ReadSpec, Table,
    check_distinct, check_inertial, median, refuse_or_warn, write_csv,
};
use crate::plot::{Band, Line, write_timeseries};
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

/// Runs the subcommand: read the recording, run the method over it, write the rows (and
/// the plot), and say where the gyro could not bridge a gap.
pub fn run(args: &Args) -> CliResult {
    check_distinct(&args.output, &[&args.input])?;
    if let Some(p) = &args.plot {
        check_distinct(p, &[&args.input, &args.output])?;
    }
    let samples = read_samples(args)?;
    check_units(args, &samples)?;
    let mut method = args
        .method
        .pipeline(!args.no_mag, args.gyro_timing)
        .map_err(|e| CliError::msg(e.to_string()))?;
    let out = estimate(args, &mut method, &samples)?;
    if let Some(p) = &args.plot {
        plot(p, &out.rows, &out.disturbed)?;
    }
    let mut header: Vec<&str> = HEADER.to_vec();
    if args.status {
        header.extend(STATUS_HEADER);
        if out.reports_sigma {
            header.extend(SIGMA_HEADER);
        }
    }
    write_csv(
        &args.output,
        &header,
        out.rows,
        args.output_options.precision,
    )?;
    if !out.gaps.is_empty() {
        errln!("{}", gap_summary(&args.input, &out.gaps));
    }
    Ok(())
}

/// Refuses a recording whose accelerometer or gyro contradicts its declared unit, or whose
/// gyro axes contradict the other sensors' (or, with `--accept-units` / `--accept-axes`, says
/// so on stderr and goes on).
fn check_units(args: &Args, samples: &[ImuSample]) -> CliResult {
    let findings = check_inertial(samples, args.gyro_unit, args.acc_unit, &args.input_options);
    refuse_or_warn(&findings, &args.input, args.accept_units, args.accept_axes)?;
    let mut norms: Vec<f64> = samples
        .iter()
        .filter_map(|s| s.mag.as_xyz())
        .map(|m| m.norm())
        .filter(|n| n.is_finite())
        .collect();
    // The raw magnitude includes any hard iron; the Earth-field range is wide enough that
    // only a wrong unit (a factor of 100 or more) falls outside it.
    let problem = median(&mut norms).and_then(|f| check_field(f, args.mag_unit, None, 3));
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

/// The recording as IMU samples; a row whose three magnetometer cells are empty has no
/// magnetometer reading, and with `--no-mag` none has.
fn read_samples(args: &Args) -> CliResult<Vec<ImuSample>> {
    let spec = ReadSpec::new(&["t_s", "gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z"])
        .optional(&["mag_x", "mag_y", "mag_z"]);
    let csv_only = [
        ("--gyro-unit", args.gyro_unit != GyroUnit::default()),
        ("--acc-unit", args.acc_unit != AccUnit::default()),
        (
            "--mag-unit",
            args.mag_unit.is_some_and(|u| u != MagUnit::MicroTesla),
        ),
    ];
    let input = log_input::source(&args.input, &args.input_options, &spec, &csv_only)?;
    let table = Table::read_with(&input, &args.input_options, &spec)?;
    let (to_rps, to_mps2) = (args.gyro_unit.to_rad_per_s(), args.acc_unit.to_mps2());
    table.require_rows()?;
    table.check_increasing_time()?;
    let col = |n: &str| table.req(n);
    let (t, gx, gy, gz) = (col("t_s")?, col("gyr_x")?, col("gyr_y")?, col("gyr_z")?);
    let (ax, ay, az) = (col("acc_x")?, col("acc_y")?, col("acc_z")?);
    let mag = match (table.col("mag_x"), table.col("mag_y"), table.col("mag_z")) {
        (Some(x), Some(y), Some(z)) if !args.no_mag => Some((x, y, z)),
        _ => None,
    };
    Ok((0..table.len())
        .map(|k| ImuSample {
            t_s: t[k],
            gyr_rps: Axes::xyz(Vector3::new(gx[k], gy[k], gz[k]) * to_rps),
            acc_mps2: Axes::xyz(Vector3::new(ax[k], ay[k], az[k]) * to_mps2),
            mag: match mag {
                Some((x, y, z)) if x[k].is_nan() && y[k].is_nan() && z[k].is_nan() => Axes::NONE,
                Some((x, y, z)) => Axes::xyz(Vector3::new(x[k], y[k], z[k])),
                None => Axes::NONE,
            },
        })
        .collect())
}

/// What the run gives: the output rows, which samples were magnetically disturbed, the
/// gaps as (row, t_s, gap length), and whether the method reports σ.
struct Estimated {
    rows: Vec<Vec<f64>>,
    disturbed: Vec<bool>,
    gaps: Vec<(usize, f64, f64)>,
    reports_sigma: bool,
}

/// Runs `method` over `samples`, one output row each.
fn estimate(args: &Args, method: &mut Orientation, samples: &[ImuSample]) -> CliResult<Estimated> {
    let to_frame = match args.frame {
        Frame::Ned => UnitQuaternion::identity(),
        Frame::Enu => ned_to_enu(),
    };
    let mut out = Estimated {
        rows: Vec::with_capacity(samples.len()),
        disturbed: Vec::with_capacity(samples.len()),
        gaps: Vec::new(),
        reports_sigma: false,
    };
    for (k, sample) in samples.iter().enumerate() {
        let est = method
            .update(sample)
            .map_err(|e| CliError::row(&args.input, k + 2, e.to_string()))?
            .estimate;
        if est.status.gap {
            let since = k
                .checked_sub(1)
                .map_or(0.0, |j| sample.t_s - samples[j].t_s);
            out.gaps.push((k + 2, sample.t_s, since));
        }
        if k == 0 {
            out.reports_sigma = est.sigma_rad.is_some();
        }
        out.rows
            .push(row(args, sample.t_s, &to_frame, &est, out.reports_sigma));
        out.disturbed.push(est.status.mag_disturbed);
    }
    Ok(out)
}

/// One output row at `t_s`: the attitude in the chosen frame, the Z-Y-X angles from NED, and with
/// `--status` the flags and σ.
fn row(
    args: &Args,
    t_s: f64,
    to_frame: &UnitQuaternion<f64>,
    est: &AttitudeEstimate,
    reports_sigma: bool,
) -> Vec<f64> {
    let q = to_frame * est.attitude;
    let e = EulerZyx::from_quaternion(&est.attitude);
    let mut row = vec![
        t_s,
        q.w,
        q.i,
        q.j,
        q.k,
        rad_to_deg(e.yaw_rad),
        rad_to_deg(e.pitch_rad),
        rad_to_deg(e.roll_rad),
    ];
    if args.status {
        let flag = |b: bool| f64::from(u8::from(b));
        row.extend(est.gyro_bias_rps.iter());
        row.extend([
            flag(est.status.at_rest),
            flag(est.status.mag_used),
            flag(est.status.mag_disturbed),
            flag(est.status.mag_calibrating),
            flag(est.status.gap),
        ]);
        if let Some(sigma) = est.sigma_rad.filter(|_| reports_sigma) {
            row.extend(sigma.iter().map(|v| rad_to_deg(*v)));
        }
    }
    row
}

/// One line: how many gaps, where, and what was done about them.
fn gap_summary(input: &std::path::Path, gaps: &[(usize, f64, f64)]) -> String {
    let listed: Vec<String> = gaps
        .iter()
        .take(GAPS_LISTED)
        .map(|(row, t, gap)| format!("row {row} (t_s {t}, after {gap:.3} s)"))
        .collect();
    let more = match gaps.len().saturating_sub(GAPS_LISTED) {
        0 => String::new(),
        n => format!(" and {n} more"),
    };
    format!(
        "truenorth orientation: {}: {} gap{} longer than the gyro can bridge at {}{more}; the attitude restarted there from the accelerometer and magnetometer (column gap with --status)",
        input.display(),
        gaps.len(),
        if gaps.len() == 1 { "" } else { "s" },
        listed.join(", "),
    )
}

/// Yaw, pitch and roll (columns 5–7 of the output rows) over time, disturbed samples shaded.
fn plot(path: &std::path::Path, rows: &[Vec<f64>], disturbed: &[bool]) -> CliResult {
    let series = |i: usize| rows.iter().map(|r| (r[0], r[i])).collect::<Vec<_>>();
    let mut bands: Vec<Band> = Vec::new();
    let mut start = None;
    for (r, &d) in rows.iter().zip(disturbed) {
        match (d, start) {
            (true, None) => start = Some(r[0]),
            (false, Some(t0)) => {
                // A gap shorter than a few samples joins the bands on either side.
                match bands.last_mut() {
                    Some(b) if t0 - b.to < 0.2 => b.to = r[0],
                    _ => bands.push(Band { from: t0, to: r[0] }),
                }
                start = None;
            }
            _ => {}
        }
    }
    if let (Some(t0), Some(last)) = (start, rows.last()) {
        bands.push(Band {
            from: t0,
            to: last[0],
        });
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
                points: series(5),
            },
            Line {
                label: "pitch",
                colour: "#2ca02c",
                points: series(6),
            },
            Line {
                label: "roll",
                colour: "#d62728",
                points: series(7),
            },
        ],
        &bands,
    )
}
