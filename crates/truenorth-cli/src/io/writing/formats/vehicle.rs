//! The vehicle file of `truenorth drive`: the odometer wheels' geometry (the layout is in
//! the command's `--help`).

use std::path::Path;

use serde::Deserialize;
use truenorth::odometer::{AckermannParams, OdometerWheels};

use super::json::{parse_json, parse_value, read_json_text, version_of};
use crate::io::{CliError, CliResult};

/// The layout version of the vehicle file this build writes in its examples: the keys
/// below. A file without `version` is read as this one (the layout has not changed since
/// before files carried a version, and vehicle files are written by hand).
pub const VEHICLE_VERSION: u32 = 1;

/// The track a vehicle can have, m: from a small robot's 5 cm to a mining truck's 8 m,
/// with room to spare.
const TRACK_RANGE_M: (f64, f64) = (0.05, 10.0);
/// The wheelbase a vehicle can have, m.
const WHEELBASE_RANGE_M: (f64, f64) = (0.1, 20.0);
/// The distance per odometer pulse, m: up to one revolution of a large wheel.
const RESOLUTION_RANGE_M: (f64, f64) = (1e-6, 5.0);

/// Quanta a wheel speed is sent in, m/s: from a robot's µm/s to a coarse bus's 1 km/h.
const SPEED_QUANTUM_RANGE_MPS: (f64, f64) = (1e-6, 1.0);
/// How far a GNSS antenna can be from the axle's centre, m, along either axis.
const LEVER_ARM_RANGE_M: (f64, f64) = (-50.0, 50.0);
/// A fix's delay a logger can add, s: the estimator's own range for it.
const LATENCY_RANGE_S: (f64, f64) = (0.0, 10.0);
/// The compass's systematic heading error, degrees: the estimator's own range.
const SYSTEMATIC_RANGE_DEG: (f64, f64) = (1e-3, 45.0);

/// The vehicle file, as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleFile {
    /// Layout version, `VEHICLE_VERSION` (optional: a file without one reads as it).
    #[serde(default)]
    pub version: Option<u32>,
    /// Track of the odometer wheels, m.
    pub track_m: f64,
    /// "rear", "front", "skid_steer" or "differential".
    pub odometer_wheels: String,
    /// Rear axle to front kingpins, m (front wheels).
    pub wheelbase_m: Option<f64>,
    /// Kingpin offset over half the front track (front wheels).
    pub pitman_ratio: Option<f64>,
    /// Distance per odometer pulse, m.
    pub wheel_resolution_m: Option<f64>,
    /// The quantum wheel speeds are sent in, m/s (optional; used with speed columns).
    pub wheel_speed_quantum_mps: Option<f64>,
    /// The compass's systematic heading error, degrees (optional; the estimator's default,
    /// 3°, is a level two-axis compass on roads that tilt it by their grade and camber; a
    /// tilt-compensated compass, or one on level ground, leaves about 0.3°).
    pub compass_systematic_deg: Option<f64>,
    /// Where the GNSS antenna is from the axle's centre, m forward and to the right
    /// (optional; [0, 0]).
    pub gnss_lever_arm_m: Option<[f64; 2]>,
    /// How long after its epoch a fix is stamped, s (optional; 0.1: a receiver's and a
    /// logger's delay). `drive` says when the fixes' course shows another.
    pub gnss_latency_s: Option<f64>,
}

impl VehicleFile {
    /// Reads, parses and checks the file: a byte-order mark is skipped, a newer layout
    /// version or an unknown key (named with the closest known one) is refused, and so is
    /// a value no vehicle has ([`VehicleFile::check`]).
    pub fn read(path: &Path) -> CliResult<Self> {
        let (text, name) = read_json_text(path)?;
        let what = "not a vehicle file";
        let value = parse_value(&text, what).map_err(|m| CliError::file(&name, m))?;
        version_of(&value, &[VEHICLE_VERSION], "vehicle file")
            .map_err(|m| CliError::file(&name, m))?;
        let file: Self = parse_json(value, what).map_err(|m| CliError::file(&name, m))?;
        file.check().map_err(|m| CliError::file(&name, m))?;
        Ok(file)
    }

    /// What in the file no vehicle has: a track, wheelbase, pitman ratio or wheel
    /// resolution that is not finite or outside its physical range.
    pub fn check(&self) -> Result<(), String> {
        let within = |key: &str, v: f64, (lo, hi): (f64, f64), unit: &str| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(format!(
                    "`{key}` is {v}{unit}, outside {lo}–{hi}{unit} (what a wheeled vehicle can have); check the value and its unit ({})",
                    if unit == " m/s" {
                        "metres per second"
                    } else {
                        "metres"
                    }
                ))
            }
        };
        if let Some(v) = self.version.filter(|v| *v != VEHICLE_VERSION) {
            return Err(format!(
                "vehicle file layout version {v} is not one this build reads (version {VEHICLE_VERSION})"
            ));
        }
        within("track_m", self.track_m, TRACK_RANGE_M, " m")?;
        if let Some(b) = self.wheelbase_m {
            within("wheelbase_m", b, WHEELBASE_RANGE_M, " m")?;
        }
        if let Some(p) = self.pitman_ratio
            && !(p.is_finite() && (0.0..1.0).contains(&p))
        {
            return Err(format!(
                "`pitman_ratio` is {p}, must be in [0, 1) (the kingpin offset over half the front track)"
            ));
        }
        if let Some(r) = self.wheel_resolution_m {
            within("wheel_resolution_m", r, RESOLUTION_RANGE_M, " m")?;
        }
        if let Some(q) = self.wheel_speed_quantum_mps {
            within(
                "wheel_speed_quantum_mps",
                q,
                SPEED_QUANTUM_RANGE_MPS,
                " m/s",
            )?;
        }
        for l in self.gnss_lever_arm_m.into_iter().flatten() {
            within("gnss_lever_arm_m", l, LEVER_ARM_RANGE_M, " m")?;
        }
        if let Some(l) = self.gnss_latency_s
            && !(l.is_finite() && (LATENCY_RANGE_S.0..=LATENCY_RANGE_S.1).contains(&l))
        {
            return Err(format!(
                "`gnss_latency_s` is {l}, outside {}–{} s (how long after its epoch a fix is stamped; a fix cannot be stamped before it); check the value and its unit (seconds)",
                LATENCY_RANGE_S.0, LATENCY_RANGE_S.1
            ));
        }
        if let Some(s) = self.compass_systematic_deg
            && !(s.is_finite() && (SYSTEMATIC_RANGE_DEG.0..=SYSTEMATIC_RANGE_DEG.1).contains(&s))
        {
            return Err(format!(
                "`compass_systematic_deg` is {s}, outside {}–{}° (a heading error a compass can leave); check the value and its unit (degrees)",
                SYSTEMATIC_RANGE_DEG.0, SYSTEMATIC_RANGE_DEG.1
            ));
        }
        Ok(())
    }

    /// The odometer wheels the file describes; `path` names the file in errors.
    pub fn wheels(&self, path: &Path) -> CliResult<OdometerWheels> {
        match self.odometer_wheels.to_ascii_lowercase().as_str() {
            "rear" => Ok(OdometerWheels::Rear {
                track_m: self.track_m,
            }),
            "front" => {
                let (Some(b), Some(p)) = (self.wheelbase_m, self.pitman_ratio) else {
                    return Err(CliError::file(
                        path,
                        "front odometer wheels need wheelbase_m and pitman_ratio (Ackermann geometry)",
                    ));
                };
                Ok(OdometerWheels::Front(AckermannParams::from_pitman_ratio(
                    b,
                    self.track_m,
                    p,
                )))
            }
            "skid_steer" | "skid-steer" => Ok(OdometerWheels::SkidSteer {
                track_m: self.track_m,
            }),
            "differential" => Ok(OdometerWheels::Differential {
                track_m: self.track_m,
            }),
            other => Err(CliError::file(
                path,
                format!(
                    "odometer_wheels is `{other}`; it must be \"rear\", \"front\", \"skid_steer\" or \"differential\""
                ),
            )),
        }
    }
}
