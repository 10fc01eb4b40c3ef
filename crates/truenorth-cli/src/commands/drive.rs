//! `truenorth drive`: vehicle heading and dead reckoning from a drive log — wheels, an
//! optional yaw gyro and an uncalibrated compass — calibrating every sensor from the drive
//! itself.

use std::path::{Path, PathBuf};

use truenorth::checks::GyroUnit;
use truenorth::core::{Fixed, Travel, VehicleSensors, rad_to_deg};
use truenorth::fusion::vehicle::VehicleCalibration;
use truenorth::fusion::{SensorPriors, VehicleConfig, VehicleEstimator};
use truenorth::odometer::OdometerWheels;

use super::field::PlaceArgs;
use crate::io::checking::{MagWatch, StuckWatch};
use crate::io::errln;
use crate::io::reading::Samples;
use crate::io::reading::kinds::Vehicle;
use crate::io::reading::logs::AxleTrack;
use crate::io::reading::wheels::FourWheels;
use crate::io::{
    CliError, CliResult, Input, InputOptions, OutputOptions, VehicleFile, check_distinct,
    read_learned, write_learned,
};
use crate::registry::{VehicleMethod, VehicleRun};

mod diagnose;
mod fix_check;
mod output;

use diagnose::{Context, Diagnosis};
use fix_check::FixTimes;
pub use output::Extra;
use output::{Tally, Writer};

/// The long help of the command (after the options).
const AFTER_HELP: &str = "VEHICLE.json: {\"track_m\": 1.55, \"odometer_wheels\": \"rear\"} or
{\"track_m\": 1.55, \"wheelbase_m\": 2.7, \"odometer_wheels\": \"front\", \"pitman_ratio\": 0.13}
or {\"track_m\": 0.6, \"odometer_wheels\": \"skid_steer\"} or \"differential\" — track_m the
odometer wheels' track, m (a skid-steer's physical track: the effective one, 1.5-2.5 times it,
is learned); wheelbase_m rear axle to front kingpins, m; pitman_ratio P = 2p/T_F (kingpin
offset p over half the front track; front wheels only). Optional: \"wheel_resolution_m\"
(distance per odometer pulse, default 0.02 with distance columns on a car and 0.003 with
speed columns, a CAN bus's 0.01 km/h over one second; 0.001 on a robot),
\"wheel_speed_quantum_mps\" (the step wheel speeds are sent in, default 0.01 km/h on a car
and 1 mm/s on a robot: held steady, each wheel's rounding turns the heading),
\"gnss_lever_arm_m\" ([forward, right] of the GNSS antenna from the axle's centre, m;
default [0, 0]), \"gnss_latency_s\" (how long after its epoch a fix is stamped, s; default
0.1, and drive says when the fixes' course shows another), \"compass_systematic_deg\" (the compass's systematic heading error, default 3: a level
two-axis compass on roads whose grade and camber tilt it; about 0.3 for a tilt-compensated
compass or level ground) and \"version\": 1.
Unknown keys are refused (naming the closest known one), and so are values no vehicle has.

DRIVE.csv: `t_s` (strictly increasing, seconds) and any of: `dist_l_m,dist_r_m` (cumulative
distance of the left and right odometer wheels as the odometer reports it) or
`speed_l_mps,speed_r_mps` (wheel speeds, integrated by the trapezoid rule), or a car's four
`speed_fl_mps,speed_fr_mps,speed_rl_mps,speed_rr_mps` (the axle odometer_wheels names is read,
the other said unused; a skid-steered vehicle's sides are each side's mean), or the vehicle's
one `dist_m` (cumulative) or `speed_mps` (a CAN bus's vehicle speed): the distance only,
nothing about turning; `gyr_z` (rad/s,
or deg/s with --gyro-unit deg/s; raw, positive for a right turn); `mag_x,mag_y` (any unit, uncalibrated; a level compass
reads mag_x = H cos(heading), mag_y = -H sin(heading)). Each sensor may come at its own
rate: an empty cell means no reading on that row, and each row is used for what it carries.
Wheels, a gyro or a compass must be present; the summary names the sensor set and warns of
what it cannot tell (no north without a compass, no gyro gain without a second turn
reference). A speed beside wheel columns is said unused, and so are four wheel speeds beside
the odometer wheels' own; other columns are ignored. Satellite fixes: `lat_deg,lon_deg`
(WGS84) with `gnss_sigma_m` (1σ, m; 5 where absent) and optionally
`gnss_speed_mps,gnss_course_deg`, on their own rows: with odometry the fused method refers
heading and track to them (north_m, east_m in the tangent plane at the first fix, heading
from true north) and corrects the position with each; without odometry their course (at 3 m/s
or more) refers the heading to true north and corrects it, the position staying empty;
`--extra geodetic` adds lat_deg, lon_deg. Frames: x forward, y right,
z down.

Output: `t_s,north_m,east_m,heading_deg` — the rear-axle centre from the start point, and
the heading clockwise from magnetic north (true north with --lat/--lon: the track is
turned with it), in [0, 360). Without wheels the position cells are empty (no position,
not zero). `--extra sigma` adds heading_sigma_deg, north_sigma_m, east_sigma_m (the
heading's σ is of the heading change since the start while heading_absolute is 0);
`--extra status` adds heading_absolute, compass_used, compass_disturbed, at_rest (0/1);
`--extra calibration` adds the learned gyro_bias_dps, gyro_gain_right, gyro_gain_left,
wheel_diff, track_scale, speed_coeff_s2_per_m2, wheel_scale (the odometer's distance
gain, learned from satellite fixes), wheel_lag_s (how far the wheels' readings trail the
gyro's) (fused method only); `--extra trust` adds
gap (a sensor's readings resumed after more than 2 s: what it could not follow was
widened) and unobserved_gyro_bias, unobserved_gyro_gain_right, unobserved_gyro_gain_left,
unobserved_wheel_diff, unobserved_track_scale, unobserved_speed_coeff,
unobserved_wheel_scale, unobserved_wheel_lag (1 while the data
have not told that sensor error apart from the others: a steady circle cannot separate a
gyro bias from a wheel-size difference).

Nothing is assumed calibrated: a drive that begins with a full turn (or one that turns
through a few corners soon) calibrates the compass from itself. Until then the heading is
relative to the start (status heading_absolute 0). By default the head of the drive is
held back (at most 2^17 rows) until the sensors are learned and then estimated again
from the start, so that the first minutes are as good as the rest; --single-pass writes
each row as it comes (a causal estimate, as a navigation unit would have it).
--calibration-in/--calibration-out carry what was learned from one drive to the next.
A time base that contradicts the motion (t_s in milliseconds, a gyro in deg/s) is refused
with the row where the evidence became clear. Where the drive turns (ten one-second windows
of 3° or more by the wheels), the gyro is checked against the wheels: one that turns 57 times
too far or too little is refused naming --gyro-unit, one that turns the other way naming
--column gyr_z=-HEADER (--accept-units / --accept-axes: warn and go on).

Output heading: degrees clockwise from magnetic north, or from true north with --lat/--lon
(magnetic + the World Magnetic Model's declination); north_m, east_m in metres from the
start (NED, z down).

Examples: truenorth drive --vehicle car.json --input drive.csv --output track.csv
--extra sigma,status; the next drive, starting from what this one learned, in true north:
truenorth drive --vehicle car.json --input drive2.csv.gz --output track2.csv
--calibration-in learned.json --lat 51.5 --lon -0.13 --date 2026-06-01
(with --calibration-out learned.json on the first).";

/// Distance resolution assumed for integrated wheel speeds, m: a CAN bus's 0.01 km/h over
/// the one second in which the estimator compares wheels with gyro. The pulse default
/// (2 cm) would make such wheels look a hundred times noisier than they are.
const SPEED_RESOLUTION_M: f64 = 0.003;

/// Arguments of `truenorth drive` (the file layouts are in `AFTER_HELP`, shown by `--help`).
#[derive(Debug, clap::Args)]
#[command(after_long_help = AFTER_HELP)]
pub struct Args {
    /// Vehicle JSON: track_m, odometer_wheels ("rear", "front", "skid_steer" or
    /// "differential"), wheelbase_m and pitman_ratio for front wheels.
    #[arg(long)]
    pub vehicle: PathBuf,
    /// Drive CSV, or a ROS 2 MCAP log with odometry (found by its magic number; read as a
    /// rigid axle's wheel speeds) (`-`: standard input; `.gz` or gzip data read as such).
    #[arg(long)]
    pub input: PathBuf,
    /// Output CSV (`-`: standard output; `*.gz`: compressed).
    #[arg(long)]
    pub output: PathBuf,
    /// Estimation method.
    #[arg(long, value_enum, default_value = "fused")]
    pub method: VehicleMethod,
    /// Extra output columns, after the contract's (comma-separated).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub extra: Vec<Extra>,
    /// Write each row as it comes instead of estimating the drive's head again once the
    /// sensors are learned.
    #[arg(long)]
    pub single_pass: bool,
    /// Start from what an earlier drive learned (a file written by --calibration-out).
    #[arg(long, value_name = "JSON")]
    pub calibration_in: Option<PathBuf>,
    /// Write what this drive learned about the sensors.
    #[arg(long, value_name = "JSON")]
    pub calibration_out: Option<PathBuf>,
    /// Unit of the gyr_z column, e.g. `--gyro-unit deg/s`.
    #[arg(long, value_enum, value_name = "UNIT", default_value = "rad/s")]
    pub gyro_unit: GyroUnit,
    /// Go on (with a warning on stderr) when the gyro's turns contradict its declared unit,
    /// instead of refusing.
    #[arg(long)]
    pub accept_units: bool,
    /// Go on (with a warning on stderr) when the gyro turns against the wheels (its sign
    /// flipped), instead of refusing.
    #[arg(long)]
    pub accept_axes: bool,
    /// Go on (with a warning on stderr) when the yaw gyro's or the compass's readings are
    /// ones no live sensor gives (clipped at the range, frozen, a field of exactly zero),
    /// instead of refusing.
    #[arg(long)]
    pub accept_sensor_faults: bool,
    /// Where and when the drive was made, for true heading.
    #[command(flatten)]
    pub place: PlaceArgs,
    /// How to read the input.
    #[command(flatten)]
    pub input_options: InputOptions,
    /// How to write the numbers.
    #[command(flatten)]
    pub output_options: OutputOptions,
}

/// Runs the subcommand: check the arguments, read the vehicle, build the method, run it
/// over the log row by row, then save what it learned and summarise.
pub fn run(args: &Args) -> CliResult {
    check_arguments(args)?;
    let csv_only = [("--gyro-unit", args.gyro_unit != GyroUnit::default())];
    let mut samples = Input::new(&args.input, &args.input_options)
        .csv_only(&csv_only)
        .axle(|| axle(args))
        .samples(Vehicle::new(args.gyro_unit, four_wheels(args)))?;
    let vehicle = VehicleFile::read(&args.vehicle)?;
    let wheels = vehicle.wheels(&args.vehicle)?;
    let true_north = args.place.true_north()?;
    let speeds = samples.kind().speeds();
    let mut method = build_method(args, &vehicle, wheels, speeds)?;
    samples.kind().check_compass(samples.path())?;
    for (name, why) in samples.kind().unused_columns() {
        errln!("truenorth drive: warning: `{name}` is not used: {why}");
    }
    let odometry = samples.kind().has_odometry();
    if samples.kind().has_gnss() {
        if args.method != VehicleMethod::Fused {
            errln!(
                "truenorth drive: warning: `lat_deg,lon_deg` are not used: only --method fused takes satellite fixes"
            );
        } else if !odometry && !samples.kind().gnss_course_given() {
            errln!(
                "truenorth drive: warning: `lat_deg,lon_deg` are not used: between fixes only odometry (wheels, a speed or a distance) carries the position, and there is none; with `gnss_speed_mps,gnss_course_deg` their course would refer the heading to true north"
            );
        } else if !odometry {
            errln!(
                "truenorth drive: warning: `lat_deg,lon_deg` give no position: between fixes only odometry (wheels, a speed or a distance) carries it, and there is none; their course (at 3 m/s or more) refers the heading to true north and corrects it"
            );
        } else if !samples.kind().gnss_sigma_given() {
            errln!(
                "truenorth drive: warning: the fixes carry no `gnss_sigma_m`: each is taken as {} m (1σ) and judged by that",
                truenorth::fusion::GnssConfig::default().default_sigma_m
            );
        }
        if args.method == VehicleMethod::Fused
            && (odometry || samples.kind().gnss_course_given())
            && args.place.is_given()
        {
            errln!(
                "truenorth drive: warning: --lat/--lon are not used for true north: the satellite fixes give it (rows before the first fixes that refer the heading still use them)"
            );
        }
    } else {
        for (key, given) in [
            ("gnss_lever_arm_m", vehicle.gnss_lever_arm_m.is_some()),
            ("gnss_latency_s", vehicle.gnss_latency_s.is_some()),
        ] {
            if given {
                errln!(
                    "truenorth drive: warning: `{key}` in the vehicle file is not used: the log has no satellite fixes"
                );
            }
        }
    }
    let mut check = Diagnosis::new(vehicle.track_m, wheels.can_pivot(), speeds);
    let mut writer = Writer::create(
        &args.output,
        &args.extra,
        true_north,
        args.output_options.precision,
    )?;
    let context = diagnosis_context(args, speeds);
    let mut sensors = VehicleSensors::default();
    let mut fix_times = FixTimes::new(
        vehicle
            .gnss_latency_s
            .unwrap_or(truenorth::fusion::GnssConfig::default().latency_s),
    );
    let mut watch = (
        StuckWatch::new("gyr_z (rad/s)", &args.input, args.accept_sensor_faults),
        MagWatch::new(&args.input, args.accept_sensor_faults),
    );
    let samples = estimate(
        &mut samples,
        &mut watch,
        &mut check,
        (&mut sensors, &mut fix_times),
        method.as_mut(),
        &mut writer,
    )
    .map_err(|e| {
        check
            .check(&context)
            .err()
            .unwrap_or_else(|| check.explain(e))
    })?;
    check.check(&context)?;
    let learned = method.calibration();
    if let (Some(out), Some(learned)) = (&args.calibration_out, &learned) {
        write_learned(out, learned)?;
    }
    let Writer { out, tally, .. } = writer;
    out.commit()?;
    summary(args, samples, &tally, learned.as_ref(), &sensors);
    for limit in sensors.limits() {
        errln!("truenorth drive: warning: {limit}");
    }
    if args.method == VehicleMethod::Fused {
        for warning in fix_times.warnings(tally.gnss.map(|(counts, _)| counts)) {
            errln!("truenorth drive: warning: {warning}");
        }
    }
    Ok(())
}

/// Refuses outputs that are inputs and options that do not go together, before anything
/// is read.
fn check_arguments(args: &Args) -> CliResult {
    let mut inputs: Vec<&Path> = vec![&args.input, &args.vehicle];
    if let Some(c) = &args.calibration_in {
        inputs.push(c);
    }
    check_distinct(&args.output, &inputs)?;
    if let Some(c) = &args.calibration_out {
        check_distinct(c, &inputs)?;
        if c == &args.output {
            return Err(CliError::msg(
                "drive: --calibration-out and --output name the same file",
            ));
        }
    }
    if args.extra.contains(&Extra::Calibration) && args.method != VehicleMethod::Fused {
        return Err(CliError::msg(
            "drive: --extra calibration needs --method fused (the seed methods learn other things)",
        ));
    }
    Ok(())
}

/// The method the arguments ask for, through the registry. The fused estimator starts from
/// the sensor priors of the vehicle (with the distance resolution of integrated speeds
/// when the log has speeds and the file gives none), or from `--calibration-in`.
fn build_method(
    args: &Args,
    vehicle: &VehicleFile,
    wheels: OdometerWheels,
    speeds: bool,
) -> CliResult<Box<dyn VehicleRun>> {
    let mut priors = if speeds {
        SensorPriors::for_wheel_speeds(&wheels)
    } else {
        SensorPriors::for_wheels(&wheels)
    };
    if let Some(r) = vehicle.wheel_resolution_m {
        priors.wheel_resolution_m = r;
    } else if speeds && !wheels.can_pivot() {
        priors.wheel_resolution_m = SPEED_RESOLUTION_M;
    }
    if let Some(q) = vehicle.wheel_speed_quantum_mps.filter(|_| speeds) {
        priors.wheel_speed_quantum_mps = q;
    }
    let mut config = VehicleConfig {
        wheels,
        priors: Some(priors),
        ..VehicleConfig::default()
    };
    if let Some(s) = vehicle.compass_systematic_deg {
        config.compass.systematic_deg = s;
    }
    if let Some(l) = vehicle.gnss_lever_arm_m {
        config.gnss.lever_arm_m = l;
    }
    if let Some(l) = vehicle.gnss_latency_s {
        config.gnss.latency_s = l;
    }
    // The declination that relates the compass to the fixes' true north comes from
    // WMM2025, which holds from 2025.0 to 2030.0; a date outside is taken at its nearest
    // end (the declination moves by a few tenths of a degree in five years).
    config.gnss.decimal_year = args.place.decimal_year()?.clamp(2025.0, 2029.999);
    let bad_config =
        |e: truenorth::core::Error| CliError::file(&args.vehicle, e.to_string()).kind_of(&e);
    let fused = match &args.calibration_in {
        Some(path) => {
            let learned = read_learned(path)?;
            VehicleEstimator::with_calibration(config, &learned)
                .map_err(|e| CliError::file(path, e.to_string()).kind_of(&e))?
        }
        None => VehicleEstimator::new(config).map_err(bad_config)?,
    };
    args.method
        .runner(wheels, fused, args.single_pass)
        .map_err(bad_config)
}

/// Which of a car's four wheel speeds are the odometer's: the axle the vehicle's
/// `odometer_wheels` names, or each side's mean for a skid-steered vehicle (a
/// differential-drive robot has only its two driven wheels). A vehicle file that cannot be
/// read is refused just after the log's columns are, so the choice made for it is never used.
fn four_wheels(args: &Args) -> FourWheels {
    match VehicleFile::read(&args.vehicle).and_then(|v| v.wheels(&args.vehicle)) {
        Ok(OdometerWheels::Front(_)) => FourWheels::Front,
        Ok(OdometerWheels::Rear { .. }) => FourWheels::Rear,
        _ => FourWheels::SideMeans,
    }
}

/// How a flight or robot log's odometry becomes the wheels read: the speeds of a rigid axle
/// with the vehicle's track, or why the vehicle's wheels are not one.
fn axle(args: &Args) -> CliResult<Result<AxleTrack, String>> {
    let wheels = VehicleFile::read(&args.vehicle)?.wheels(&args.vehicle)?;
    Ok(match wheels {
        OdometerWheels::Rear { track_m } | OdometerWheels::Differential { track_m } => {
            Ok(AxleTrack { track_m })
        }
        other => Err(format!(
            "a log's odometry gives the body's speed and turn, read as the wheels of a rigid axle that do not slide; {} has {} odometer wheels: describe it as \"rear\" or \"differential\" with the same track_m",
            args.vehicle.display(),
            match other {
                OdometerWheels::Front(_) => "steered (front)",
                _ => "sliding (skid_steer)",
            }
        )),
    })
}

/// What the diagnosis of the log needs of the arguments. It refuses a drive whose data
/// contradict how they were declared (a unit, a sign, the wheels' sides, the track), or with
/// `--accept-units` / `--accept-axes` says so on stderr: before the output is committed,
/// and in place of the estimator's own error when that came from the same contradiction.
fn diagnosis_context(args: &Args, speeds: bool) -> Context<'_> {
    Context {
        input: args.input.clone(),
        vehicle: args.vehicle.clone(),
        gyro_unit: args.gyro_unit,
        options: &args.input_options,
        speeds,
        accept_units: args.accept_units,
        accept_axes: args.accept_axes,
        accept_sensor_faults: args.accept_sensor_faults,
    }
}

/// Runs `method` over every sample, each to the diagnosis `check` first and each final
/// estimate to `writer`; the number of samples.
fn estimate(
    samples: &mut Samples<Vehicle>,
    (gyro, mag): &mut (StuckWatch<1>, MagWatch),
    check: &mut Diagnosis,
    (sensors, fix_times): (&mut VehicleSensors, &mut FixTimes),
    method: &mut dyn VehicleRun,
    writer: &mut Writer,
) -> CliResult<usize> {
    let path = samples.path().to_path_buf();
    let count = samples.for_each(|row, sample| {
        if let Some(rate) = sample.gyr_z_rps {
            gyro.push(row, sample.t_s, &[rate])?;
        }
        if let Some(m) = &sample.mag {
            mag.push_cells(row, sample.t_s, m.as_slice())?;
        }
        check.push(&sample, row);
        sensors.add(&sample);
        fix_times.push(&sample);
        method
            .push(&sample, &mut |e, fused| writer.write(e, fused))
            .map_err(|e| CliError::row(&path, row, e.to_string()).kind_of(&e))?;
        writer.error.take().map_or(Ok(()), Err)
    })?;
    gyro.finish()?;
    mag.finish()?;
    method
        .finish(&mut |e, fused| writer.write(e, fused))
        .map_err(|e| CliError::file(&path, e.to_string()).kind_of(&e))?;
    if let Some(e) = writer.error.take() {
        return Err(e);
    }
    Ok(count)
}

/// One line on stderr: what was done, what was learned, and the sensor set the log carried
/// (what that set cannot tell follows, a warning line each).
fn summary(
    args: &Args,
    samples: usize,
    tally: &Tally,
    learned: Option<&VehicleCalibration>,
    sensors: &VehicleSensors,
) {
    let Tally {
        rows: written,
        gaps,
        fallbacks,
        gnss,
        last,
    } = *tally;
    let Some(e) = last else { return };
    let reference = if e.status.gnss_frame {
        "true north, from the satellite fixes"
    } else if !e.status.heading_absolute {
        "relative to the start heading (the compass never calibrated)"
    } else if args.place.is_given() {
        "true north"
    } else {
        "magnetic north"
    };
    let mut line = format!(
        "truenorth drive: {samples} rows → {written}, {} m, heading {reference}",
        Fixed(e.distance_m, 0)
    );
    if !e.status.position_known {
        line += " (no wheels or speed: no position)";
    }
    line += &format!(", final heading σ {:.2}°", rad_to_deg(e.heading_sigma_rad));
    if let Some(c) = learned {
        line += &format!(", gyro bias {:.3}°/s", rad_to_deg(c.gyro_bias_rps.value));
        if sensors.travel == Travel::Wheels {
            line += &format!(
                ", wheel scale difference {:.3} %",
                100.0 * c.wheel_diff.value
            );
        }
        if gnss.is_some() && sensors.travel != Travel::None {
            line += &format!(
                ", odometer scale {:+.2} ± {:.2} % (from the fixes)",
                100.0 * c.wheel_scale.value,
                100.0 * c.wheel_scale.sigma
            );
        }
    }
    let u = e.status.unobserved;
    // The wheels' states say nothing of a drive without them.
    let (wheels, odometer) = (
        sensors.travel == Travel::Wheels,
        sensors.travel != Travel::None,
    );
    let open: Vec<&str> = [
        (u.gyro_bias, "gyro bias"),
        (u.gyro_gain_right, "gyro gain right"),
        (u.gyro_gain_left, "gyro gain left"),
        (u.wheel_diff && wheels, "wheel scale difference"),
        (u.track_scale && wheels, "effective track"),
        (u.speed_coeff && wheels, "speed coefficient"),
        (u.wheel_scale && odometer, "odometer scale"),
        (u.wheel_lag && wheels, "wheels' delay"),
    ]
    .iter()
    .filter(|(o, _)| *o)
    .map(|(_, n)| *n)
    .collect();
    if !open.is_empty() {
        line += &format!(
            "; not yet told apart by the motion (their priors stand): {}",
            open.join(", ")
        );
    }
    if gaps > 0 {
        line += &format!("; {gaps} gaps in the log, widened rather than bridged");
    }
    if fallbacks > 0 {
        line += &format!(
            "; fell back to plain integration {fallbacks} times (a learned gyro or wheel error that the gyro's own integration contradicted was forgotten)"
        );
    }
    if let Some((c, (lat, lon))) = gnss {
        if sensors.travel == Travel::None {
            line += &format!(
                "; satellite fixes: {} courses used (no odometry: no position)",
                c.used
            );
        } else {
            line += &format!(
                "; satellite fixes: {} used, {} rejected (too far from the dead-reckoned track), {} restarts of the position after a run of rejections; north_m, east_m from {lat:.7}, {lon:.7} (the first fix)",
                c.used, c.rejected, c.restarts
            );
        }
    }
    line += &format!(
        "; sensors: {}{}",
        sensors.name(),
        if sensors.gnss { " + GNSS" } else { "" }
    );
    errln!("{line}");
}
