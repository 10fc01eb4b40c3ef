//! # truenorth-accel
//!
//! The accelerometer: a forward model (gravity plus the vehicle's own acceleration, with bias,
//! scale error and noise) for the simulator and round-trip tests, its calibration (per axis,
//! or with cross-axis terms: [`AccelTriadCalibration`]), static
//! tilt (pitch and roll from gravity) and the quasi-static test that says when static tilt
//! can be trusted (the accelerometer parts of WO 00/36376).
//!
//! Frames: body x forward, y right, z down; the truth's attitude rotates body → NED. The
//! sensor reads specific force `f_b = Rᵀ(a_ned − g_ned)` with `g_ned = (0, 0, +g)`, so a level
//! sensor at rest reads `(0, 0, −g)`.
//!
//! ```
//! use nalgebra::{UnitQuaternion, Vector3};
//! use truenorth_accel::{
//!     AccelModel, AccelParams, AccelTruth, QuasiStaticConfig, QuasiStaticDetector, static_tilt,
//! };
//! use truenorth_core::{Calibration, EulerZyx, SensorModel, STANDARD_GRAVITY_MPS2};
//!
//! // Level and at rest: (0, 0, −g).
//! let perfect = AccelModel::new(AccelParams::default())?;
//! let level = perfect.ideal(&AccelTruth::at_rest(UnitQuaternion::identity()))?;
//! assert!((level - Vector3::new(0.0, 0.0, -STANDARD_GRAVITY_MPS2)).norm() < 1e-12);
//!
//! // A biased sensor, nose up 10°, right side down 20°: calibrate, check it is at rest,
//! // and read the tilt back.
//! let params = AccelParams { bias_mps2: Vector3::new(0.1, -0.2, 0.05), ..AccelParams::default() };
//! let accel = AccelModel::new(params)?;
//! let att = EulerZyx { yaw_rad: 1.0, pitch_rad: 10f64.to_radians(), roll_rad: 20f64.to_radians() };
//! let raw = accel.ideal(&AccelTruth::at_rest(att.to_quaternion()))?;
//! let f = accel.true_calibration().apply(&raw)?;
//! let detector = QuasiStaticDetector::new(QuasiStaticConfig::default())?;
//! assert!(detector.is_quasi_static(&f)?);
//! let tilt = static_tilt(&f)?;
//! assert!((tilt.pitch_rad.to_degrees() - 10.0).abs() < 1e-9);
//! assert!((tilt.roll_rad.to_degrees() - 20.0).abs() < 1e-9);
//!
//! // Every fallible entry point returns a typed error, never NaN.
//! assert!(accel.true_calibration().apply(&Vector3::new(f64::NAN, 0.0, 0.0)).is_err());
//! # Ok::<(), truenorth_core::Error>(())
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

mod accel_model;
mod calibration;
mod quasi_static;
mod specific_force;
mod static_tilt;
mod triad_calibration;

pub use accel_model::{AccelCoefficients, AccelModel, AccelParams, MIN_SCALE_ERROR};
pub use calibration::AccelCalibration;
pub use quasi_static::{QuasiStaticConfig, QuasiStaticDetector};
pub use specific_force::{AccelTruth, gravity_ned_mps2, specific_force_body_mps2};
pub use static_tilt::{MIN_SPECIFIC_FORCE_MPS2, pitch_from_forward_axis_rad, static_tilt};
pub use triad_calibration::{AccelTriadCalibration, MAX_TRIAD_CONDITION};

/// The code blocks of the crate's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
