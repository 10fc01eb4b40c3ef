//! Yaw-rate integration: calibrated `gyr_z` → heading change per step.
//!
//! `dt` comes from the samples' timestamps (never from a nominal rate), so dropped samples
//! and jitter do not bias the heading; a timestamp that does not increase is refused.

use truenorth_core::{GyroSample, RelativeHeadingSource, Result, TimeStep, check_finite};

use crate::GyroCalibration;

/// Integrates a yaw gyro into heading change, positive for a right turn.
///
/// Between two samples the rate is taken to vary linearly, so the step is the trapezoid
/// `(ω_prev + ω_now)/2 · dt`: exact for a constant or linearly changing rate, where the
/// rectangle rule would lag by half a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YawIntegrator {
    calibration: GyroCalibration,
    clock: TimeStep,
    last_rate_rps: Option<f64>,
    heading_rad: f64,
}

impl YawIntegrator {
    /// An integrator that applies `calibration` to every raw `gyr_z` before integrating.
    pub fn new(calibration: GyroCalibration) -> Self {
        Self {
            calibration,
            clock: TimeStep::new(),
            last_rate_rps: None,
            heading_rad: 0.0,
        }
    }

    /// The calibration in use.
    pub fn calibration(&self) -> &GyroCalibration {
        &self.calibration
    }

    /// Replaces the calibration (e.g. after a calibrator produced a better one). Takes effect
    /// from the next sample.
    pub fn set_calibration(&mut self, calibration: GyroCalibration) {
        self.calibration = calibration;
    }

    /// Heading change accumulated since construction or [`RelativeHeadingSource::reset`],
    /// radians, not wrapped (two right turns in a circle give 4π).
    pub fn heading_rad(&self) -> f64 {
        self.heading_rad
    }

    /// Feeds one raw yaw-rate sample (`gyr_z`, rad/s, with the gyro's own bias and scale) at
    /// time `t_s` and returns the heading change since the previous sample (0 for the
    /// first). On error (non-finite value, non-increasing time, invalid calibration) nothing
    /// changes, so the caller may skip the sample and go on.
    pub fn push_yaw_rate(&mut self, t_s: f64, gyr_z_rps: f64) -> Result<f64> {
        check_finite("gyr_z", gyr_z_rps)?;
        let rate_rps = self.calibration.try_apply(gyr_z_rps)?;
        let mut clock = self.clock;
        let dt_s = clock.dt_s(t_s)?;
        let change_rad = match (dt_s, self.last_rate_rps) {
            (Some(dt_s), Some(prev)) => 0.5 * (prev + rate_rps) * dt_s,
            _ => 0.0,
        };
        self.clock = clock;
        self.last_rate_rps = Some(rate_rps);
        self.heading_rad += change_rad;
        Ok(change_rad)
    }
}

impl RelativeHeadingSource for YawIntegrator {
    type Sample = GyroSample;

    /// Uses only `gyr_rps.z` (a vehicle's yaw axis); see [`YawIntegrator::push_yaw_rate`].
    fn heading_change_rad(&mut self, sample: &GyroSample) -> Result<f64> {
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
            let mut yaw = YawIntegrator::new(m.true_calibration(temp).unwrap());
            let mut t = 10.0;
            let mut prev_rate = 0.3;
            yaw.push_yaw_rate(t, m.ideal(&RateTruth { rate_rps: prev_rate, temp_c: temp })).unwrap();
            let mut truth = 0.0;
            for (dt, rate) in steps {
                t += dt;
                truth += 0.5 * (prev_rate + rate) * dt;
                prev_rate = rate;
                let raw = m.ideal(&RateTruth { rate_rps: rate, temp_c: temp });
                yaw.heading_change_rad(&GyroSample { t_s: t, gyr_rps: Vector3::new(9.0, 9.0, raw) }).unwrap();
            }
            prop_assert!((yaw.heading_rad() - truth).abs() < 1e-9 * (1.0 + truth.abs()),
                "{} vs {truth}", yaw.heading_rad());
        }

        /// Without calibration the same biased gyro drifts by bias·time: the round trip above
        /// is not passing by accident.
        #[test]
        fn an_uncalibrated_biased_gyro_drifts(bias in 0.01f64..0.1, dur in 1.0f64..100.0) {
            let mut yaw = YawIntegrator::new(GyroCalibration::IDENTITY);
            yaw.push_yaw_rate(0.0, bias).unwrap();
            yaw.push_yaw_rate(dur, bias).unwrap();
            prop_assert!((yaw.heading_rad() - bias * dur).abs() < 1e-9);
        }

        #[test]
        fn bad_samples_are_typed_errors_and_change_nothing(
            t in proptest::num::f64::ANY, w in proptest::num::f64::ANY,
        ) {
            let mut yaw = YawIntegrator::new(GyroCalibration::IDENTITY);
            yaw.push_yaw_rate(0.0, 0.1).unwrap();
            yaw.push_yaw_rate(1.0, 0.1).unwrap();
            let before = yaw;
            let ok = t.is_finite() && t > 1.0 && w.is_finite();
            let r = yaw.push_yaw_rate(t, w);
            prop_assert_eq!(r.is_ok(), ok);
            if !ok {
                prop_assert_eq!(yaw, before);
            }
            if w.is_finite() && t.is_finite() && t <= 1.0 {
                let is_time_error = matches!(r, Err(Error::NonIncreasingTime { .. }));
                prop_assert!(is_time_error);
            }
            if !w.is_finite() {
                let is_non_finite = matches!(r, Err(Error::NonFinite { .. }));
                prop_assert!(is_non_finite);
            }
        }
    }

    #[test]
    fn first_sample_returns_zero_and_reset_forgets() {
        let mut yaw = YawIntegrator::new(GyroCalibration::IDENTITY);
        assert_eq!(yaw.push_yaw_rate(5.0, 1.0).unwrap(), 0.0);
        assert_eq!(yaw.push_yaw_rate(6.0, 1.0).unwrap(), 1.0);
        yaw.reset();
        assert_eq!(yaw.heading_rad(), 0.0);
        // After a reset an earlier timestamp is acceptable again.
        assert_eq!(yaw.push_yaw_rate(0.0, 1.0).unwrap(), 0.0);
    }
}
