//! Orientation of an IMU: the quaternion filter and the Euler detector of WO 00/36376,
//! the parts the quaternion filter is built from (rest detection, magnetic-disturbance
//! rejection, online hard-iron re-estimation, the σ of its attitude, small-angle rotations)
//! and the gap rule both estimators share, with BROAD's error split to score them.
//! The quaternion filter's per-sample path is generic over the float type (`f64` or
//! `f32`, [`truenorth_core::Real`]).

mod attitude_error;
pub mod attitude_uncertainty;
mod attitude_uncertainty_config;
mod broad_rmse;
mod euler_config;
mod euler_detector;
mod euler_state;
mod gyro_conditioner;
mod hard_iron;
mod mag_reference;
mod min_max;
mod moving_average;
mod quaternion_config;
mod quaternion_filter;
mod quaternion_gains;
mod quaternion_input;
mod quaternion_state;
mod real_checks;
mod rest_detector;
mod rotation;
mod sample_bounds;
mod time_gap;
mod triad;

pub use attitude_error::AttitudeError;
pub use attitude_uncertainty_config::AttitudeUncertaintyConfig;
pub use broad_rmse::{BroadRmse, broad_rmse};
pub use euler_config::{
    CorrectionDefinerConfig, EulerDetectorConfig, EulerVariant, GyroConditioning,
    MAX_DEFINER_WINDOW, StartupField, coefficient_table,
};
pub use euler_detector::EulerDetector;
pub use euler_state::EulerDetectorState;
pub use gyro_conditioner::GyroConditioner;
pub use hard_iron::{HardIronConfig, HardIronEstimator};
pub use mag_reference::{MagReference, MagReferenceConfig};
pub use moving_average::MovingAverage;
pub use quaternion_config::{GyroTiming, QuaternionFilterConfig};
pub use quaternion_filter::QuaternionFilter;
pub use quaternion_state::QuaternionFilterState;
pub use rest_detector::{RestConfig, RestDetector};
pub use time_gap::GapMonitor;
