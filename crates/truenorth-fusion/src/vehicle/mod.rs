//! Vehicle heading and dead reckoning from a gyro, wheel odometers and a compass, each
//! calibrated online from the drive itself.

mod compass_learning;
mod compass_monitor;
mod config;
mod estimator;
mod heading_trig;
mod innovation_line;
mod learned;
pub mod nav_filter;
mod seed_blend;
mod seed_gyro_compass;
mod seed_odometer_compass;
mod step_batch;
mod two_pass;
mod wheel_odometry;

pub use compass_learning::{CompassLearner, Judged};
pub use compass_monitor::{CompassFix, CompassMonitor, Verdict};
pub use config::{CompassGates, SensorPriors, VehicleConfig};
pub use estimator::VehicleEstimator;
pub use learned::{Learned, LearnedCompass, VehicleCalibration};
pub use nav_filter::NavFilter;
pub use seed_blend::{SeedBlend, SeedBlendConfig};
pub use seed_gyro_compass::{SeedGyroCompass, SeedGyroCompassConfig};
pub use seed_odometer_compass::{SeedOdometerCompass, SeedOdometerCompassConfig};
pub use two_pass::{TwoPassConfig, TwoPassStart};
pub use wheel_odometry::{WheelCalibration, WheelOdometry, WheelStep};
