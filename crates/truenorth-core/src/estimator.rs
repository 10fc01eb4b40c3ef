//! Estimators: IMU samples → attitude, and vehicle streams → heading and position.

use nalgebra::UnitQuaternion;
use serde::{Deserialize, Serialize};

use crate::{ImuSample, Result, VehicleSample};

/// An orientation estimator. Every seed method and modern filter implements it, so tests,
/// benches, the CLI and the evaluation harness take any of them.
pub trait OrientationEstimator {
    /// Takes one sample (dt from its timestamp) and returns the new body → NED attitude.
    fn update(&mut self, sample: &ImuSample) -> Result<UnitQuaternion<f64>>;

    /// The current attitude estimate, body → NED.
    fn orientation(&self) -> UnitQuaternion<f64>;

    /// Returns to the initial state.
    fn reset(&mut self);
}

/// Position and heading of a land vehicle relative to its start point.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct NavState {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Northward displacement from the start, metres.
    pub north_m: f64,
    /// Eastward displacement from the start, metres.
    pub east_m: f64,
    /// Heading, radians clockwise from north, (-π, π].
    pub heading_rad: f64,
}

/// A vehicle heading / dead-reckoning estimator.
pub trait HeadingEstimator {
    /// Takes one sample and returns the new state.
    fn update(&mut self, sample: &VehicleSample) -> Result<NavState>;

    /// The current state.
    fn state(&self) -> NavState;

    /// Returns to the initial state.
    fn reset(&mut self);
}
