//! # truenorth-gyro
//!
//! The rate gyro: a forward model of its errors (for the simulator and for round-trip tests),
//! its calibration (zero and scale), and the integration of yaw rate into heading change.
//!
//! A vehicle usually has one gyro, about the vertical axis (`gyr_z`, positive for a right
//! turn). That case is the plain [`GyroAxisModel`], [`GyroCalibration`] and [`YawIntegrator`];
//! the three-axis [`Gyro3Model`] and [`Gyro3Calibration`] are three of those side by side.
//!
//! Error model of one axis (reading `r` for true rate `ω`, temperature `T`):
//!
//! `r = k(ω)·ω + b₀ + k_T·(T − T_ref) + b_walk(t) + n`, with `k(ω) = 1 + s₊` for `ω ≥ 0` and
//! `1 + s₋` for `ω < 0`, `b_walk` a random walk and `n` white noise.
//!
//! ```
//! use truenorth_core::{Calibration, SensorModel};
//! use truenorth_gyro::{GyroAxisModel, GyroAxisParams, RateTruth, YawIntegrator};
//!
//! // A yaw gyro with 0.01 rad/s bias and 2 % scale error.
//! let params = GyroAxisParams { bias_rps: 0.01, scale_error_pos: 0.02, scale_error_neg: 0.02,
//!                               ..GyroAxisParams::default() };
//! let gyro = GyroAxisModel::new(params).unwrap();
//! let truth = RateTruth::at_reference(0.5, &params);
//! let raw = gyro.ideal(&truth);
//! assert!((raw - (1.02 * 0.5 + 0.01)).abs() < 1e-12);
//!
//! // The model's true inverse gives the rate back.
//! let cal = gyro.true_calibration(truth.temp_c).unwrap();
//! assert!((cal.apply(&raw) - 0.5).abs() < 1e-12);
//!
//! // Integrate a constant calibrated 0.5 rad/s for 2 s into heading change.
//! let mut yaw = YawIntegrator::new(cal);
//! yaw.push_yaw_rate(0.0, raw).unwrap();
//! yaw.push_yaw_rate(2.0, raw).unwrap();
//! assert!((yaw.heading_rad() - 1.0).abs() < 1e-12);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

mod axis_model;
mod calibration;
mod triad_model;
mod yaw_integrator;

pub use axis_model::{
    GyroAxisCoefficients, GyroAxisModel, GyroAxisParams, GyroAxisState, MIN_SCALE_ERROR, RateTruth,
};
pub use calibration::{Gyro3Calibration, GyroCalibration};
pub use triad_model::{Gyro3Model, Rate3Truth};
pub use yaw_integrator::YawIntegrator;

/// The model of a single-axis yaw gyro, the usual vehicle case (`gyr_z`, positive = right turn).
pub type YawGyroModel = GyroAxisModel;
