//! Online least-squares ellipsoid calibration of a three-axis magnetometer: the calibrator,
//! its configuration, and the refresh it runs in short stages.

pub(crate) mod calibrator;
pub(crate) mod config;
pub(crate) mod refresh;

pub use calibrator::{OnlineEllipsoidCalibrator, OnlineEllipsoidState};
pub use config::OnlineEllipsoidConfig;
