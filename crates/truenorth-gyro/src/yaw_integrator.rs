//! Yaw-rate integration: calibrated `gyr_z` → heading change per step.
//!
//! `dt` comes from the samples' timestamps (never from a nominal rate), so dropped samples
//! and jitter do not bias the heading; a timestamp that does not increase is refused.

use serde::{Deserialize, Serialize};
use truenorth_core::{
    Calibration, GyroSample, RelativeHeadingSource, RelativeStep, Result, TimeStep, Validate,
    check_finite, check_finite3,
};

use crate::{GyroCalibration, YawIncrement};

/// Settings of a [`YawIntegrator`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct YawIntegratorConfig {
    /// Applied to every raw `gyr_z` before integrating. Default
    /// [`GyroCalibration::IDENTITY`] (the raw rate is taken as calibrated).
    pub calibration: GyroCalibration,
}

impl Validate for YawIntegratorConfig {
    /// The calibration's zero finite and gains positive.
    fn validate(&self) -> Result<()> {
        self.calibration.validate()
    }
}

/// Integrates a yaw gyro into heading change, positive for a right turn.
///
/// Each sample is the instantaneous rate at its timestamp (the convention of
/// [`GyroSample`], which the simulator follows too). Between two samples the rate is taken to
/// vary linearly, so the step is the trapezoid `(ω_prev + ω_now)/2 · dt` ([`YawIncrement`]):
/// exact for a constant or linearly changing rate, with an error of `dt³/12 · |ω̈|` per step
/// otherwise, where the rectangle rule on either end point would be off by `dt²/2 · |ω̇|`
/// per step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YawIntegrator {
    config: YawIntegratorConfig,
    clock: TimeStep,
    last_rate_rps: Option<f64>,
    heading_rad: f64,
}

impl YawIntegrator {
    /// An integrator with a validated `config`, heading change zero, no sample seen.
    pub fn new(config: YawIntegratorConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            config,
            clock: TimeStep::new(),
            last_rate_rps: None,
            heading_rad: 0.0,
        })
    }

    /// The settings in use.
    pub fn config(&self) -> &YawIntegratorConfig {
        &self.config
    }

    /// The calibration in use.
    pub fn calibration(&self) -> &GyroCalibration {
        &self.config.calibration
    }

    /// Replaces the calibration (e.g. after a calibrator produced a better one). Takes effect
    /// from the next sample; an invalid calibration is refused and the old one kept.
    pub fn set_calibration(&mut self, calibration: GyroCalibration) -> Result<()> {
        calibration.validate()?;
        self.config.calibration = calibration;
        Ok(())
    }

    /// Heading change accumulated since construction or [`RelativeHeadingSource::reset`],
    /// radians, not wrapped (two right turns in a circle give 4π).
    pub fn heading_rad(&self) -> f64 {
        self.heading_rad
    }

    /// Feeds one raw yaw-rate sample (`gyr_z`, rad/s, with the gyro's own bias and scale) at
    /// time `t_s` and returns the step since the previous sample (`None` for the first; the
    /// step's `distance_m` is always `None`). On error (non-finite value, non-increasing
    /// time) nothing changes, so the caller may skip the sample and go on.
    pub fn push_yaw_rate(&mut self, t_s: f64, gyr_z_rps: f64) -> Result<Option<RelativeStep>> {
        let rate_rps = self.config.calibration.apply(&gyr_z_rps)?;
        let mut clock = self.clock;
        let dt_s = clock.dt_s(t_s)?;
        let step = match (dt_s, self.last_rate_rps) {
            (Some(dt_s), Some(prev)) => Some(RelativeStep {
                dt_s,
                heading_change_rad: check_finite(
                    "gyro heading change (rates too large)",
                    YawIncrement::new(prev, rate_rps, dt_s).angle_rad(),
                )?,
                distance_m: None,
            }),
            _ => None,
        };
        self.clock = clock;
        self.last_rate_rps = Some(rate_rps);
        if let Some(s) = step {
            self.heading_rad += s.heading_change_rad;
        }
        Ok(step)
    }
}

impl RelativeHeadingSource for YawIntegrator {
    type Sample = GyroSample;

    /// Integrates `gyr_rps.z` (a vehicle's yaw axis); see [`YawIntegrator::push_yaw_rate`].
    /// The x and y rates are not used but must be finite: a sample with a non-finite
    /// component is refused as a whole.
    fn step(&mut self, sample: &GyroSample) -> Result<Option<RelativeStep>> {
        check_finite3("gyro sample gyr_rps", &sample.gyr_rps)?;
        self.push_yaw_rate(sample.t_s, sample.gyr_rps.z)
    }

    fn reset(&mut self) {
        self.clock.reset();
        self.last_rate_rps = None;
        self.heading_rad = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{GyroAxisModel, GyroAxisParams, RateTruth};
    use nalgebra::Vector3;
    use proptest::prelude::*;
    use truenorth_core::{Error, SensorModel};

    fn identity() -> YawIntegrator {
        YawIntegrator::new(YawIntegratorConfig::default()).unwrap()
    }

    proptest! {
        /// truth → gyro model (bias, asymmetric scale, temperature) → integrator with the
        /// model's true inverse gives back the true heading change.
        #[test]
        fn model_then_true_calibration_integrates_to_the_truth(
            bias in -0.1f64..0.1, sp in -0.2f64..0.2, sn in -0.2f64..0.2,
            temp in -20.0f64..60.0, kt in -1e-3f64..1e-3,
            steps in proptest::collection::vec((1e-3f64..0.5, -2.0f64..2.0), 1..100),
        ) {
            let p = GyroAxisParams {
                bias_rps: bias, scale_error_pos: sp, scale_error_neg: sn,
                temp_coeff_rps_per_k: kt, ..GyroAxisParams::PERFECT
            };
            let m = GyroAxisModel::new(p).unwrap();
            let config = YawIntegratorConfig { calibration: m.true_calibration(temp).unwrap() };
            let mut yaw = YawIntegrator::new(config).unwrap();
            let mut t = 10.0;
            let mut prev_rate = 0.3;
            let first = m.ideal(&RateTruth { rate_rps: prev_rate, temp_c: temp }).unwrap();
            prop_assert_eq!(yaw.push_yaw_rate(t, first).unwrap(), None);
            let mut truth = 0.0;
            for (dt, rate) in steps {
                t += dt;
                truth += 0.5 * (prev_rate + rate) * dt;
                prev_rate = rate;
                let raw = m.ideal(&RateTruth { rate_rps: rate, temp_c: temp }).unwrap();
                let sample = GyroSample { t_s: t, gyr_rps: Vector3::new(9.0, 9.0, raw) };
                let step = yaw.step(&sample).unwrap().unwrap();
                prop_assert!((step.dt_s - dt).abs() < 1e-9);
                prop_assert_eq!(step.distance_m, None);
            }
            prop_assert!((yaw.heading_rad() - truth).abs() < 1e-9 * (1.0 + truth.abs()),
                "{} vs {truth}", yaw.heading_rad());
        }

        /// Without calibration the same biased gyro drifts by bias·time: the round trip above
        /// is not passing by accident.
        #[test]
        fn an_uncalibrated_biased_gyro_drifts(bias in 0.01f64..0.1, dur in 1.0f64..100.0) {
            let mut yaw = identity();
            yaw.push_yaw_rate(0.0, bias).unwrap();
            yaw.push_yaw_rate(dur, bias).unwrap();
            prop_assert!((yaw.heading_rad() - bias * dur).abs() < 1e-9);
        }

        #[test]
        fn bad_samples_are_typed_errors_and_change_nothing(
            t in proptest::num::f64::ANY, w in proptest::num::f64::ANY,
            x in proptest::num::f64::ANY,
        ) {
            let mut yaw = identity();
            yaw.push_yaw_rate(0.0, 0.1).unwrap();
            yaw.push_yaw_rate(1.0, 0.1).unwrap();
            let before = yaw;
            // Refused when an input is not finite, time does not increase, or the step
            // overflows.
            let fits = (0.5 * (0.1 + w) * (t - 1.0)).is_finite();
            let ok = t.is_finite() && t > 1.0 && w.is_finite() && fits;
            let r = yaw.push_yaw_rate(t, w);
            prop_assert_eq!(r.is_ok(), ok);
            if !ok {
                prop_assert_eq!(yaw, before);
            }
            if w.is_finite() && t.is_finite() && t <= 1.0 {
                let is_time_error = matches!(r, Err(Error::NonIncreasingTime { .. }));
                prop_assert!(is_time_error);
            }
            if !w.is_finite() || !t.is_finite() {
                let is_non_finite = matches!(r, Err(Error::NonFinite { .. }));
                prop_assert!(is_non_finite);
            }
            // Through the trait, a non-finite x (unused) refuses the sample as well.
            let mut yaw = before;
            let r = yaw.step(&GyroSample { t_s: 2.0, gyr_rps: Vector3::new(x, 0.0, 0.1) });
            prop_assert_eq!(r.is_ok(), x.is_finite());
            if r.is_err() {
                let is_non_finite = matches!(r, Err(Error::NonFinite { .. }));
                prop_assert!(is_non_finite);
                prop_assert_eq!(yaw, before);
            }
        }

        /// An invalid calibration is refused at construction and by `set_calibration`.
        #[test]
        fn invalid_calibrations_are_refused(z in proptest::num::f64::ANY, g in proptest::num::f64::ANY) {
            let cal = GyroCalibration { zero_rps: z, gain_pos: g, gain_neg: 1.0 };
            let ok = z.is_finite() && g.is_finite() && g > 0.0;
            prop_assert_eq!(YawIntegrator::new(YawIntegratorConfig { calibration: cal }).is_ok(), ok);
            let mut yaw = identity();
            prop_assert_eq!(yaw.set_calibration(cal).is_ok(), ok);
            if !ok {
                prop_assert_eq!(*yaw.calibration(), GyroCalibration::IDENTITY);
            }
        }
    }

    #[test]
    fn first_sample_is_none_and_reset_forgets() {
        let mut yaw = identity();
        assert_eq!(yaw.push_yaw_rate(5.0, 1.0).unwrap(), None);
        let step = yaw.push_yaw_rate(6.0, 1.0).unwrap().unwrap();
        assert_eq!((step.dt_s, step.heading_change_rad), (1.0, 1.0));
        yaw.reset();
        assert_eq!(yaw.heading_rad(), 0.0);
        // After a reset an earlier timestamp is acceptable again.
        assert_eq!(yaw.push_yaw_rate(0.0, 1.0).unwrap(), None);
    }

    /// A rate that ramps linearly is integrated exactly (the trapezoid's defining property),
    /// while the rectangle rule would be off by half of Δω·dt.
    #[test]
    fn a_linear_ramp_is_integrated_exactly() {
        let mut yaw = identity();
        let (dt, slope) = (0.1, 0.3);
        for k in 0..=50 {
            let t = k as f64 * dt;
            yaw.push_yaw_rate(t, slope * t).unwrap();
        }
        let t_end = 50.0 * dt;
        assert!((yaw.heading_rad() - 0.5 * slope * t_end * t_end).abs() < 1e-12);
    }
}
