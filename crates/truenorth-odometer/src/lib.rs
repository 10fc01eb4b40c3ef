//! # truenorth-odometer
//!
//! Two-wheel differential odometry for land vehicles: a forward model of the odometer (for
//! the simulator and round-trip tests), its calibration, and heading change from the
//! difference of the wheel distances (US 4,788,645 "Method and apparatus for measuring
//! relative heading changes in a vehicular onboard navigation system", Etak).
//!
//! * [`OdometerModel`]: truth ([`WheelMotion`]: rear-axle-centre distance, curvature,
//!   speed) → raw wheel distances with per-wheel scale error, the speed-dependent
//!   differential error `(1 + aV²)` and pulse quantisation, over either rear wheels or
//!   Ackermann-steered front wheels with **exact** rigid-body geometry ([`AckermannGeometry`]).
//! * [`OdometerCalibration`]: the inverse of the scale and speed errors
//!   ([`truenorth_core::Calibration::apply`], fallible like every entry point here).
//! * [`heading_change_plain_rad`] (eq. 1/7) and [`heading_change_speed_corrected_rad`]
//!   (eq. 2/8).
//! * The effective front track ([`EffectiveTrack`]): exact ([`AckermannGeometry`]), the
//!   patent's eq. 3/14 ([`PatentAckermannTrack`]) and its look-up table
//!   ([`EffectiveTrackTable`], claims 15-16).
//! * [`OdometryStep`]: one step of the two wheels → distance, speed-corrected difference and,
//!   over the effective track, heading change with its derivatives with respect to the
//!   calibration ([`OdometryTurn`]).
//! * [`DifferentialOdometer`]: cumulative [`truenorth_core::WheelSample`]s → heading change
//!   and distance per step, a [`truenorth_core::RelativeHeadingSource`].
//!
//! Sign: the left wheel rolling further is a right turn (positive heading change).
//!
//! ## How good is the patent's formula?
//!
//! Relative error `(T_E,patent − T_E,exact)/T_E,exact` at the same measured ratio c, for
//! B = 2.7 m, T_F = 1.55 m and a kingpin offset p = 0.10 m, i.e. P = 2p/T_F = 0.129 (the
//! patent's "approx. 1/8"). Printed by
//! `cargo run -p truenorth-odometer --example ackermann_error`:
//!
//! | c = ΔD/AD | rear-axle radius | inner steer | error of T_E | heading error on a 90° turn |
//! |---|---|---|---|---|
//! | 0.04 | 38.6 m | 4.1° | −1.6e-6 | 0.000° |
//! | 0.10 | 15.1 m | 10.6° | −6.8e-5 | 0.006° |
//! | 0.16 | 8.9 m | 18.1° | −5.6e-4 | 0.05° |
//! | 0.20 | 6.7 m | 24.0° | −1.8e-3 | 0.16° |
//! | 0.24 | 5.1 m | 31.2° | −6.0e-3 | 0.55° |
//! | 0.26 | 4.4 m | 35.8° | −1.26e-2 | 1.15° |
//! | 0.28 | 3.7 m | 41.8° | −4.1e-2 | 3.8° |
//! | 0.2841 (c_max) | 3.5 m | 43.4° | −8.9e-2 | 8.8° |
//!
//! The formula under-states the track (over-states the turn) by less than 0.1 % on curves of
//! radius above about 8 m, by 1.3-2 % at a typical full lock (inner wheel 36-39°), and
//! refuses beyond its c_max while the car itself could turn tighter (the exact ratio peaks at
//! 0.2986 for this geometry).
//! Over B 2.2-3.3 m, T_F 1.3-1.8 m, p 0-0.12 m the error stays below 4.5e-4 for
//! c ≤ c_max/2 and 1.4 % for c ≤ 0.9 c_max (tests in `tests/patent_vs_exact.rs`).
//!
//! ```
//! use truenorth_core::{RelativeHeadingSource, SensorModel, ZeroNoise};
//! use truenorth_odometer::{
//!     AckermannGeometry, AckermannParams, DifferentialOdometer, DifferentialOdometerConfig,
//!     OdometerModel, OdometerParams, OdometerWheels, WheelMotion,
//! };
//!
//! let car = AckermannParams { wheelbase_m: 2.7, track_m: 1.55, kingpin_offset_m: 0.1 };
//! let mut odometer = OdometerModel::new(OdometerParams::perfect(OdometerWheels::Front(car)))?;
//! let mut heading =
//!     DifferentialOdometer::new(AckermannGeometry::new(car)?, DifferentialOdometerConfig::default())?;
//!
//! // 10 m on a right-hand curve of radius 8 m, in one step of 1 s.
//! let start = odometer.sample_cumulative(0.0, &WheelMotion::default(), 1.0)?;
//! assert_eq!(heading.step(&start)?, None); // the first sample only starts the clock
//! let arc = WheelMotion { ds_m: 10.0, curvature_per_m: 1.0 / 8.0, speed_mps: 10.0, pivot_rad: 0.0 };
//! let end = odometer.sample_cumulative(1.0, &arc, 1.0)?;
//! assert!(end.dist_l_m > end.dist_r_m); // left longer: right turn
//! let step = heading.step(&end)?.unwrap();
//! assert!((step.heading_change_rad - 10.0 / 8.0).abs() < 1e-9);
//! // The distance is the front wheels' mean path, longer than the rear axle's 10 m.
//! assert!(step.distance_m.unwrap() > 10.0);
//!
//! // Every fallible entry point returns a typed error, never NaN.
//! assert!(odometer.sample(&WheelMotion { ds_m: f64::NAN, ..arc }, 1.0, &mut ZeroNoise).is_err());
//! assert!(heading.step(&end).is_err()); // the same timestamp again
//! # Ok::<(), truenorth_core::Error>(())
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

mod ackermann;
mod calibration;
mod differential;
mod differential_odometer;
mod effective_track;
mod odometer_model;
mod odometry_step;
mod patent_track;
mod track_table;
mod wheel_distances;
mod wheels;

pub use ackermann::{AckermannCoefficients, AckermannGeometry, AckermannParams, RigidMotion};
pub use calibration::{OdometerCalibration, OdometerRaw};
pub use differential::{
    curvature_ratio, heading_change_plain_rad, heading_change_speed_corrected_rad, speed_factor,
};
pub use differential_odometer::{DifferentialOdometer, DifferentialOdometerConfig, OdometerStep};
pub use effective_track::{EffectiveTrack, FixedTrack};
pub use odometer_model::{
    MIN_SCALE_ERROR, OdometerCoefficients, OdometerModel, OdometerParams, OdometerState,
};
pub use odometry_step::{OdometryStep, OdometryTurn, differential_gains};
pub use patent_track::PatentAckermannTrack;
pub use track_table::EffectiveTrackTable;
pub use wheel_distances::{TRACK_RANGE_M, WheelDistances, check_track};
pub use wheels::{OdometerWheels, WheelGeometry, WheelMotion};

/// The code blocks of the crate's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
