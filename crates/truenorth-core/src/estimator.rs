//! Estimators: IMU samples → attitude, and vehicle streams → heading and position.
//!
//! Both kinds return a full estimate from every `update` — the state, its uncertainty and
//! what the estimator currently believes about its sensors (biases, rest, disturbances) —
//! so that a caller can log, gate or fuse it without reaching into the estimator.

use nalgebra::{Matrix2, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::{ImuSample, MagneticHeading, Result, VehicleSample};

/// What an orientation estimator currently believes about its inputs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct AttitudeStatus {
    /// The sensor is judged to be at rest (gyro bias is being learned from it).
    pub at_rest: bool,
    /// The accelerometer was used to correct inclination at this sample (not rejected as
    /// disturbed by acceleration).
    pub accel_used: bool,
    /// The magnetometer was used to correct heading at this sample.
    pub mag_used: bool,
    /// The magnetic field is judged disturbed (norm or dip off the learned values); heading
    /// runs on the gyro alone meanwhile.
    pub mag_disturbed: bool,
    /// The estimator is re-estimating the magnetometer's hard iron.
    pub mag_calibrating: bool,
    /// The time since the previous sample was longer than the estimator can bridge with
    /// the gyro (its `max_gap_s`): the attitude was taken anew from this sample's
    /// accelerometer (and magnetometer) and its σ widened.
    #[serde(default)]
    pub gap: bool,
}

/// An orientation estimate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AttitudeEstimate {
    /// Timestamp of the last sample, seconds.
    pub t_s: f64,
    /// Best attitude, body → reference (NED), using the magnetometer when one is present
    /// and trusted (9-D).
    pub attitude: UnitQuaternion<f64>,
    /// Attitude from gyro and accelerometer only (6-D): inclination as good as `attitude`,
    /// heading relative to the start and drifting with the uncorrected gyro bias. `None`
    /// from an estimator that keeps no such attitude apart from `attitude` (the Euler
    /// detector of WO 00/36376 corrects heading inside the same angles).
    pub attitude_6d: Option<UnitQuaternion<f64>>,
    /// Estimated gyro bias, rad/s, body axes (subtracted from the raw rates).
    pub gyro_bias_rps: Vector3<f64>,
    /// One standard deviation of the attitude error about the reference x, y, z axes
    /// (north, east, down: the error rotation `attitude ⊗ truth⁻¹` as a rotation vector),
    /// radians; `None` when the estimator does not model it. Without a magnetometer the
    /// heading is relative to the start and its σ is the drift since the start.
    pub sigma_rad: Option<Vector3<f64>>,
    /// Rest and disturbance flags.
    pub status: AttitudeStatus,
}

impl AttitudeEstimate {
    /// The estimate before any sample: the given attitude (level, heading north unless the
    /// estimator was given one), as its 6-D attitude too since no heading correction has
    /// been made, no bias.
    pub fn initial(attitude: UnitQuaternion<f64>) -> Self {
        Self {
            t_s: f64::NAN,
            attitude,
            attitude_6d: Some(attitude),
            gyro_bias_rps: Vector3::zeros(),
            sigma_rad: None,
            status: AttitudeStatus::default(),
        }
    }
}

/// An orientation estimator. Every seed method and modern filter implements it, so tests,
/// benches, the CLI and the evaluation harness take any of them.
pub trait OrientationEstimator {
    /// Takes one sample (dt from its timestamp; a non-increasing timestamp is an error and
    /// changes nothing) and returns the new estimate.
    fn update(&mut self, sample: &ImuSample) -> Result<AttitudeEstimate>;

    /// The current estimate, without changing anything.
    fn estimate(&self) -> AttitudeEstimate;

    /// Returns to the initial state.
    fn reset(&mut self);
}

/// What a vehicle heading estimator currently believes about its heading and sensors.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct NavStatus {
    /// The heading is referred to magnetic north. While false (no calibrated compass yet, or
    /// none fitted) it is the heading change since the start, and the track is drawn as if
    /// the vehicle had started facing north.
    pub heading_absolute: bool,
    /// The vehicle is judged to be standing still (gyro bias is being learned from it).
    pub at_rest: bool,
    /// A compass calibration is available.
    pub compass_calibrated: bool,
    /// A compass reading corrected the heading at this sample.
    pub compass_used: bool,
    /// The compass is judged disturbed (its readings disagree with the dead-reckoned
    /// heading or its field magnitude is off); heading runs on the gyro or wheels meanwhile.
    pub compass_disturbed: bool,
    /// Wheel readings have been seen, so the position is dead-reckoned. While false (no
    /// wheels fitted, or none read yet) `north_m` and `east_m` stay 0 and the position
    /// covariance is infinite: the position is absent, not zero.
    #[serde(default)]
    pub position_known: bool,
    /// A sensor's readings stopped for longer than the estimator can bridge, and resumed at
    /// this sample: what could not be followed across the gap was widened (heading, the
    /// track, the gyro bias) rather than guessed.
    #[serde(default)]
    pub gap: bool,
    /// The fused estimate departed from plain integration (the raw gyro less its rest bias,
    /// along the odometry) by more than both their uncertainties allow, and fell back to it
    /// at this sample: a learned sensor error was wrong, and was forgotten.
    #[serde(default)]
    pub fell_back: bool,
    /// A satellite fix corrected the estimate at this sample.
    #[serde(default)]
    pub gnss_used: bool,
    /// The track is in the local tangent plane at the first satellite fix and the heading
    /// was referred to true north by the fixes (the heading is still given from magnetic
    /// north: the estimator says the declination it used).
    #[serde(default)]
    pub gnss_frame: bool,
    /// The learned sensor errors the data have not yet told apart.
    #[serde(default)]
    pub unobserved: Unobserved,
}

/// Which of a vehicle estimator's learned sensor errors the data have not yet determined:
/// true where a state's uncertainty is still more than half its prior's, or where it is
/// so strongly correlated with another that the data fix only their combination (a gyro
/// bias and a wheel-size difference on a steady circle turn the heading alike).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct Unobserved {
    /// Gyro bias.
    pub gyro_bias: bool,
    /// Gyro gain for right turns.
    pub gyro_gain_right: bool,
    /// Gyro gain for left turns.
    pub gyro_gain_left: bool,
    /// Difference of the two wheels' scales.
    pub wheel_diff: bool,
    /// The wheels' effective track.
    pub track_scale: bool,
    /// The speed coefficient of the wheels' difference.
    pub speed_coeff: bool,
    /// The odometer's mean scale (learned only from satellite fixes).
    pub wheel_scale: bool,
    /// How far the wheels' readings trail the gyro's (learned from turns, with a gyro).
    pub wheel_lag: bool,
}

impl Unobserved {
    /// Whether any state is not yet determined.
    pub fn any(&self) -> bool {
        self.gyro_bias
            || self.gyro_gain_right
            || self.gyro_gain_left
            || self.wheel_diff
            || self.track_scale
            || self.speed_coeff
            || self.wheel_scale
            || self.wheel_lag
    }
}

/// Position, heading and speed of a land vehicle relative to its start point, with their
/// uncertainty.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NavEstimate {
    /// Timestamp, seconds.
    #[serde(with = "crate::extended_float::scalar")]
    pub t_s: f64,
    /// Northward displacement from the start, metres.
    pub north_m: f64,
    /// Eastward displacement from the start, metres.
    pub east_m: f64,
    /// Heading from magnetic north (add the declination for true north).
    pub heading: MagneticHeading,
    /// One standard deviation of the heading, radians: of the heading from north when
    /// `status.heading_absolute`, otherwise of the heading change since the start.
    pub heading_sigma_rad: f64,
    /// Covariance of (north, east), m² (infinite while `status.position_known` is false).
    #[serde(with = "crate::extended_float::matrix2")]
    pub position_cov_m2: Matrix2<f64>,
    /// Speed along the track, m/s.
    pub speed_mps: f64,
    /// Distance travelled since the start, metres.
    pub distance_m: f64,
    /// Heading reference, rest and compass flags.
    #[serde(default)]
    pub status: NavStatus,
}

impl NavEstimate {
    /// At the start point with the given heading and its uncertainty, at rest.
    pub fn at_start(t_s: f64, heading: MagneticHeading, heading_sigma_rad: f64) -> Self {
        Self {
            t_s,
            north_m: 0.0,
            east_m: 0.0,
            heading,
            heading_sigma_rad,
            position_cov_m2: Matrix2::zeros(),
            speed_mps: 0.0,
            distance_m: 0.0,
            status: NavStatus::default(),
        }
    }
}

/// A vehicle heading / dead-reckoning estimator.
pub trait HeadingEstimator {
    /// Takes one sample (a non-increasing timestamp is an error and changes nothing) and
    /// returns the new estimate.
    fn update(&mut self, sample: &VehicleSample) -> Result<NavEstimate>;

    /// The current estimate, without changing anything.
    fn estimate(&self) -> NavEstimate;

    /// Returns to the initial state.
    fn reset(&mut self);
}
