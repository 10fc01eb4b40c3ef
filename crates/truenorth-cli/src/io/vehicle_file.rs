//! The vehicle file of `truenorth drive`: the odometer wheels' geometry (the layout is in
//! the command's `--help`).

use std::path::Path;

use serde::Deserialize;
use truenorth::odometer::{AckermannParams, OdometerWheels};

use super::{CliError, CliResult};

/// The vehicle file, as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleFile {
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
}

impl VehicleFile {
    /// Reads and parses the file; an unknown key is refused.
    pub fn read(path: &Path) -> CliResult<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| CliError::file(path, format!("cannot read: {e}")))?;
        serde_json::from_str(&text)
            .map_err(|e| CliError::file(path, format!("not a vehicle file: {e}")))
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
