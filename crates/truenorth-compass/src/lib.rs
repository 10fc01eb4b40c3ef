//! # truenorth-compass
//!
//! The magnetometer as a compass: compass calibration parameters (hard iron, soft iron),
//! heading from a calibrated reading, tilt compensation, and the forward model of a
//! magnetometer mounted in a vehicle.
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
#![cfg_attr(not(feature = "std"), no_std)]

mod calibration;

pub use calibration::{CompassCalibration2d, CompassCalibration3d, heading_from_horizontal};
