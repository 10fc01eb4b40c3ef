//! Every method by name: the one place where a method named on the command line (or in the
//! demo and the evaluations) becomes an implementation, boxed behind the trait the commands
//! run it through.
//!
//! * [`CalibrationMethod`] → [`CompassCalibrator`]: a `Calibrator` of the samples the
//!   method learns from (two-axis, three-axis, magnetometer with accelerometer, one turn);
//! * [`OrientationMethod`] → a `dyn OrientationEstimator`;
//! * [`VehicleMethod`] → a `dyn` [`VehicleRun`]: a `HeadingEstimator`, or the fused
//!   estimator with its two-pass start.

mod compass;
mod orientation;
mod vehicle;

pub use compass::{CalibrationMethod, CompassCalibrator, MagAccel, Planar, Spatial, TurnWithGyro};
pub use orientation::{Orientation, OrientationMethod, Timing};
pub use vehicle::{VehicleMethod, VehicleRun};
