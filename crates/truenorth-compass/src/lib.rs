//! # truenorth-compass
//!
//! The magnetometer as a compass:
//!
//! - **calibration parameters** — [`CompassCalibration2d`] and [`CompassCalibration3d`]
//!   (`corrected = soft_iron · (raw − hard_iron)`), plain serde types that every calibrator in
//!   `truenorth-calib` produces;
//! - **heading** from a calibrated reading ([`heading_from_horizontal`]), **tilt
//!   compensation** of a three-axis reading ([`level_field`], [`tilt_compensated_heading`]),
//!   and, with only two axes, the **M_z reconstruction** of the seed WO 00/36376
//!   ([`MzReconstruction`]);
//! - the **binned-ellipse heading formulas** of EP 0634001 ([`EllipsePhasors`]: the
//!   counter-rotating phasor parameters, the closed-form and the iterative corrected heading,
//!   and their conversion to a [`CompassCalibration2d`]);
//! - **forward models** of a magnetometer in a vehicle behind
//!   [`truenorth_core::SensorModel`]: [`MagnetometerModel2d`] (level, two axes) and
//!   [`MagnetometerModel3d`] (three axes, tilted body, inclined field), with hard iron, a full
//!   soft-iron matrix, noise and transient [`Disturbance`]s. Each model's
//!   `true_calibration()` is its exact inverse.
//!
//! Applying a calibration and the heading from it are generic over the float type
//! ([`truenorth_core::Real`]: `f64`, or `f32` for a single-precision FPU):
//! [`CompassCalibration2d::to_precision`] turns the fitted `f64` parameters into `f32` ones.
//!
//! Heading convention: a level compass reads `mag_x = H cos ψ`, `mag_y = −H sin ψ`, so
//! `ψ = atan2(−mag_y, mag_x)`, clockwise from magnetic north.
//!
//! ```
//! use nalgebra::{Matrix2, Vector2};
//! use truenorth_compass::CompassCalibration2d;
//!
//! // A compass whose reading is shifted by (5, -3) (hard iron) and otherwise ideal.
//! let cal = CompassCalibration2d { hard_iron: Vector2::new(5.0, -3.0), soft_iron: Matrix2::identity() };
//! // Heading 90° (east): ideal reading (0, -H), here H = 20.
//! let raw = Vector2::new(5.0, -3.0 - 20.0);
//! assert!((cal.heading_rad(&raw).to_degrees() - 90.0).abs() < 1e-9);
//! ```
//!
//! A simulated compass with hard and soft iron, and its exact inverse:
//!
//! ```
//! use nalgebra::Vector2;
//! use truenorth_compass::{HeadingTruth, MagnetometerModel2d, soft_iron_from_axes};
//! use truenorth_core::SensorModel;
//!
//! let model = MagnetometerModel2d::new(
//!     Vector2::new(10.0, -4.0),                           // hard iron
//!     soft_iron_from_axes(1.3, 1.0, 30f64.to_radians()),  // axis ratio 1.3, rotated 30°
//!     0.0,                                                // no noise
//! )?;
//! let truth = HeadingTruth { heading_rad: 1.0, horizontal_field: 20.0 };
//! let raw = model.ideal(&truth)?;
//! let heading = model.true_calibration().heading_rad(&raw);
//! assert!((heading - 1.0).abs() < 1e-9);
//! # Ok::<(), truenorth_core::Error>(())
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

mod calibration;
mod distortion;
mod disturbance;
mod model2d;
mod model3d;
mod mz_reconstruction;
mod phasors;
mod soft_iron;
mod tilt;

pub use calibration::{
    CompassCalibration2d, CompassCalibration2dIn, CompassCalibration3d, CompassCalibration3dIn,
};
pub use disturbance::{Disturbance, DisturbanceShape, Disturbances, MAX_DISTURBANCES};
pub use model2d::{HeadingTruth, MagnetometerModel2d};
pub use model3d::{AttitudeTruth, MagnetometerModel3d, earth_field_ned};
pub use mz_reconstruction::MzReconstruction;
pub use phasors::{EllipsePhasors, ITERATIVE_MAX_STEPS};
pub use soft_iron::{EllipseAxes, ellipse_axes, soft_iron_from_axes};
pub use tilt::{
    heading_from_horizontal, heading_from_horizontal_in, level_field, level_field_in,
    tilt_compensated_heading, tilt_compensated_heading_checked, tilt_compensated_heading_in,
};

/// The code blocks of the crate's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
