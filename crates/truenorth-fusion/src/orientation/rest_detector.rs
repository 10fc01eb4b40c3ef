//! Rest detection: the sensor is at rest when its gyro and accelerometer readings stay
//! close to their own recent means for a minimum time and, when a magnetometer is present,
//! the mean field has not turned meanwhile.
//!
//! Gyro and accelerometer alone cannot tell a constant bias from a steady rotation about
//! the vertical (both give a constant rate and a constant specific force); the field's
//! direction can, so it is tested as a turn of its running mean over the still period
//! rather than sample by sample (single readings of a low-cost magnetometer scatter by
//! several percent; BROAD's trials show up to 9 % at rest).
//!
//! Testing deviations from a running mean rather than the size of the rate itself means a
//! gyro with a large bias is still recognised as resting (a test on |ω| would have to clip
//! the bias it can learn, as VQF's 2°/s limit does; Laidig & Seel, *VQF*, Information Fusion
//! 91, 2023, §IV-B uses the deviation from a low-pass mean for the same reason).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Real, Result, Validate, check_positive, check_range};

use super::min_max::at_most;
use super::real_checks::{check_finite3_in, check_range_in};

/// Thresholds of the rest detector (derived values live in [`RestDetector`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RestConfig {
    /// Largest deviation of the gyro from its running mean, rad/s (default 2°/s).
    pub gyro_dev_rps: f64,
    /// Largest deviation of the accelerometer from its running mean, m/s² (default 0.5).
    pub acc_dev_mps2: f64,
    /// Largest turn of the running mean of the field over the still period, rad (default
    /// 2°): a steady 5°/s rotation turns it 7.5° before `min_time_s` has passed.
    pub mag_turn_rad: f64,
    /// Time the deviations must stay small before the sensor counts as at rest, s
    /// (default 1.5).
    pub min_time_s: f64,
    /// Time constant of the running means, s (default 0.5).
    pub mean_tau_s: f64,
}

impl Default for RestConfig {
    fn default() -> Self {
        Self {
            gyro_dev_rps: 2f64.to_radians(),
            acc_dev_mps2: 0.5,
            mag_turn_rad: 2f64.to_radians(),
            min_time_s: 1.5,
            mean_tau_s: 0.5,
        }
    }
}

impl Validate for RestConfig {
    /// Every threshold and time constant positive, the minimum time ≥ 0.
    fn validate(&self) -> Result<()> {
        check_positive("rest.gyro_dev_rps", self.gyro_dev_rps)?;
        check_positive("rest.acc_dev_mps2", self.acc_dev_mps2)?;
        check_positive("rest.mag_turn_rad", self.mag_turn_rad)?;
        check_range("rest.min_time_s", self.min_time_s, 0.0, 1e9)?;
        check_positive("rest.mean_tau_s", self.mean_tau_s)?;
        Ok(())
    }
}

/// The thresholds of a [`RestConfig`] in the detector's float type, as [`RestDetector`]
/// compares with them: converted once by the filter that owns the detector, not per sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RestThresholds<T> {
    gyro_dev2: T,
    acc_dev2: T,
    /// `sin²` of the largest turn of the field (at most 1.5 rad, within a quarter turn).
    sin2_turn: T,
    min_time_s: T,
    /// `1/mean_tau_s`, 1/s.
    inv_mean_tau: T,
}

impl<T: Real> RestThresholds<T> {
    pub(crate) fn of(config: &RestConfig) -> Self {
        let (g, a) = (T::of(config.gyro_dev_rps), T::of(config.acc_dev_mps2));
        let sin = T::of(config.mag_turn_rad).min(T::of(1.5)).sin();
        Self {
            gyro_dev2: g * g,
            acc_dev2: a * a,
            sin2_turn: sin * sin,
            min_time_s: T::of(config.min_time_s),
            inv_mean_tau: T::of(1.0 / config.mean_tau_s),
        }
    }
}

/// Running means and the time the sensor has looked still, in the float type `T` (the
/// thresholds stay `f64`, converted for each update; the filter converts them once).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
// `Real` includes serde's bounds on `T`.
#[serde(bound = "")]
pub struct RestDetector<T: Real = f64> {
    config: RestConfig,
    gyr_mean: Vector3<T>,
    acc_mean: Vector3<T>,
    mag_mean: Option<Vector3<T>>,
    mag_at_start: Option<Vector3<T>>,
    still_s: T,
    primed: bool,
    /// The running means' gain for the last interval (recomputed when it changes).
    gain: (T, T),
}

impl RestDetector {
    /// A detector with the given thresholds, refused when they are invalid.
    pub fn new(config: RestConfig) -> Result<Self> {
        Self::with_precision(config)
    }
}

impl<T: Real> RestDetector<T> {
    /// As [`RestDetector::new`], computing in `T` (`RestDetector::<f32>::with_precision(config)`).
    pub fn with_precision(config: RestConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::with_config(config))
    }

    /// A detector for thresholds already validated (by the filter's config).
    pub(crate) fn with_config(config: RestConfig) -> Self {
        Self {
            config,
            gyr_mean: Vector3::zeros(),
            acc_mean: Vector3::zeros(),
            mag_mean: None,
            mag_at_start: None,
            still_s: T::zero(),
            primed: false,
            gain: (T::zero(), T::zero()),
        }
    }

    /// Forgets everything seen; the thresholds stay.
    pub fn reset(&mut self) {
        *self = Self::with_config(self.config);
    }

    /// Takes one sample (raw gyro, accelerometer, optional magnetometer) `dt_s` after the
    /// previous one and says whether the sensor is at rest.
    pub fn update(
        &mut self,
        gyr: &Vector3<T>,
        acc: &Vector3<T>,
        mag: Option<&Vector3<T>>,
        dt_s: T,
    ) -> bool {
        self.update_with(&RestThresholds::of(&self.config), gyr, acc, mag, dt_s)
    }

    /// [`Self::update`] with the thresholds already converted (`th` of this detector's
    /// configuration).
    pub(crate) fn update_with(
        &mut self,
        th: &RestThresholds<T>,
        gyr: &Vector3<T>,
        acc: &Vector3<T>,
        mag: Option<&Vector3<T>>,
        dt_s: T,
    ) -> bool {
        if !self.primed {
            self.gyr_mean = *gyr;
            self.acc_mean = *acc;
            self.mag_mean = mag.copied();
            self.primed = true;
            return false;
        }
        if self.gain.0 != dt_s {
            self.gain = (dt_s, at_most(dt_s * th.inv_mean_tau, T::one()));
        }
        let k = self.gain.1;
        self.gyr_mean += (gyr - self.gyr_mean) * k;
        self.acc_mean += (acc - self.acc_mean) * k;
        let mut still = (gyr - self.gyr_mean).norm_squared() < th.gyro_dev2
            && (acc - self.acc_mean).norm_squared() < th.acc_dev2;
        match (mag, self.mag_mean.as_mut()) {
            (Some(m), Some(mean)) => *mean += (m - *mean) * k,
            (Some(m), None) => self.mag_mean = Some(*m),
            _ => {}
        }
        if still && let (Some(start), Some(mean)) = (self.mag_at_start, self.mag_mean) {
            // angle < θ ⇔ dot > 0 and |a × b|² < sin²θ |a|² |b|² (θ < 90°): no arccosine.
            still = start.dot(&mean) > T::zero()
                && start.cross(&mean).norm_squared()
                    < th.sin2_turn * start.norm_squared() * mean.norm_squared();
        }
        if still {
            if self.still_s == T::zero() {
                self.mag_at_start = self.mag_mean;
            }
            self.still_s += dt_s;
        } else {
            self.still_s = T::zero();
            self.mag_at_start = None;
        }
        self.still_s >= th.min_time_s
    }

    /// Running mean of the raw gyro, rad/s: the bias while at rest.
    pub fn gyro_mean(&self) -> Vector3<T> {
        self.gyr_mean
    }

    /// Checks a restored detector against the thresholds `config` of its filter: the same
    /// thresholds, finite means, a still time ≥ 0.
    pub(crate) fn check(&self, config: &RestConfig) -> Result<()> {
        if self.config != *config {
            return Err(Error::InvalidSnapshot {
                reason: "the rest detector's thresholds differ from the filter's",
            });
        }
        check_finite3_in("rest.gyr_mean", &self.gyr_mean)?;
        check_finite3_in("rest.acc_mean", &self.acc_mean)?;
        for m in [self.mag_mean, self.mag_at_start].iter().flatten() {
            check_finite3_in("rest.mag_mean", m)?;
        }
        check_range_in("rest.still_s", self.still_s, 0.0, f64::MAX)?;
        check_range_in("rest.gain", self.gain.1, 0.0, 1.0)?;
        check_range_in("rest.gain interval", self.gain.0, 0.0, f64::MAX)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn constant_readings_with_any_bias_are_rest(
            bias in proptest::array::uniform3(-1.0f64..1.0),
            acc in proptest::array::uniform3(-10.0f64..10.0),
            mag in proptest::array::uniform3(-50.0f64..50.0),
        ) {
            let cfg = RestConfig::default();
            let mut r = RestDetector::new(cfg).unwrap();
            let (g, a, m) = (Vector3::from(bias), Vector3::from(acc), Vector3::from(mag));
            let mut rest = false;
            for _ in 0..((cfg.min_time_s / 0.01) as usize + 2) {
                rest = r.update(&g, &a, Some(&m), 0.01);
            }
            prop_assert!(rest);
            prop_assert!((r.gyro_mean() - g).norm() < 1e-12);
        }

        #[test]
        fn a_steady_turn_is_not_rest(rate_dps in 5.0f64..90.0) {
            // Constant gyro and specific force (a turn about the vertical), but the field's
            // direction turns: the magnetometer tells it from a bias.
            let cfg = RestConfig::default();
            let mut r = RestDetector::new(cfg).unwrap();
            let g = Vector3::new(0.0, 0.0, rate_dps.to_radians());
            let a = Vector3::new(0.0, 0.0, -9.81);
            for k in 0..300 {
                let psi = rate_dps.to_radians() * 0.01 * k as f64;
                let m = Vector3::new(20.0 * psi.cos(), -20.0 * psi.sin(), 40.0);
                prop_assert!(!r.update(&g, &a, Some(&m), 0.01), "rest at k = {k}");
            }
        }
    }
}
