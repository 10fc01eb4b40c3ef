//! Sample types: one timestamped reading per struct, in SI units, body axes x forward,
//! y right, z down.

use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// A two-axis magnetometer reading (any unit; calibration removes it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mag2Sample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// (mag_x, mag_y) in the sensor's unit. Level and heading ψ, ideal: (H cos ψ, −H sin ψ).
    pub mag: Vector2<f64>,
}

/// A three-axis magnetometer reading (any unit).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mag3Sample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// (mag_x, mag_y, mag_z) in the sensor's unit.
    pub mag: Vector3<f64>,
}

/// A three-axis rate-gyro reading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GyroSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Angular rate about x, y, z, rad/s. `gyr.z > 0` is a right turn.
    pub gyr_rps: Vector3<f64>,
}

/// A three-axis accelerometer reading (specific force).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AccelSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Specific force, m/s². At rest and level it reads (0, 0, −g) with z down.
    pub acc_mps2: Vector3<f64>,
}

/// One IMU sample: gyro and accelerometer, optionally a magnetometer.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ImuSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Angular rate, rad/s.
    pub gyr_rps: Vector3<f64>,
    /// Specific force, m/s².
    pub acc_mps2: Vector3<f64>,
    /// Magnetic field (any unit), if a magnetometer is present.
    pub mag: Option<Vector3<f64>>,
}

/// Cumulative distances of the left and right odometer wheels, as the odometer reports them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WheelSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Cumulative distance of the left wheel, metres.
    pub dist_l_m: f64,
    /// Cumulative distance of the right wheel, metres.
    pub dist_r_m: f64,
}

/// Everything a land vehicle's navigation sensors report at one instant (the `drive` CSV row).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VehicleSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Cumulative distance of the left odometer wheel, metres.
    pub dist_l_m: f64,
    /// Cumulative distance of the right odometer wheel, metres.
    pub dist_r_m: f64,
    /// Raw yaw rate (with the gyro's own bias and scale error), rad/s, if a gyro is fitted.
    pub gyr_z_rps: Option<f64>,
    /// Raw, uncalibrated horizontal magnetometer reading, if a compass is fitted.
    pub mag: Option<Vector2<f64>>,
}
