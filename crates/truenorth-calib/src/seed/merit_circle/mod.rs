//! The merit-circle calibrator (US 5,297,063): circumcentres of reading triples, merged by
//! a figure of merit; its configuration and its saved state.

pub(crate) mod calibrator;
pub(crate) mod config;
pub(crate) mod persist;

#[cfg(test)]
mod tests;

pub use calibrator::{MeritCircleCalibrator, MeritCircleState};
pub use config::{MERIT_CIRCLE_MIN_ARC_DEG, MeritCircleConfig, RING};
pub use persist::MeritCircleCalibratorState;
