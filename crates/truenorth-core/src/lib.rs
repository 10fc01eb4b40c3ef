//! # truenorth-core
//!
//! The vocabulary every other truenorth crate speaks: angles and units, the sample types
//! that carry sensor readings, the traits that join sensor models, calibrators and
//! estimators, input validation, and the one error type.
//!
//! Conventions (fixed across the workspace, see `ARCHITECTURE.md`, section "Frames and
//! signs"): body axes x forward, y right, z down; heading clockwise from north; radians and
//! SI units inside, degrees only at the edges through [`deg_to_rad`] / [`rad_to_deg`];
//! quaternions are Hamilton, scalar first, rotating body vectors into the NED reference
//! frame.
//!
//! ```
//! use truenorth_core::{wrap_pi, deg_to_rad, rad_to_deg, TimeStep};
//!
//! // 350° + 20° is 10°, not 370°.
//! let h = wrap_pi(deg_to_rad(350.0) + deg_to_rad(20.0));
//! assert!((rad_to_deg(h) - 10.0).abs() < 1e-9);
//!
//! // dt comes from timestamps; a timestamp that goes backwards is a typed error.
//! let mut clock = TimeStep::new();
//! assert_eq!(clock.dt_s(0.0).unwrap(), None);
//! assert_eq!(clock.dt_s(0.01).unwrap(), Some(0.01));
//! assert!(clock.dt_s(0.005).is_err());
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

mod angle;
mod attitude;
mod calibrator;
pub mod compass_quality;
mod error;
mod estimator;
pub mod extended_float;
mod fit_quality;
mod gnss_fix;
mod heading;
mod heading_source;
mod inertial_calibration;
mod message_numbers;
mod noise;
mod persist;
mod real;
mod refusal;
mod sample;
mod sensor_model;
mod units;
mod validate;
mod vehicle_sensors;
pub mod verdict;

pub use angle::{Unwrapper, angle_diff, unwrap_near, wrap_pi, wrap_two_pi};
pub use attitude::{EulerZyx, Tilt, ned_to_enu};
pub use calibrator::{Calibration, Calibrator, OnlineCalibrator, Progress, Pushed, Solution};
pub use compass_quality::{CompassQuality, CompassUncertainty};
pub use error::Error;
pub use estimator::{
    AttitudeEstimate, AttitudeStatus, HeadingEstimator, NavEstimate, NavStatus,
    OrientationEstimator, Unobserved,
};
pub use fit_quality::{FitQuality, ScalarQuality};
pub use gnss_fix::{GnssFix, MAX_GNSS_SIGMA_M, MAX_GNSS_SPEED_MPS};
pub use heading::{Declination, MagneticHeading, TrueHeading};
pub use heading_source::{
    AbsoluteHeading, AbsoluteHeadingSource, RelativeHeadingSource, RelativeStep,
};
pub use inertial_calibration::{InertialCalibration, axis_calibrated};
pub use message_numbers::{Fixed, Precise, Readable};
pub use noise::{NoiseSource, SplitMix64, ZeroNoise};
pub use persist::{Persistent, Snapshot, check_snapshot_version};
pub use real::Real;
pub use sample::{
    AccelSample, Axes, GyroSample, ImuSample, MAX_YAW_RATE_RPS, Mag2Sample, Mag3Sample,
    VehicleSample, WheelReading, WheelSample,
};
pub use sensor_model::SensorModel;
pub use units::{STANDARD_GRAVITY_MPS2, deg_to_rad, mph_to_mps, mps_to_mph, rad_to_deg};
pub use validate::{
    TimeStep, Validate, check_dt, check_finite, check_finite2, check_finite3, check_positive,
    check_range,
};
pub use vehicle_sensors::{Travel, VehicleSensors};
pub use verdict::{Cause, Grade, Verdict};

/// Float methods (`sin`, `sqrt`, `atan2`, …) for `f64` that work with and without `std`.
///
/// With `std` the inherent `f64` methods are used; without it, `libm` through `num-traits`.
/// Import it as `use truenorth_core::Float as _;` in modules that do float math.
pub use num_traits::Float;

/// Result type with the workspace error.
pub type Result<T, E = Error> = core::result::Result<T, E>;

/// The code blocks of the crate's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
