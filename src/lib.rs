//! # truenorth
//!
//! Calibrated heading, orientation and dead reckoning from low-cost navigation sensors.
//! This facade re-exports the layered crates.
//!
//! ```
//! use truenorth::core::wrap_pi;
//! assert!(wrap_pi(7.0) < 1.0);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

pub use truenorth_accel as accel;
pub use truenorth_calib as calib;
pub use truenorth_compass as compass;
pub use truenorth_core as core;
pub use truenorth_fusion as fusion;
pub use truenorth_geomag as geomag;
pub use truenorth_gyro as gyro;
pub use truenorth_odometer as odometer;
