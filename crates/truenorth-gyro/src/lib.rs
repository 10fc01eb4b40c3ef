//! # truenorth-gyro
//!
//! The rate gyro: a forward model of its errors (for the simulator and for round-trip tests),
//! its calibration (zero and scale), and the integration of yaw rate into heading change.
//!
//! Conditioning of a gyro's output as the orientation detector of WO 00/36376 does it
//! (its high-pass filters, corrector and oscillation removers): a [`HighPassFilter`] with a variable cutoff removes the offset, a
//! [`HighPassCorrection`] undoes the filter's distortion (with an offset-error compensator),
//! an [`IirHighPass`] is the digital variant (buffer reset and input-offset correction), and
//! an [`OscillationRemover`] zeroes hand tremor.
//!
//! A vehicle usually has one gyro, about the vertical axis (`gyr_z`, positive for a right
//! turn). That case is the plain [`GyroAxisModel`], [`GyroCalibration`] and [`YawIntegrator`]
//! (whose trapezoid step, [`YawIncrement`], every estimator of the workspace integrates by);
//! the three-axis [`Gyro3Model`] and [`Gyro3Calibration`] are three of those side by side.
//!
//! Error model of one axis (reading `r` for true rate `ω`, temperature `T`):
//!
//! `r = k(ω)·ω + b₀ + k_T·(T − T_ref) + b_walk(t) + n`, with `k(ω) = 1 + s₊` for `ω ≥ 0` and
//! `1 + s₋` for `ω < 0`, `b_walk` a random walk and `n` white noise.
//!
//! Every fallible entry point returns a typed [`truenorth_core::Error`] instead of a NaN:
//! [`SensorModel::ideal`](truenorth_core::SensorModel::ideal) and
//! [`sample`](truenorth_core::SensorModel::sample),
//! [`Calibration::apply`](truenorth_core::Calibration::apply) and the integrator's `step`.
//!
//! ```
//! use truenorth_core::{Calibration, GyroSample, RelativeHeadingSource, SensorModel};
//! use truenorth_gyro::{
//!     GyroAxisModel, GyroAxisParams, RateTruth, YawIntegrator, YawIntegratorConfig,
//! };
//! use nalgebra::Vector3;
//!
//! // A yaw gyro with 0.01 rad/s bias and 2 % scale error.
//! let params = GyroAxisParams { bias_rps: 0.01, scale_error_pos: 0.02, scale_error_neg: 0.02,
//!                               ..GyroAxisParams::default() };
//! let gyro = GyroAxisModel::new(params)?;
//! let truth = RateTruth::at_reference(0.5, &params);
//! let raw = gyro.ideal(&truth)?;
//! assert!((raw - (1.02 * 0.5 + 0.01)).abs() < 1e-12);
//!
//! // The model's true inverse gives the rate back.
//! let calibration = gyro.true_calibration(truth.temp_c)?;
//! assert!((calibration.apply(&raw)? - 0.5).abs() < 1e-12);
//!
//! // Integrate a constant calibrated 0.5 rad/s for 2 s into heading change.
//! let mut yaw = YawIntegrator::new(YawIntegratorConfig { calibration })?;
//! let at = |t_s| GyroSample { t_s, gyr_rps: Vector3::new(0.0, 0.0, raw) };
//! assert_eq!(yaw.step(&at(0.0))?, None); // the first sample only starts the clock
//! let step = yaw.step(&at(2.0))?.unwrap();
//! assert!((step.heading_change_rad - 1.0).abs() < 1e-12);
//! assert_eq!(step.distance_m, None); // a gyro measures no distance
//! // A timestamp that does not increase is a typed error and changes nothing.
//! assert!(yaw.step(&at(2.0)).is_err());
//! assert!((yaw.heading_rad() - 1.0).abs() < 1e-12);
//! # Ok::<(), truenorth_core::Error>(())
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

mod axis_model;
mod calibration;
mod high_pass;
mod high_pass_correction;
mod iir_high_pass;
mod oscillation_remover;
mod triad_model;
mod yaw_increment;
mod yaw_integrator;

pub use axis_model::{
    GyroAxisCoefficients, GyroAxisModel, GyroAxisParams, GyroAxisState, MIN_SCALE_ERROR, RateTruth,
};
pub use calibration::{Gyro3Calibration, GyroCalibration};
pub use high_pass::{HighPassConfig, HighPassFilter};
pub use high_pass_correction::{HighPassCorrection, HighPassCorrectionConfig};
pub use iir_high_pass::{IirHighPass, IirHighPassConfig};
pub use oscillation_remover::{
    MAX_OSCILLATION_WINDOW, OscillationRemover, OscillationRemoverConfig,
};
pub use triad_model::{Gyro3Model, Gyro3Params, Rate3Truth};
pub use yaw_increment::YawIncrement;
pub use yaw_integrator::{YawIntegrator, YawIntegratorConfig};

/// The model of a single-axis yaw gyro, the usual vehicle case (`gyr_z`, positive = right turn).
pub type YawGyroModel = GyroAxisModel;

/// The code blocks of the crate's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
