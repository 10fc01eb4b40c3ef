//! # truenorth
//!
//! Calibrated heading, orientation and dead reckoning from low-cost navigation sensors:
//! magnetic compass, rate gyro, wheel odometer and accelerometer.
//!
//! This facade re-exports the layered crates under short names and offers a [`prelude`]
//! with the types most programs need. Each crate can also be used on its own.
//!
//! | module | crate | what |
//! |---|---|---|
//! | [`core`] | `truenorth-core` | angles, units, samples, traits, errors |
//! | [`geomag`] | `truenorth-geomag` | World Magnetic Model 2025: declination, dip, field |
//! | [`compass`] | `truenorth-compass` | magnetometer model, compass calibration, heading |
//! | [`gyro`] | `truenorth-gyro` | rate-gyro model, zero/scale, integration |
//! | [`odometer`] | `truenorth-odometer` | wheel odometer, differential heading, Ackermann track |
//! | [`accel`] | `truenorth-accel` | accelerometer model, static tilt |
//! | [`calib`] | `truenorth-calib` | calibrators with quality reports |
//! | [`fusion`] | `truenorth-fusion` | orientation and vehicle heading estimators |
//! | [`checks`] | `truenorth-checks` | a recording against its physics: units, axes, yaw against wheels (`std`) |
//!
//! On top of them, what the `truenorth` command and the Python package stand on: a [`Place`]
//! and [`TrueNorth`], the one place where a magnetic heading, a track or an attitude turns
//! onto true north, and [`CompassCalibration`], any stored compass calibration and the
//! heading it gives a raw reading.
//!
//! ```
//! use truenorth::prelude::*;
//!
//! let h = wrap_pi(deg_to_rad(370.0));
//! assert!((rad_to_deg(h) - 10.0).abs() < 1e-9);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

mod heading;
mod place;

pub use heading::CompassCalibration;
pub use place::{Place, TrueNorth};

// Inlined so that `cargo doc -p truenorth` documents every crate's types under the facade.
#[doc(inline)]
pub use truenorth_accel as accel;
#[doc(inline)]
pub use truenorth_calib as calib;
#[doc(inline)]
#[cfg(feature = "std")]
pub use truenorth_checks as checks;
#[doc(inline)]
pub use truenorth_compass as compass;
#[doc(inline)]
pub use truenorth_core as core;
#[doc(inline)]
pub use truenorth_fusion as fusion;
#[doc(inline)]
pub use truenorth_geomag as geomag;
#[doc(inline)]
pub use truenorth_gyro as gyro;
#[doc(inline)]
pub use truenorth_odometer as odometer;

/// The linear-algebra crate of every vector, matrix and quaternion in the API, so that a user
/// needs no version of their own to match it.
pub use nalgebra;

/// The one error type of every crate, and its `Result`.
pub use truenorth_core::{Error, Result};

/// The types and functions most programs need, in one import. The error type is not in it
/// (it would hide `std::error::Error`): it is [`crate::Error`].
pub mod prelude {
    pub use crate::{CompassCalibration, Place, TrueNorth};
    pub use truenorth_compass::{CompassCalibration2d, CompassCalibration3d};
    pub use truenorth_core::{
        AbsoluteHeadingSource, AttitudeEstimate, Axes, Calibration, Calibrator, CompassQuality,
        Declination, HeadingEstimator, ImuSample, Mag2Sample, Mag3Sample, MagneticHeading,
        NavEstimate, OnlineCalibrator, OrientationEstimator, Persistent, Pushed,
        RelativeHeadingSource, Solution, TrueHeading, VehicleSample, WheelSample, angle_diff,
        deg_to_rad, rad_to_deg, wrap_pi, wrap_two_pi,
    };
}
