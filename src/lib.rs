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
//!
//! The [`pipeline`] module wires them: a self-calibrating compass, or any vehicle or
//! orientation estimator, with true north from the World Magnetic Model, in a few lines.
//!
//! ```
//! use truenorth::prelude::*;
//!
//! let h = wrap_pi(deg_to_rad(370.0));
//! assert!((rad_to_deg(h) - 10.0).abs() < 1e-9);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

pub mod pipeline;

pub use truenorth_accel as accel;
pub use truenorth_calib as calib;
pub use truenorth_compass as compass;
pub use truenorth_core as core;
pub use truenorth_fusion as fusion;
pub use truenorth_geomag as geomag;
pub use truenorth_gyro as gyro;
pub use truenorth_odometer as odometer;

/// The types and functions most programs need, in one import.
pub mod prelude {
    pub use crate::pipeline::{CompassPipeline, NavPipeline, OrientationPipeline, Place};
    pub use truenorth_compass::{CompassCalibration2d, CompassCalibration3d};
    pub use truenorth_core::{
        AbsoluteHeadingSource, AttitudeEstimate, Axes, Calibration, Calibrator, CompassQuality,
        Declination, Error, HeadingEstimator, ImuSample, Mag2Sample, Mag3Sample, MagneticHeading,
        NavEstimate, OnlineCalibrator, OrientationEstimator, Persistent, Pushed,
        RelativeHeadingSource, Solution, TrueHeading, VehicleSample, WheelSample, angle_diff,
        deg_to_rad, rad_to_deg, wrap_pi, wrap_two_pi,
    };
}
