//! # truenorth-sim
//!
//! Trajectories and sensor streams with ground truth, for tests, benches and the demo.
//! A route of driving commands is integrated by a rear-axle kinematic model
//! ([`simulate`]); named [`scenario`]s cover a calibration circle, city blocks with stops,
//! a highway stretch and a parking manoeuvre; [`handheld_motion`] gives smooth 3-D motion
//! for orientation filters; [`protocol_shots`] gives the few-shot calibration protocols of a
//! hand-held pointing instrument ([`FewShotInstrument`]). [`vehicle_streams`] and [`imu_streams`] run the truth through the
//! sensor crates' forward models (gyro, odometer, compass, accelerometer) with errors from
//! [`VehicleSensorParams`] / [`ImuSensorParams`]. [`LogDrive`] gives drives as real logs come
//! ([`log_drive`]): in motion from the first row, each sensor on rows of its own with its
//! latency, wheel data filtered and quantised by its controller, the sensor sets real
//! vehicles carry (a CAN vehicle speed and yaw rate, two or four wheel speeds, a gyro and a
//! compass without wheels, ...) and a GNSS receiver's fixes, as a `DRIVE.csv` if wanted.
//! Everything is deterministic for a given seed.
//! Gyro samples are the instantaneous rate at their timestamp (the convention of
//! [`truenorth_core::GyroSample`]), so a trapezoid integrator tracks the heading to second
//! order in the sample interval.
//!
//! ```
//! use truenorth_sim::{RouteBuilder, VehicleSensorParams, simulate, vehicle_streams};
//!
//! let route = RouteBuilder::at_speed(5.0)?.turn(2.0 * std::f64::consts::PI, 10.0)?.build();
//! let truth = simulate(&route, 0.0, 50.0)?;
//! let last = truth.last().unwrap();
//! // One full circle: back where it started, having turned 360°.
//! assert!(last.north_m.hypot(last.east_m) < 1e-6);
//! assert!((last.heading_unwrapped_rad.to_degrees() - 360.0).abs() < 1e-6);
//!
//! // The sensors of a typical installation, one sample per truth sample.
//! let samples = vehicle_streams(&truth, &VehicleSensorParams::typical(), 7)?;
//! assert_eq!(samples.len(), truth.len());
//! assert!(samples.iter().all(|s| s.gyr_z_rps.is_some() && s.mag.is_some()));
//! # Ok::<(), truenorth_core::Error>(())
//! ```

mod baseline;
pub mod consistency;
mod draw;
mod drive;
mod drive_score;
mod few_shot;
mod handheld;
pub mod log_drive;
mod range_drive;
mod range_route;
mod route;
pub mod scenario;
pub mod shared_data;
mod streams;
mod track_fit;
mod vehicle;
mod vehicle_kind;

pub use baseline::{gyro_wheels_final_error_pct, gyro_wheels_final_position};
pub use consistency::{CHI2_2DOF_3SIGMA, Consistency, Normalised};
pub use drive::{DriveSpec, DriveWheels, SimulatedDrive};
pub use drive_score::DriveScore;
pub use few_shot::{
    FewShotInstrument, Shot, pointing_ned, protocol_shots, random_attitude, rolled_run,
};
pub use handheld::{HandheldParams, MotionTruth, handheld_motion};
pub use log_drive::{
    Canyons, Clock, CompassConfig, Episodes, FixCondition, GnssConfig, GnssErrors, GnssFix,
    GnssTruth, Habit, Jump, LateFixes, LogDrive, LogDriveConfig, LogErrors, LogRow, Measured,
    MotionConfig, Odometry, OdometryReading, Origin, Rests, RobotConfig, RouteShape, RowLayout,
    SensorSet, SensorTiming, SkidGround, SkidSteerConfig, Span, TiltConfig, TiltErrors,
    TimingConfig, WheelConfig, YawRateConfig, YawRateErrors, drive_csv, vehicle_samples,
};
pub use range_drive::{Fitted, RangeDrive, RangeSpec, SensorRates};
pub use route::{Command, Route, RouteBuilder};
pub use streams::{
    ImuSensorParams, VehicleSensorParams, imu_streams, rotated_soft_iron, vehicle_accel_stream,
    vehicle_streams, vehicle_streams_disturbed,
};
pub use track_fit::rotated_track_errors;
pub use truenorth_geomag::LocalTangentPlane;
pub use vehicle::{MAX_SAMPLES, VehicleTruth, simulate, simulate_at};
pub use vehicle_kind::{RangeVehicle, Slip, SlipProcess, VehicleKind};

/// The code blocks of the crate's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
