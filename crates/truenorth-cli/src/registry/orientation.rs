//! Orientation methods by name.

use truenorth::core::{OrientationEstimator, Result};
use truenorth::fusion::{
    EulerDetector, EulerDetectorConfig, GyroTiming, QuaternionFilter, QuaternionFilterConfig,
};

/// An orientation method ready to run.
pub type Orientation = dyn OrientationEstimator;

/// Orientation methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum OrientationMethod {
    /// Quaternion filter: gyro strapdown, inclination from the low-passed specific force,
    /// heading from the magnetometer with disturbance rejection and online hard-iron
    /// re-estimation, gyro bias at rest and in motion.
    Quaternion,
    /// The Euler orientation angle detector of WO 00/36376 (Euler-rate integration,
    /// static tilt and tilt-compensated yaw, correction definer, coefficient table).
    EulerDetector,
}

/// What a gyro sample's rate stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Timing {
    /// The mean rate over the interval ending at the sample (digital MEMS gyros).
    IntervalMean,
    /// The instantaneous rate at the sample (integrated by the trapezoid rule).
    Instantaneous,
}

impl OrientationMethod {
    /// The method with the magnetometer used or not and the gyro timing (the quaternion
    /// filter's; the Euler detector integrates Euler rates its own way), on magnetic north.
    pub fn estimator(self, use_mag: bool, timing: Timing) -> Result<Box<Orientation>> {
        Ok(match self {
            Self::Quaternion => Box::new(QuaternionFilter::new(QuaternionFilterConfig {
                use_mag,
                gyro_timing: match timing {
                    Timing::IntervalMean => GyroTiming::IntervalMean,
                    Timing::Instantaneous => GyroTiming::Instantaneous,
                },
                ..Default::default()
            })?),
            Self::EulerDetector => Box::new(EulerDetector::new(EulerDetectorConfig {
                use_mag,
                ..Default::default()
            })?),
        })
    }
}
