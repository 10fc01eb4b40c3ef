//! The configuration of the [`crate::VehicleEstimator`]: the vehicle, the method, what the
//! sensors are believed to do before anything is learned, and the compass gates. Angles in
//! the serde form are degrees (they are edited by hand in files); everything else SI.

use serde::{Deserialize, Serialize};
use truenorth_calib::OnlineEllipseConfig;
use truenorth_core::{Result, Validate, check_positive, check_range};
use truenorth_odometer::OdometerWheels;

/// What the sensors are believed to do before anything is learned (the filter's prior and
/// process noise). Defaults suit automotive MEMS gyros and ABS wheel sensors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SensorPriors {
    /// Gyro white noise (angle random walk), °/s/√Hz (0.03).
    pub gyro_noise_dps_per_sqrt_hz: f64,
    /// Gyro bias random walk, °/s/√s (0.005): how fast the bias may wander with temperature.
    pub gyro_bias_walk_dps_per_sqrt_s: f64,
    /// Standard deviation of the gyro bias before it is measured, °/s (1).
    pub gyro_bias_sigma_dps: f64,
    /// Standard deviation of each gyro gain error before it is learned (0.05).
    pub gyro_gain_sigma: f64,
    /// Standard deviation of the differential wheel scale δ before it is learned (0.01).
    pub wheel_diff_sigma: f64,
    /// Standard deviation of the odometer's mean scale, which no sensor here observes; it
    /// makes the reported along-track uncertainty (0.003).
    pub wheel_scale_sigma: f64,
    /// Standard deviation of the relative error of the wheels' effective track before it is
    /// learned (0.02): the contact patches' spacing differs from the nominal track, and the
    /// mean scale error scales the wheels' heading too.
    pub wheel_track_sigma: f64,
    /// Initial speed coefficient `a`, s²/m² (0).
    pub speed_coeff_s2_per_m2: f64,
    /// Standard deviation of `a` before it is learned, s²/m² (1e-4).
    pub speed_coeff_sigma: f64,
    /// Heading noise of the wheels per square-root metre travelled, °/√m (0.01): slip,
    /// bumps and tyre deflection.
    pub wheel_heading_noise_deg_per_sqrt_m: f64,
    /// Resolution of the wheel distances, m (0.02: ABS pulses; a few mm for integrated CAN
    /// wheel speeds). Sets the noise of the wheels' heading against the gyro's.
    pub wheel_resolution_m: f64,
}

impl Default for SensorPriors {
    fn default() -> Self {
        Self {
            gyro_noise_dps_per_sqrt_hz: 0.03,
            gyro_bias_walk_dps_per_sqrt_s: 0.005,
            gyro_bias_sigma_dps: 1.0,
            gyro_gain_sigma: 0.05,
            wheel_diff_sigma: 0.01,
            wheel_scale_sigma: 0.003,
            wheel_track_sigma: 0.02,
            speed_coeff_s2_per_m2: 0.0,
            speed_coeff_sigma: 1e-4,
            wheel_heading_noise_deg_per_sqrt_m: 0.01,
            wheel_resolution_m: 0.02,
        }
    }
}

impl Validate for SensorPriors {
    fn validate(&self) -> Result<()> {
        check_positive(
            "gyro_noise_dps_per_sqrt_hz",
            self.gyro_noise_dps_per_sqrt_hz,
        )?;
        check_positive(
            "gyro_bias_walk_dps_per_sqrt_s",
            self.gyro_bias_walk_dps_per_sqrt_s,
        )?;
        check_positive("gyro_bias_sigma_dps", self.gyro_bias_sigma_dps)?;
        check_range("gyro_gain_sigma", self.gyro_gain_sigma, 1e-9, 0.5)?;
        check_range("wheel_diff_sigma", self.wheel_diff_sigma, 1e-9, 0.2)?;
        check_range("wheel_scale_sigma", self.wheel_scale_sigma, 0.0, 0.5)?;
        check_range("wheel_track_sigma", self.wheel_track_sigma, 1e-9, 0.3)?;
        check_range(
            "speed_coeff_s2_per_m2",
            self.speed_coeff_s2_per_m2,
            -1e-2,
            1e-2,
        )?;
        check_range("speed_coeff_sigma", self.speed_coeff_sigma, 1e-12, 1e-2)?;
        check_positive(
            "wheel_heading_noise_deg_per_sqrt_m",
            self.wheel_heading_noise_deg_per_sqrt_m,
        )?;
        check_range("wheel_resolution_m", self.wheel_resolution_m, 1e-6, 1.0)?;
        Ok(())
    }
}

/// How compass readings are calibrated, judged and used.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CompassGates {
    /// The online least-squares calibrators the compass learns its hard and soft iron with
    /// (defaults as [`OnlineEllipseConfig`], but refreshed every 64 readings taken: a
    /// vehicle's calibration changes slowly, and a refresh costs as much as a few hundred
    /// samples' filtering).
    pub calibrator: OnlineEllipseConfig,
    /// A reading goes to the calibrator once the heading has moved this far since the last
    /// one it took, degrees (2): even coverage, and a small per-sample cost on straights.
    pub calibrator_spacing_deg: f64,
    /// …or once this long has passed, s (10).
    pub calibrator_interval_s: f64,
    /// Largest relative departure of the calibrated field magnitude from the fitted one
    /// before a reading is taken as disturbed (0.1).
    pub field_tolerance: f64,
    /// A reading whose innovation exceeds this many standard deviations is rejected (3.5).
    pub innovation_gate_sigma: f64,
    /// Time constant of the averaged innovation that catches slow disturbances, s (1.5):
    /// longer averages less noise but lags a drifting field by more.
    pub slow_gate_tau_s: f64,
    /// The compass counts as disturbed while the averaged innovation exceeds this many of
    /// its standard deviations (3).
    pub slow_gate_sigma: f64,
    /// Standard deviation of the heading error that the calibration and the road (grade,
    /// camber) leave in every reading alike for a while, degrees (0.3): the filter carries
    /// it as a state, so that it is not averaged away as if it were noise.
    pub systematic_deg: f64,
    /// Correlation time of that error, s (20): it changes as the vehicle turns and the road
    /// changes.
    pub systematic_tau_s: f64,
    /// Readings averaged into one heading correction (5): the covariance is carried
    /// forward once per correction rather than at every sample.
    pub readings_per_update: u32,
    /// Readings that must agree before the heading is first referred to north (20).
    pub alignment_readings: u32,
}

impl Default for CompassGates {
    fn default() -> Self {
        Self {
            calibrator: OnlineEllipseConfig {
                refresh_interval_samples: 64,
                ..OnlineEllipseConfig::default()
            },
            calibrator_spacing_deg: 2.0,
            calibrator_interval_s: 10.0,
            field_tolerance: 0.1,
            innovation_gate_sigma: 3.5,
            slow_gate_tau_s: 1.5,
            slow_gate_sigma: 3.0,
            systematic_deg: 0.3,
            systematic_tau_s: 20.0,
            readings_per_update: 10,
            alignment_readings: 20,
        }
    }
}

impl Validate for CompassGates {
    fn validate(&self) -> Result<()> {
        self.calibrator.validate()?;
        check_range(
            "calibrator_spacing_deg",
            self.calibrator_spacing_deg,
            0.0,
            90.0,
        )?;
        check_positive("calibrator_interval_s", self.calibrator_interval_s)?;
        check_range("field_tolerance", self.field_tolerance, 1e-3, 1.0)?;
        check_range(
            "innovation_gate_sigma",
            self.innovation_gate_sigma,
            1.0,
            100.0,
        )?;
        check_positive("slow_gate_tau_s", self.slow_gate_tau_s)?;
        check_range("slow_gate_sigma", self.slow_gate_sigma, 1.0, 100.0)?;
        check_range("systematic_deg", self.systematic_deg, 1e-3, 45.0)?;
        check_positive("systematic_tau_s", self.systematic_tau_s)?;
        check_range(
            "readings_per_update",
            f64::from(self.readings_per_update),
            1.0,
            100.0,
        )?;
        check_range(
            "alignment_readings",
            f64::from(self.alignment_readings),
            1.0,
            1e4,
        )?;
        Ok(())
    }
}

/// Configuration of the [`crate::VehicleEstimator`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct VehicleConfig {
    /// Which wheels carry the odometer and the vehicle's dimensions (default: rear wheels,
    /// track 1.55 m).
    pub wheels: OdometerWheels,
    /// Prior beliefs about the sensors.
    pub priors: SensorPriors,
    /// Compass calibration and gates.
    pub compass: CompassGates,
    /// The wheels must stand still this long before the vehicle counts as at rest, s (0.5).
    pub standstill_s: f64,
}

impl Default for VehicleConfig {
    fn default() -> Self {
        Self {
            wheels: OdometerWheels::Rear { track_m: 1.55 },
            priors: SensorPriors::default(),
            compass: CompassGates::default(),
            standstill_s: 0.5,
        }
    }
}

impl Validate for VehicleConfig {
    fn validate(&self) -> Result<()> {
        self.wheels.validate()?;
        self.priors.validate()?;
        self.compass.validate()?;
        check_range("standstill_s", self.standstill_s, 0.0, 60.0)?;
        Ok(())
    }
}
