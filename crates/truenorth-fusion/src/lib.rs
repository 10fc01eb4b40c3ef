//! # truenorth-fusion
//!
//! Estimators that fuse the calibrated sensors: the Euler orientation detector of
//! WO 00/36376, a quaternion orientation filter, and vehicle heading and dead reckoning.
//!
//! Every estimator here implements one of the two traits of `truenorth-core`, so tests,
//! benches and the CLI take any of them:
//! [`truenorth_core::OrientationEstimator`] (IMU samples → [`AttitudeEstimate`]: 9-D and 6-D
//! attitude, gyro bias, rest and disturbance flags, σ) and
//! [`truenorth_core::HeadingEstimator`] (vehicle samples → [`NavEstimate`]: position,
//! heading, speed and their uncertainty).
//!
//! [`orientation`] holds the IMU estimators and their parts, [`vehicle`] the land-vehicle
//! ones; their public types are also re-exported here.
//!
//! - [`AttitudeError`]: an estimate's error against a reference, split into heading and
//!   inclination as the BROAD benchmark does.
//! - [`EulerDetector`]: the orientation angle detector of WO 00/36376, every piece
//!   selectable ([`EulerDetectorConfig`]).
//! - [`QuaternionFilter`]: 6-D / 9-D quaternion filter with gyro-bias estimation at rest
//!   ([`RestDetector`]) and in motion, magnetic-disturbance rejection ([`MagReference`]),
//!   online hard-iron re-estimation ([`HardIronEstimator`]) and the σ of its attitude from
//!   the sensors' error model ([`AttitudeUncertaintyConfig`]).
//! - Both orientation estimators save and restore what they carry between samples as plain
//!   data ([`truenorth_core::Persistent`]: [`QuaternionFilterState`], [`EulerDetectorState`]).
//! - [`VehicleEstimator`]: vehicle heading and dead reckoning from wheels, an optional yaw
//!   gyro and a raw compass, learning every sensor's errors while it drives (a 13-state
//!   Kalman filter; [`vehicle`] also holds the two-pass start, the learned calibration
//!   carried between drives, and the seed configurations of US 4,788,645 and EP 0640207).
//!
//! Code written against the traits works with whichever estimator is picked:
//!
//! ```
//! use truenorth_core::{HeadingEstimator, NavEstimate};
//!
//! /// Final position and its 1σ radius, for whichever vehicle estimator the caller picks.
//! fn final_position<E: HeadingEstimator>(est: &E) -> (f64, f64, f64) {
//!     let NavEstimate { north_m, east_m, position_cov_m2, .. } = est.estimate();
//!     (north_m, east_m, position_cov_m2.trace().sqrt())
//! }
//! ```
//!
//! [`AttitudeEstimate`]: truenorth_core::AttitudeEstimate
//! [`NavEstimate`]: truenorth_core::NavEstimate
#![cfg_attr(not(feature = "std"), no_std)]

pub mod orientation;
pub mod vehicle;

pub use orientation::attitude_uncertainty;
pub use orientation::{
    AttitudeError, AttitudeUncertaintyConfig, CorrectionDefinerConfig, EulerDetector,
    EulerDetectorConfig, EulerDetectorState, EulerVariant, GyroConditioning, GyroTiming,
    HardIronConfig, HardIronEstimator, MAX_DEFINER_WINDOW, MagReference, MagReferenceConfig,
    QuaternionFilter, QuaternionFilterConfig, QuaternionFilterState, RestConfig, RestDetector,
    StartupField, coefficient_table,
};
pub use vehicle::{CompassGates, GnssConfig, SensorPriors, VehicleConfig, VehicleEstimator};

/// The code blocks of the crate's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
