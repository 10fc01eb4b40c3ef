//! The odometer wheels of a drive log, and its yaw gyro against them: the wheels' distance
//! difference per radian the gyro integrates is the track if the gyro is in rad/s and its
//! sign right (the shared check `drive` refuses by, with a track of one metre).

use serde::Serialize;
use truenorth::checks::{GyroUnit, SignedPermutation, YawRateCheck};
use truenorth::core::VehicleSample;

use super::Recording;
use crate::io::InputOptions;
use crate::io::checking::fix_pair;
use crate::io::reading::wheels::WheelColumns;

/// The odometer wheels.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WheelReport {
    /// `distances` (`dist_l_m,dist_r_m`) or `speeds` (`speed_l_mps,speed_r_mps`).
    pub columns: &'static str,
    /// The fastest wheel speed (speeds), or the mean speed over the recording (distances),
    /// in the file's numbers per second.
    pub speed: Option<f64>,
    /// Whether that speed is plausible in m/s (under 70 m/s, 250 km/h); a larger one is
    /// likely km/h, which the commands do not read.
    pub plausible_in_mps: Option<bool>,
}

/// The wheels' report, if the recording has them (distances before speeds, as `drive`
/// reads them).
pub fn wheels(rec: &Recording) -> Option<WheelReport> {
    let finite = |v: &[f64]| {
        v.iter()
            .copied()
            .filter(|x| x.is_finite())
            .collect::<Vec<_>>()
    };
    let (columns, speed) = match (rec.col("dist_l_m"), rec.col("dist_r_m")) {
        (Some(l), Some(r)) => {
            let (l, r) = (finite(l), finite(r));
            let t = finite(&rec.t_s);
            let span = t
                .last()
                .zip(t.first())
                .map(|(b, a)| b - a)
                .filter(|d| *d > 0.0);
            let travelled = |v: &[f64]| v.last().zip(v.first()).map(|(b, a)| (b - a).abs());
            let mean = travelled(&l)
                .zip(travelled(&r))
                .zip(span)
                .map(|((a, b), s)| 0.5 * (a + b) / s);
            ("distances", mean)
        }
        _ => {
            let (l, r) = (rec.col("speed_l_mps")?, rec.col("speed_r_mps")?);
            let fastest = finite(l)
                .into_iter()
                .chain(finite(r))
                .map(f64::abs)
                .reduce(f64::max);
            ("speeds", fastest)
        }
    };
    Some(WheelReport {
        columns,
        speed,
        plausible_in_mps: speed.map(|v| v < 70.0),
    })
}

/// The yaw gyro against the wheels (a drive log: `gyr_z` and wheel columns).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct YawReport {
    /// The wheels' distance difference per radian the gyro integrates, over the turning
    /// seconds (least squares): the track, m, if the gyro is in rad/s and its sign right
    /// (0.3–3 m for robots and cars; a deg/s gyro gives 57 times less, a flipped one a
    /// negative track).
    pub implied_track_m: Option<f64>,
    /// The squared correlation of the two turns.
    pub r2: Option<f64>,
    /// One-second windows in which the wheels turned enough to compare.
    pub windows: usize,
    /// `rad/s` or `deg/s` when the implied track says so.
    pub likely_unit: Option<&'static str>,
    /// Whether the gyro turns against the wheels (its sign flipped), when judged.
    pub flipped: Option<bool>,
    /// The `--column` value (unquoted) that flips it back, when it is flipped.
    pub fix: Option<String>,
}

/// The yaw gyro's report, if the recording has `gyr_z` and wheels.
pub fn yaw(rec: &Recording, opts: &InputOptions) -> Option<YawReport> {
    let gyr = rec.col("gyr_z")?;
    let (mut wheels, l, r) = match (rec.col("dist_l_m"), rec.col("dist_r_m")) {
        (Some(l), Some(r)) => (WheelColumns::Distances([0, 1]), l, r),
        _ => (
            WheelColumns::Speeds {
                columns: [0, 1],
                last: None,
                dist: [0.0; 2],
            },
            rec.col("speed_l_mps")?,
            rec.col("speed_r_mps")?,
        ),
    };
    // With a track of 1 m the ratio the check learns is the track the data imply.
    let mut check = YawRateCheck::new(1.0);
    for k in 0..rec.t_s.len() {
        let t = rec.t_s[k];
        let mut sample = VehicleSample::at(t);
        if let Ok(Some([dl, dr])) = wheels.cumulative(t, &[l[k], r[k]]) {
            sample = sample.with_wheels(dl, dr);
        }
        if gyr[k].is_finite() {
            sample = sample.with_gyro(gyr[k]);
        }
        check.push(&sample);
    }
    let fit = check.ratio();
    let track = fit.map(|f| f.0.abs());
    let plausible = |m: f64| (0.1..=10.0).contains(&m);
    Some(YawReport {
        implied_track_m: fit.map(|f| f.0),
        r2: fit.map(|f| f.1),
        windows: check.windows,
        likely_unit: track.and_then(|m| {
            if plausible(m) {
                Some("rad/s")
            } else if plausible(m / GyroUnit::DegPerS.to_rad_per_s()) {
                Some("deg/s")
            } else {
                None
            }
        }),
        flipped: fit.map(|f| f.0 < 0.0),
        fix: fit.filter(|f| f.0 < 0.0).map(|_| {
            let flip_z = SignedPermutation {
                source: [0, 1, 2],
                sign: [1, 1, -1],
            };
            fix_pair(&flip_z, 2, opts)
        }),
    })
}

/// A drive log's sensor set, as `drive` names it, and what that set cannot tell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VehicleSetReport {
    /// The set's name (`truenorth::core::VehicleSensors::name`).
    pub set: String,
    /// What the set cannot tell, one sentence each.
    pub cannot_tell: Vec<String>,
}

/// The sensor set of a drive log — wheels (two distances or speeds, or a car's four
/// speeds), one distance or speed, a yaw gyro, a two-axis compass — judged from the columns present; `None` for a file with
/// a three-axis gyro or an accelerometer (an IMU recording, not a drive log) or none of them.
pub fn vehicle_sensors(rec: &Recording) -> Option<VehicleSetReport> {
    use truenorth::core::{Travel, VehicleSensors};
    let has = |n: &str| rec.col(n).is_some();
    if has("gyr_x") || has("gyr_y") || has("acc_x") || has("acc_z") || has("mag_z") {
        return None;
    }
    let four = [
        "speed_fl_mps",
        "speed_fr_mps",
        "speed_rl_mps",
        "speed_rr_mps",
    ];
    let wheels = (has("dist_l_m") && has("dist_r_m"))
        || (has("speed_l_mps") && has("speed_r_mps"))
        || four.iter().all(|n| has(n));
    let travel = if wheels {
        Travel::Wheels
    } else if has("dist_m") || has("speed_mps") {
        Travel::Speed
    } else {
        Travel::None
    };
    let set = VehicleSensors {
        travel,
        gyro: has("gyr_z"),
        compass: has("mag_x") && has("mag_y"),
        gnss: has("lat_deg") && has("lon_deg"),
        gnss_course: has("lat_deg") && has("gnss_speed_mps") && has("gnss_course_deg"),
    };
    if set == VehicleSensors::default() {
        return None;
    }
    Some(VehicleSetReport {
        set: format!("{}{}", set.name(), if set.gnss { " + GNSS" } else { "" }),
        cannot_tell: set.limits().map(String::from).collect(),
    })
}
