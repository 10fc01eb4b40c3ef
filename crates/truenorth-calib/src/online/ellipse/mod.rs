//! Online least-squares ellipse calibration of a two-axis compass: the calibrator, its
//! configuration, and the refresh it runs in short stages.

pub(crate) mod calibrator;
pub(crate) mod config;
pub(crate) mod refresh;

pub use crate::online::conic::{OnlineConicState, PendingRefresh};
pub use calibrator::{OnlineEllipseCalibrator, OnlineEllipseState};
pub use config::OnlineEllipseConfig;
pub use refresh::ONLINE_SLOTS_2D;
