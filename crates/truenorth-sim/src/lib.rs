//! # truenorth-sim
//!
//! Trajectories and sensor streams with ground truth, for tests, benches and the demo.
//! A route of driving commands is integrated by a rear-axle kinematic model
//! ([`simulate`]); named [`scenario`]s cover a calibration circle, city blocks with stops,
//! a highway stretch and a parking manoeuvre; [`handheld_motion`] gives smooth 3-D motion
//! for orientation filters. [`vehicle_streams`] and [`imu_streams`] run the truth through the
//! sensor crates' forward models (gyro, odometer, compass, accelerometer) with errors from
//! [`VehicleSensorParams`] / [`ImuSensorParams`]. Everything is deterministic for a given seed.
//!
//! ```
//! use truenorth_sim::{RouteBuilder, simulate};
//!
//! let route = RouteBuilder::at_speed(5.0)?.turn(2.0 * std::f64::consts::PI, 10.0)?.build();
//! let truth = simulate(&route, 0.0, 50.0).unwrap();
//! let last = truth.last().unwrap();
//! // One full circle: back where it started, having turned 360°.
//! assert!(last.north_m.hypot(last.east_m) < 1e-6);
//! assert!((last.heading_unwrapped_rad.to_degrees() - 360.0).abs() < 1e-6);
//! # Ok::<(), truenorth_core::Error>(())
//! ```

mod handheld;
mod route;
pub mod scenario;
mod streams;
mod vehicle;

pub use handheld::{HandheldParams, MotionTruth, handheld_motion};
pub use route::{Command, Route, RouteBuilder};
pub use streams::{
    ImuSensorParams, VehicleSensorParams, imu_streams, rotated_soft_iron, vehicle_accel_stream,
    vehicle_streams,
};
pub use vehicle::{MAX_SAMPLES, VehicleTruth, simulate};
