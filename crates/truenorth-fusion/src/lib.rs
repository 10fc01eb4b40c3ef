//! # truenorth-fusion
//!
//! Estimators that fuse the calibrated sensors: the Euler orientation detector of
//! WO 00/36376, a quaternion orientation filter, and vehicle heading and dead reckoning.
//!
//! **Status:** no estimator is implemented yet. They will implement the traits defined in
//! `truenorth-core`, [`truenorth_core::OrientationEstimator`] (IMU samples → attitude) and
//! [`truenorth_core::HeadingEstimator`] (vehicle samples → heading and position), so that
//! tests, benches and the CLI take any of them:
//!
//! ```
//! use truenorth_core::{HeadingEstimator, NavState};
//!
//! /// Works with whichever vehicle estimator the caller picks.
//! fn final_position<E: HeadingEstimator>(est: &E) -> (f64, f64) {
//!     let NavState { north_m, east_m, .. } = est.state();
//!     (north_m, east_m)
//! }
//! ```
#![cfg_attr(not(feature = "std"), no_std)]
