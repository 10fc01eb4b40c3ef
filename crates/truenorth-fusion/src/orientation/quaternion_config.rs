//! Parameters of the [`crate::QuaternionFilter`] (the derived per-sample gains are computed
//! in the filter from these and the sample interval).

use serde::de::IgnoredAny;
use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result, Validate, check_positive, check_range};

use super::attitude_uncertainty_config::AttitudeUncertaintyConfig;
use super::hard_iron::HardIronConfig;
use super::mag_reference::MagReferenceConfig;
use super::rest_detector::RestConfig;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// What a gyro sample's rate stands for, which decides how it is integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GyroTiming {
    /// The mean rate over the interval that ends at the sample's timestamp: what a digital
    /// MEMS gyro outputs (its decimation filter averages over the output period), and what
    /// Madgwick, Mahony, Fusion and VQF assume. The step uses the sample's own rate.
    IntervalMean,
    /// The instantaneous rate at the timestamp (the convention of `truenorth_core::GyroSample`
    /// and of the simulator): the step uses the mean of the previous and current rate, the
    /// trapezoid rule. On a gyro that reports interval means it lags half a sample.
    Instantaneous,
}

/// Parameters of the [`crate::QuaternionFilter`]. Times in seconds, rates in rad/s.
///
/// Read with serde, every field is optional (its default when absent). A configuration that
/// names `acc_lowpass_s` is refused, with what replaced it: that was the time constant of a
/// first-order low-pass ahead of a correction of time constant `tau_acc_s` (until the
/// filter's state layout 2), and both are now the one second-order low-pass of
/// `tau_acc_s`, so such a file's `tau_acc_s` meant something else.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ConfigFields")]
pub struct QuaternionFilterConfig {
    /// How the gyro's samples are integrated (default [`GyroTiming::IntervalMean`]).
    pub gyro_timing: GyroTiming,
    /// Time constant of the inclination correction, s (default 2): that of the second-order
    /// Butterworth low-pass (cut-off `1/(2π τ)`) the specific force passes in the
    /// almost-inertial frame before it levels the attitude. Chosen on the BROAD trials
    /// (`tests/broad.rs`): 1.5 s is best on the half with most fast rotation, 2.5 s on the
    /// half with most translation, 2 s within 2 % of either's best.
    pub tau_acc_s: f64,
    /// Time constant of the heading correction while the sensor moves, s (default 15).
    pub tau_mag_s: f64,
    /// Time constant of the heading correction while the sensor rests, s (default 5): at
    /// rest the reading has no motion-induced error (no latency against the gyro, no
    /// acceleration in the tilt it is levelled with), so heading error collected during
    /// motion is removed faster.
    pub tau_mag_rest_s: f64,
    /// Time constant of the in-motion bias estimate, s (default 400): long against
    /// `tau_acc_s` so the bias loop cannot ring, and long enough that the body's own
    /// accelerations, which leak into every correction, average out of it.
    pub bias_tau_motion_s: f64,
    /// Time constant of the in-motion bias estimate before any rest has measured the bias,
    /// s (default 60); it moves to `bias_tau_motion_s` as rest time accumulates.
    pub bias_tau_unknown_s: f64,
    /// Rest time after which the bias counts as known, s (default 5).
    pub bias_known_after_rest_s: f64,
    /// Time constant of the bias estimate at rest, s (default 2).
    pub bias_tau_rest_s: f64,
    /// Largest bias the filter may estimate on any axis, rad/s (default 20°/s).
    pub max_bias_rps: f64,
    /// Time after the first sample with fast corrections, s (default 1): the attitude
    /// converges from the first reading before the slow filter takes over.
    pub startup_s: f64,
    /// Rest detection.
    pub rest: RestConfig,
    /// Magnetic-disturbance detection.
    pub mag: MagReferenceConfig,
    /// Online hard-iron re-estimation (a magnet attached to the sensor).
    pub hard_iron: HardIronConfig,
    /// Use the magnetometer when the samples have one (default `true`; `false` gives 6-D).
    pub use_mag: bool,
    /// Initial attitude, body → NED, scalar first; `None` (default) starts from the first
    /// accelerometer (and magnetometer) reading.
    pub initial_attitude: Option<[f64; 4]>,
    /// Longest time between samples the gyro is integrated across, s (default 0.5). Strapdown
    /// holds one rate sample over the step, and a hand-held sensor turning at 1 rad/s with
    /// a 1 Hz bandwidth has changed its rate completely within half a second; after a longer
    /// gap the attitude is taken anew from the accelerometer and magnetometer (status
    /// `gap`). Half a second also makes a millisecond time column read as seconds a gap at
    /// every step for every IMU up to 2 kHz, which the filter refuses as implausible.
    pub max_gap_s: f64,
    /// Propagate the attitude's σ and report it as `sigma_rad` (default `true`); `false`
    /// saves its cost (about a third of an update) and reports none.
    pub sigma: bool,
    /// The sensors' error model behind `sigma_rad`.
    pub uncertainty: AttitudeUncertaintyConfig,
}

impl Default for QuaternionFilterConfig {
    fn default() -> Self {
        Self {
            gyro_timing: GyroTiming::IntervalMean,
            tau_acc_s: 2.0,
            tau_mag_s: 15.0,
            tau_mag_rest_s: 5.0,
            bias_tau_motion_s: 400.0,
            bias_tau_unknown_s: 60.0,
            bias_known_after_rest_s: 5.0,
            bias_tau_rest_s: 2.0,
            max_bias_rps: 20f64.to_radians(),
            startup_s: 1.0,
            rest: RestConfig::default(),
            mag: MagReferenceConfig::default(),
            hard_iron: HardIronConfig::default(),
            use_mag: true,
            initial_attitude: None,
            max_gap_s: 0.5,
            sigma: true,
            uncertainty: AttitudeUncertaintyConfig::default(),
        }
    }
}

/// A [`QuaternionFilterConfig`] as read, before the check for the parameter it no longer has.
#[derive(Deserialize)]
#[serde(default)]
struct ConfigFields {
    gyro_timing: GyroTiming,
    tau_acc_s: f64,
    tau_mag_s: f64,
    tau_mag_rest_s: f64,
    bias_tau_motion_s: f64,
    bias_tau_unknown_s: f64,
    bias_known_after_rest_s: f64,
    bias_tau_rest_s: f64,
    max_bias_rps: f64,
    startup_s: f64,
    rest: RestConfig,
    mag: MagReferenceConfig,
    hard_iron: HardIronConfig,
    use_mag: bool,
    initial_attitude: Option<[f64; 4]>,
    max_gap_s: f64,
    sigma: bool,
    uncertainty: AttitudeUncertaintyConfig,
    /// Any value: the key alone is refused.
    acc_lowpass_s: Option<IgnoredAny>,
}

impl Default for ConfigFields {
    fn default() -> Self {
        let d = QuaternionFilterConfig::default();
        Self {
            gyro_timing: d.gyro_timing,
            tau_acc_s: d.tau_acc_s,
            tau_mag_s: d.tau_mag_s,
            tau_mag_rest_s: d.tau_mag_rest_s,
            bias_tau_motion_s: d.bias_tau_motion_s,
            bias_tau_unknown_s: d.bias_tau_unknown_s,
            bias_known_after_rest_s: d.bias_known_after_rest_s,
            bias_tau_rest_s: d.bias_tau_rest_s,
            max_bias_rps: d.max_bias_rps,
            startup_s: d.startup_s,
            rest: d.rest,
            mag: d.mag,
            hard_iron: d.hard_iron,
            use_mag: d.use_mag,
            initial_attitude: d.initial_attitude,
            max_gap_s: d.max_gap_s,
            sigma: d.sigma,
            uncertainty: d.uncertainty,
            acc_lowpass_s: None,
        }
    }
}

impl TryFrom<ConfigFields> for QuaternionFilterConfig {
    type Error = Error;

    fn try_from(f: ConfigFields) -> Result<Self> {
        if f.acc_lowpass_s.is_some() {
            return Err(Error::Unsupported {
                reason: "acc_lowpass_s is no longer a parameter of the quaternion filter: the \
                         inclination's low-pass is one second-order Butterworth filter of time \
                         constant tau_acc_s (default 2 s), which also replaces the correction \
                         tau_acc_s used to name. Remove acc_lowpass_s and set tau_acc_s anew \
                         (the same lag behind a steady drift as the old pair: (acc_lowpass_s + \
                         tau_acc_s)/√2)",
            });
        }
        Ok(Self {
            gyro_timing: f.gyro_timing,
            tau_acc_s: f.tau_acc_s,
            tau_mag_s: f.tau_mag_s,
            tau_mag_rest_s: f.tau_mag_rest_s,
            bias_tau_motion_s: f.bias_tau_motion_s,
            bias_tau_unknown_s: f.bias_tau_unknown_s,
            bias_known_after_rest_s: f.bias_known_after_rest_s,
            bias_tau_rest_s: f.bias_tau_rest_s,
            max_bias_rps: f.max_bias_rps,
            startup_s: f.startup_s,
            rest: f.rest,
            mag: f.mag,
            hard_iron: f.hard_iron,
            use_mag: f.use_mag,
            initial_attitude: f.initial_attitude,
            max_gap_s: f.max_gap_s,
            sigma: f.sigma,
            uncertainty: f.uncertainty,
        })
    }
}

impl Validate for QuaternionFilterConfig {
    fn validate(&self) -> Result<()> {
        check_positive("tau_acc_s", self.tau_acc_s)?;
        check_positive("tau_mag_s", self.tau_mag_s)?;
        check_positive("tau_mag_rest_s", self.tau_mag_rest_s)?;
        check_range(
            "bias_tau_motion_s",
            self.bias_tau_motion_s,
            2.0 * self.tau_acc_s,
            1e9,
        )?;
        check_range(
            "bias_tau_unknown_s",
            self.bias_tau_unknown_s,
            2.0 * self.tau_acc_s,
            1e9,
        )?;
        check_positive("bias_known_after_rest_s", self.bias_known_after_rest_s)?;
        check_positive("bias_tau_rest_s", self.bias_tau_rest_s)?;
        check_range("max_bias_rps", self.max_bias_rps, 0.0, 10.0)?;
        check_range("startup_s", self.startup_s, 0.0, 1e9)?;
        self.rest.validate()?;
        self.mag.validate()?;
        self.hard_iron.validate()?;
        super::time_gap::check_max_gap(self.max_gap_s)?;
        self.uncertainty.validate()?;
        if let Some(q) = self.initial_attitude {
            for v in q {
                check_range("initial_attitude component", v, -1e3, 1e3)?;
            }
            let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
            check_range("initial_attitude norm", n, 1e-6, 1e3)?;
        }
        Ok(())
    }
}
