//! The computation that the Cortex-M4F binary and its host twin (`tests/embedded_twin.rs` in
//! the main workspace) both run, from this one file: the quaternion filter over a slice of a
//! real BROAD recording compiled into the binary, then a tilt-compensated compass heading
//! with a stored calibration ([`run`]), and the online ellipse calibrator learning a
//! two-axis compass from a simulated turn, then a heading through what it learned
//! ([`calibrate`]), all in the float type the caller names. Every result goes out as text
//! through [`core::fmt::Write`], so the two outputs can be compared line by line.
//!
//! Nothing here allocates, reads a clock or knows where it runs; the only hook is
//! [`UpdateMeter`], which the target uses to count the instructions of each filter update
//! and each calibrator push.

use core::fmt::{self, Write};

use nalgebra::{Matrix2, Matrix3, Quaternion, UnitQuaternion, Vector2, Vector3};
use truenorth_calib::{OnlineEllipseCalibrator, OnlineEllipseConfig};
use truenorth_compass::CompassCalibration3d;
use truenorth_core::{AttitudeStatus, Calibrator, EulerZyx, Real, ned_to_enu};
use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig};

/// The recording, as written by `tests/embedded_twin.rs` (`embedded_data_is_the_broad_slice`):
/// little-endian `f32`s, first [`HEADER_VALUES`] of header, then [`SAMPLE_VALUES`] per
/// sample. Header: the first sample's index in the trial, the compass calibration's hard iron
/// (µT, 3) and soft iron (9, row-major), and the motion-capture reference attitude at the
/// last sample (sensor → ENU with magnetic north, `w, x, y, z`). Sample: gyro (rad/s, 3),
/// accelerometer (m/s², 3), magnetometer (µT, 3), in the sensor's axes.
static RECORDING: &[u8] = include_bytes!("../data/broad_01_slice.bin");

/// Values in the recording's header.
pub const HEADER_VALUES: usize = 17;
/// Values per sample in the recording.
pub const SAMPLE_VALUES: usize = 9;
/// BROAD's sample interval, seconds (285.714 Hz = 2000/7 Hz).
pub const SAMPLE_INTERVAL_S: f64 = 0.0035;
/// Every how many samples the attitude is printed.
const PRINT_EVERY: usize = 100;

/// Counts what one filter update (or calibrator push) costs; the host twin's meter does
/// nothing.
pub trait UpdateMeter {
    /// Runs `update` and accounts for it.
    fn measure<T>(&mut self, update: impl FnOnce() -> T) -> T;

    /// Says whether the last measured call was the steady path (`true`): a filter update
    /// after the start-up (whose gains are the start-up's own), a calibrator push that ran
    /// the per-sample path alone (no stage of its refresh).
    fn classify_last(&mut self, _steady: bool) {}
}

/// Readings of the simulated turn fed to the online ellipse calibrator: one per degree.
pub const TURN_READINGS: usize = 360;
/// The simulated two-axis compass: hard iron (µT), soft-iron distortion `W` (row-major,
/// symmetric: the raw locus is `hard + W·h`), horizontal field (µT).
pub const TURN_HARD_IRON_UT: [f64; 2] = [12.0, -5.0];
const TURN_W: [f64; 4] = [1.15, 0.08, 0.08, 0.9];
/// The horizontal field of the simulated compass, µT.
pub const TURN_FIELD_UT: f64 = 20.0;
/// Amplitude (µT) of a second-harmonic wobble added to the readings, so the fit has a
/// residual: 0.2 % of the field.
const TURN_WOBBLE_UT: f64 = 0.04;
/// cos 1° and sin 1°: the turn advances by a rotation, with + − × only, so the readings have
/// the same bits on the target and on the host.
const COS_1_DEG: f64 = 0.999_847_695_156_391_3;
const SIN_1_DEG: f64 = 0.017_452_406_437_283_51;
/// The heading, degrees, of the reading whose heading is printed after the calibration.
pub const TURN_CHECK_HEADING_DEG: usize = 40;

/// Why the run stopped early.
#[derive(Debug)]
pub enum RunError {
    /// The recording's length is not a header plus whole samples.
    Recording,
    /// The filter or the calibrator refused a sample, or the calibrator a solve.
    Filter(truenorth_core::Error),
    /// The output could not be written.
    Output(fmt::Error),
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Recording => f.write_str("the recording is not a header plus whole samples"),
            Self::Filter(e) => write!(f, "the filter or the calibrator refused: {e}"),
            Self::Output(_) => f.write_str("the output could not be written"),
        }
    }
}

impl From<fmt::Error> for RunError {
    fn from(e: fmt::Error) -> Self {
        Self::Output(e)
    }
}

impl From<truenorth_core::Error> for RunError {
    fn from(e: truenorth_core::Error) -> Self {
        Self::Filter(e)
    }
}

/// Value `i` of the recording (header and samples counted together).
fn value(i: usize) -> Option<f32> {
    let b = RECORDING.get(4 * i..4 * i + 4)?;
    Some(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// `N` consecutive values from `first`, in the float type `R` (exact: they are `f32`s).
fn values<R: Real, const N: usize>(first: usize) -> Option<[R; N]> {
    let mut out = [R::zero(); N];
    for (k, v) in out.iter_mut().enumerate() {
        *v = R::of(f64::from(value(first + k)?));
    }
    Some(out)
}

/// The recording's compass calibration (stored in the header).
fn calibration() -> Option<CompassCalibration3d> {
    let h: [f64; 3] = values(1)?;
    let s: [f64; 9] = values(4)?;
    Some(CompassCalibration3d {
        hard_iron: Vector3::from(h),
        soft_iron: Matrix3::from_row_slice(&s),
    })
}

/// The reference attitude at the last sample, body → NED.
fn reference_ned() -> Option<UnitQuaternion<f64>> {
    let [w, x, y, z]: [f64; 4] = values(13)?;
    let enu = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
    Some(ned_to_enu().inverse() * enu)
}

/// One sample in the float type `R`: its timestamp and time since the first sample (s,
/// `f64` in both precisions, as the filter takes them), gyro (rad/s), accelerometer (m/s²),
/// magnetometer (µT), sensor axes.
pub struct Readings<R: Real> {
    pub t_s: f64,
    pub since_first_s: f64,
    pub gyr_rps: Vector3<R>,
    pub acc_mps2: Vector3<R>,
    pub mag_ut: Vector3<R>,
}

/// Sample `k` of the slice, whose first sample is sample `first_index` of the trial.
fn readings<R: Real>(k: usize, first_index: f64) -> Option<Readings<R>> {
    let v: [R; SAMPLE_VALUES] = values(HEADER_VALUES + SAMPLE_VALUES * k)?;
    Some(Readings {
        t_s: (first_index + k as f64) * SAMPLE_INTERVAL_S,
        since_first_s: k as f64 * SAMPLE_INTERVAL_S,
        gyr_rps: Vector3::new(v[0], v[1], v[2]),
        acc_mps2: Vector3::new(v[3], v[4], v[5]),
        mag_ut: Vector3::new(v[6], v[7], v[8]),
    })
}

/// Degrees of an angle in radians (of either float type), in `f64`.
fn deg<R: Real>(rad: R) -> f64 {
    rad.to_f64().to_degrees()
}

/// An attitude in `f64`, component by component (exact: no renormalisation, so the `f64`
/// run's attitude keeps its bits).
fn to_f64<R: Real>(q: &UnitQuaternion<R>) -> UnitQuaternion<f64> {
    UnitQuaternion::new_unchecked(Quaternion::new(
        q.w.to_f64(),
        q.i.to_f64(),
        q.j.to_f64(),
        q.k.to_f64(),
    ))
}

/// The number of samples in the recording and the index in the trial of the first.
fn layout() -> Result<(usize, f64), RunError> {
    let body = RECORDING
        .len()
        .checked_sub(4 * HEADER_VALUES)
        .ok_or(RunError::Recording)?;
    if !body.is_multiple_of(4 * SAMPLE_VALUES) || !RECORDING.len().is_multiple_of(4) {
        return Err(RunError::Recording);
    }
    let first_index = f64::from(value(0).ok_or(RunError::Recording)?);
    Ok((body / (4 * SAMPLE_VALUES), first_index))
}

/// The recording's samples in the float type `R`, in order.
pub fn samples<R: Real>() -> Result<impl Iterator<Item = Readings<R>>, RunError> {
    let (n, first_index) = layout()?;
    // Every sample is there: `layout` checked the length.
    Ok((0..n).filter_map(move |k| readings(k, first_index)))
}

/// One update of `filter` by the sample `s`, as an application makes it: a call, on a filter
/// the compiler knows nothing about (as one kept in a static, behind an interrupt), so that
/// it can neither hoist the update's work on the parameters out of the caller's loop nor
/// drop what the loop does not read, and the count is the update's however the caller is
/// compiled.
#[inline(never)]
pub fn update<R: Real>(
    filter: &mut QuaternionFilter<R>,
    s: &Readings<R>,
) -> Result<AttitudeStatus, truenorth_core::Error> {
    core::hint::black_box(filter).update_readings(
        s.t_s,
        s.gyr_rps,
        Some(s.acc_mps2),
        Some(s.mag_ut),
    )
}

/// Runs the filter in the float type `R` (`f32` or `f64`) over the recording, then the
/// compass, also in `R`, on its last reading, writing one `name value...` line per result
/// (numbers in Rust's shortest round-trip form for `R`, so equal text means equal bits).
/// The first line names the float: `float f32: ...`; `.ci/embedded` takes the tolerance of
/// the lines that follow from it.
pub fn run<R: Real>(out: &mut impl Write, meter: &mut impl UpdateMeter) -> Result<(), RunError> {
    let (n, first_index) = layout()?;
    let cal = calibration()
        .ok_or(RunError::Recording)?
        .to_precision::<R>();
    let reference = reference_ned().ok_or(RunError::Recording)?;
    let float = core::any::type_name::<R>();
    writeln!(
        out,
        "float {float}: the filter and the compass heading in {float}, recording BROAD trial 01 \
         samples {first_index}..{} ({n} at 2000/7 Hz)",
        first_index + n as f64,
    )?;

    let config = QuaternionFilterConfig::default();
    let mut filter = QuaternionFilter::<R>::with_precision(config)?;
    let mut last_mag = Vector3::zeros();
    for (k, s) in samples::<R>()?.enumerate() {
        meter.measure(|| update(&mut filter, &s))?;
        meter.classify_last(s.since_first_s >= config.startup_s);
        last_mag = s.mag_ut;
        if (k + 1).is_multiple_of(PRINT_EVERY) {
            let q = filter.attitude();
            writeln!(out, "q[{}] {} {} {} {}", k + 1, q.w, q.i, q.j, q.k)?;
        }
    }

    let q = filter.attitude();
    writeln!(out, "final_q {} {} {} {}", q.w, q.i, q.j, q.k)?;
    let b = filter.gyro_bias_rps();
    writeln!(
        out,
        "gyro_bias_deg_s {} {} {}",
        deg(b.x),
        deg(b.y),
        deg(b.z)
    )?;
    // The Euler angles in f64 (the library's `EulerZyx` and `Tilt` are f64; done once, not
    // per sample); the compass heading in `R`.
    let euler = EulerZyx::from_quaternion(&to_f64(&q));
    writeln!(
        out,
        "filter_yaw_pitch_roll_deg {} {} {}",
        deg(euler.yaw_rad),
        deg(euler.pitch_rad),
        deg(euler.roll_rad)
    )?;
    let compass = cal.heading_rad(&last_mag, &euler.tilt());
    writeln!(out, "compass_heading_deg {}", deg(compass))?;
    let reference_yaw = EulerZyx::from_quaternion(&reference).yaw_rad;
    writeln!(out, "reference_yaw_deg {}", deg(reference_yaw))?;
    Ok(())
}

/// The readings of the simulated turn, in `f64`: heading `k`° for reading `k`, raw
/// `hard + W·F(cos ψ, −sin ψ)` plus the wobble.
fn turn_readings() -> [Vector2<f64>; TURN_READINGS] {
    let hard = Vector2::from(TURN_HARD_IRON_UT);
    let w = Matrix2::from_row_slice(&TURN_W);
    let (mut c, mut s) = (1.0, 0.0);
    let mut out = [Vector2::zeros(); TURN_READINGS];
    for p in out.iter_mut() {
        let wobble = Vector2::new(2.0 * c * s, c * c - s * s) * TURN_WOBBLE_UT;
        *p = hard + w * Vector2::new(c, -s) * TURN_FIELD_UT + wobble;
        (c, s) = (c * COS_1_DEG - s * SIN_1_DEG, s * COS_1_DEG + c * SIN_1_DEG);
    }
    out
}

/// The online ellipse calibrator in the float type `R` fed the simulated turn, readings in
/// `R` (its per-sample path runs in `R`; its solve in `f64`, returning the calibration in
/// `R`), then the calibration and the heading of one reading through it, one line each. Each
/// push goes through `meter`, classified as the per-sample path alone or a push that also ran
/// a refresh stage.
pub fn calibrate<R: Real>(
    out: &mut impl Write,
    meter: &mut impl UpdateMeter,
) -> Result<(), RunError> {
    let mut cal = OnlineEllipseCalibrator::<R>::with_precision(OnlineEllipseConfig::default())?;
    let readings = turn_readings();
    for (k, p) in readings.iter().enumerate() {
        let mag = p.map(R::of);
        let idle = cal.refresh_stage().is_none();
        meter.measure(|| cal.push_reading(k as f64, &mag))?;
        meter.classify_last(idle && cal.refresh_stage().is_none());
    }
    let sol = cal.solve()?;
    let (h, s) = (sol.params.hard_iron, sol.params.soft_iron);
    writeln!(out, "ellipse_readings {TURN_READINGS}")?;
    writeln!(out, "ellipse_hard_iron_ut {} {}", h.x, h.y)?;
    writeln!(
        out,
        "ellipse_soft_iron {} {} {} {}",
        s[(0, 0)],
        s[(0, 1)],
        s[(1, 0)],
        s[(1, 1)]
    )?;
    writeln!(out, "ellipse_field_ut {}", sol.quality.field_magnitude)?;
    let check = readings[TURN_CHECK_HEADING_DEG].map(R::of);
    writeln!(
        out,
        "ellipse_heading_deg {} {}",
        deg(sol.params.heading_rad(&check)),
        TURN_CHECK_HEADING_DEG
    )?;
    Ok(())
}
