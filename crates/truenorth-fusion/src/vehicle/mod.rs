//! Vehicle heading and dead reckoning from a gyro, wheel odometers and a compass, each
//! calibrated online from the drive itself.
//!
//! [`VehicleEstimator`] is the fused estimator; [`SeedOdometerCompass`] (US 4,788,645) and
//! [`SeedGyroCompass`] (EP 0640207) are the seed documents' configurations behind the same
//! [`truenorth_core::HeadingEstimator`] trait. [`TwoPassStart`] runs the head of a drive
//! again once the sensors are learned, and [`VehicleCalibration`] carries what was learned
//! to the next drive.
//!
//! ```
//! use nalgebra::Vector2;
//! use truenorth_core::{HeadingEstimator, VehicleSample};
//! use truenorth_fusion::{VehicleConfig, VehicleEstimator};
//!
//! let mut nav = VehicleEstimator::new(VehicleConfig::default())?;
//! // Ten seconds straight ahead at 10 m/s, a raw gyro with its own bias, a raw compass.
//! for k in 0..=100 {
//!     let t_s = 0.1 * k as f64;
//!     let row = VehicleSample::at(t_s)
//!         .with_wheels(10.0 * t_s, 10.0 * t_s)
//!         .with_gyro(0.005)
//!         .with_mag(Vector2::new(25.0, -3.0));
//!     let e = nav.update(&row)?;
//!     // No turn yet, so no compass calibration: the heading is relative to the start.
//!     assert!(!e.status.heading_absolute);
//! }
//! let e = nav.estimate();
//! assert!((e.north_m.hypot(e.east_m) - 100.0).abs() < 1.0);
//! // Time going backwards is refused, and changes nothing.
//! let late = VehicleSample::at(5.0).with_wheels(50.0, 50.0);
//! assert!(nav.update(&late).is_err());
//! assert_eq!(nav.estimate(), e);
//! # Ok::<(), truenorth_core::Error>(())
//! ```

mod compass_fusion;
mod compass_learning;
mod compass_monitor;
mod config;
mod dead_reckoning;
mod estimator;
mod gnss_fusion;
mod gnss_speed;
mod gnss_track;
mod heading_trig;
mod innovation_line;
mod learned;
mod learning_gates;
pub mod nav_filter;
mod observability;
mod odometer_history;
mod path_trail;
mod plain_baseline;
mod plain_guard;
mod seed_blend;
mod seed_gyro_compass;
mod seed_odometer_compass;
mod seed_state;
mod state;
mod step_batch;
mod tracking;
mod two_pass;
mod wheel_odometry;

pub use compass_learning::{CompassLearner, CompassLearnerState, Judged};
pub use compass_monitor::{CompassFix, CompassMonitor, CompassMonitorState, Verdict};
pub use config::{CompassGates, GnssConfig, SensorPriors, VehicleConfig};
pub use estimator::VehicleEstimator;
pub use gnss_fusion::GnssCounts;
pub use gnss_track::PlaneShift;
pub use learned::{Learned, LearnedCompass, VehicleCalibration};
pub use learning_gates::SPEED_COEFF_MIN_SPEED_MPS;
pub use nav_filter::NavFilter;
pub use seed_blend::{SeedBlend, SeedBlendConfig};
pub use seed_gyro_compass::{SeedGyroCompass, SeedGyroCompassConfig};
pub use seed_odometer_compass::{SeedOdometerCompass, SeedOdometerCompassConfig};
pub use seed_state::{SeedGyroCompassState, SeedOdometerCompassState};
pub use state::VehicleEstimatorState;
pub use tracking::VehicleTracking;
pub use two_pass::{TwoPassConfig, TwoPassStart};
pub use wheel_odometry::{
    MAX_WHEEL_SPEED_MPS, TrackModel, WheelCalibration, WheelOdometry, WheelOdometryState, WheelStep,
};
