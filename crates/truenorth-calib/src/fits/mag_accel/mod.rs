//! Joint calibration of a magnetometer and an accelerometer mounted together: its
//! configuration, the calibration it produces, the readings it keeps, the calibrator and
//! its fit, the least-squares problem (its parameters, its data and its normal equations), the runs of shots aimed at one target and their
//! rows, and the report.

pub(crate) mod calibration;
pub(crate) mod calibrator;
pub(crate) mod config;
pub(crate) mod data;
pub(crate) mod model;
pub(crate) mod readings;
#[cfg(test)]
mod readings_tests;
pub(crate) mod report;
pub(crate) mod run_rows;
pub(crate) mod runs;
pub(crate) mod solve;
#[cfg(test)]
mod solve_tests;

pub use calibration::{MagAccelCalibration, MagAccelSample};
pub use calibrator::{MagAccelCalibrator, fit_mag_accel, fit_mag_accel_readings};
pub use config::{INITIAL_FIT_BOUND_DEG, MIN_MAG_ACCEL_READINGS, MagAccelConfig};
pub use readings::{MagAccelReading, MagAccelStore, mag_accel_reading};
pub use report::MagAccelQuality;
