//! The sensors' error model behind the [`crate::QuaternionFilter`]'s σ
//! ([`AttitudeUncertaintyConfig`]): its parameters apart from the propagation that uses them
//! (the `attitude_uncertainty` module), as the filter's own configuration keeps them.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_range};

/// The sensors' error model behind the filter's σ: what a typical consumer MEMS IMU with a
/// calibrated magnetometer promises. Units in the names; every value is one standard
/// deviation.
///
/// Outside the model, and so outside σ (see [the model](crate::attitude_uncertainty)): a
/// horizontal acceleration that lasts longer than the inclination loop (a vehicle's turn,
/// a hand carried along at more than about 0.5 m/s² below 0.1 Hz), which no accelerometer
/// can tell from a tilt; a gyro whose scale differs between the two senses of rotation,
/// which turns part of its scale error into a drift like a bias; a field disturbance
/// present since the start, which becomes the reference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AttitudeUncertaintyConfig {
    /// Gyro white-noise density (angle random walk), rad/s/√Hz (default 0.01°/s/√Hz:
    /// InvenSense MPU-9250 0.01, Bosch BMI160 0.007, TDK ICM-20948 0.015).
    pub gyro_noise_rps_per_sqrt_hz: f64,
    /// Gyro bias before a rest has measured it, rad/s (default 0.5°/s: a consumer gyro's
    /// zero-rate offset after a board-level calibration; datasheets give ±3–5°/s before).
    pub gyro_bias_rps: f64,
    /// Gyro bias random walk (its drift with time and temperature), rad/s/√s (default
    /// 0.002°/s/√s: 0.03°/s over 4 minutes).
    pub gyro_bias_walk_rps_per_sqrt_s: f64,
    /// Gyro scale-factor and axis-misalignment error, relative (default 0.01: the ±3 %
    /// sensitivity tolerance of consumer datasheets taken as 3σ).
    pub gyro_scale_rel: f64,
    /// Uncertainty of the gyro's latency against the other sensors and the timestamps, s
    /// (default 0.003: the group delay of a consumer gyro's default digital low-pass).
    pub gyro_latency_s: f64,
    /// Accelerometer white-noise density, m/s²/√Hz (default 0.003: MPU-9250 300 µg/√Hz).
    pub accel_noise_mps2_per_sqrt_hz: f64,
    /// Accelerometer bias after calibration, m/s² (default 0.05, about 5 mg: 0.3° of tilt).
    pub accel_bias_mps2: f64,
    /// Magnetometer noise per component and reading, relative to the field's norm
    /// (default 0.01).
    pub mag_noise_rel: f64,
    /// Heading error the magnetometer's calibration leaves, rad (default 1°).
    pub mag_heading_rad: f64,
}

impl Default for AttitudeUncertaintyConfig {
    fn default() -> Self {
        Self {
            gyro_noise_rps_per_sqrt_hz: 0.01f64.to_radians(),
            gyro_bias_rps: 0.5f64.to_radians(),
            gyro_bias_walk_rps_per_sqrt_s: 0.002f64.to_radians(),
            gyro_scale_rel: 0.01,
            gyro_latency_s: 0.003,
            accel_noise_mps2_per_sqrt_hz: 0.003,
            accel_bias_mps2: 0.05,
            mag_noise_rel: 0.01,
            mag_heading_rad: 1f64.to_radians(),
        }
    }
}

impl Validate for AttitudeUncertaintyConfig {
    /// Every value finite and ≥ 0, and below a bound no real sensor reaches (rates 10 rad/s,
    /// relative errors 1, latency 1 s, accelerometer terms 100 m/s², heading π).
    fn validate(&self) -> Result<()> {
        let bounds = [
            (
                "uncertainty.gyro_noise_rps_per_sqrt_hz",
                self.gyro_noise_rps_per_sqrt_hz,
                10.0,
            ),
            ("uncertainty.gyro_bias_rps", self.gyro_bias_rps, 10.0),
            (
                "uncertainty.gyro_bias_walk_rps_per_sqrt_s",
                self.gyro_bias_walk_rps_per_sqrt_s,
                10.0,
            ),
            ("uncertainty.gyro_scale_rel", self.gyro_scale_rel, 1.0),
            ("uncertainty.gyro_latency_s", self.gyro_latency_s, 1.0),
            (
                "uncertainty.accel_noise_mps2_per_sqrt_hz",
                self.accel_noise_mps2_per_sqrt_hz,
                100.0,
            ),
            ("uncertainty.accel_bias_mps2", self.accel_bias_mps2, 100.0),
            ("uncertainty.mag_noise_rel", self.mag_noise_rel, 1.0),
            (
                "uncertainty.mag_heading_rad",
                self.mag_heading_rad,
                core::f64::consts::PI,
            ),
        ];
        for (what, value, max) in bounds {
            check_range(what, value, 0.0, max)?;
        }
        Ok(())
    }
}
