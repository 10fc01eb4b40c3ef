//! Forward model of one gyro axis: bias, bias random walk, scale error (different for
//! positive and negative rates if wanted), white noise and a temperature coefficient of bias.
//!
//! Parameters (what a user sets, serde), coefficients (derived once, validated) and state
//! (the random walk) are kept apart, as VQF does (Laidig & Seel 2023, "VQF: Highly accurate
//! IMU orientation estimation with bias estimation and magnetic disturbance rejection").

use serde::{Deserialize, Serialize};
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{
    NoiseSource, Result, SensorModel, Validate, check_dt, check_finite, check_range,
};

use crate::GyroCalibration;

/// Smallest accepted scale error: a gain `1 + s` below 0.001 is not a gyro any more, and a
/// gain ≤ 0 would make the model impossible to invert.
pub const MIN_SCALE_ERROR: f64 = -0.999;

/// The true error parameters of one gyro axis. All rates in rad/s.
///
/// A forward model's parameters are called `*Params` (not `*Config`): they describe the
/// sensor's actual errors, which a calibration estimates, rather than options a user picks.
/// They are validated like every config ([`Validate`]) and [`GyroAxisModel::new`] refuses
/// invalid ones.
///
/// For a yaw gyro, "positive" rotation is a right turn and "negative" a left turn (body z
/// down, heading clockwise). `Default` is a perfect gyro at a 25 °C reference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GyroAxisParams {
    /// Constant bias (zero-rate output) at the reference temperature, rad/s.
    pub bias_rps: f64,
    /// Bias random walk: the bias changes by `N(0, (this · √dt)²)` per step, rad/s/√s.
    pub bias_walk_rps_per_sqrt_s: f64,
    /// Relative scale error for positive rates (right turns for a yaw gyro); gain `1 + this`.
    pub scale_error_pos: f64,
    /// Relative scale error for negative rates (left turns for a yaw gyro); gain `1 + this`.
    pub scale_error_neg: f64,
    /// White-noise density (angle random walk), rad/s/√Hz. Per sample the noise has standard
    /// deviation `this / √dt` (IEEE Std 952-1997, angle random walk).
    pub noise_density_rps_per_sqrt_hz: f64,
    /// Change of bias with temperature, rad/s per kelvin.
    pub temp_coeff_rps_per_k: f64,
    /// Temperature at which the bias equals `bias_rps`, °C.
    pub ref_temp_c: f64,
}

impl Default for GyroAxisParams {
    fn default() -> Self {
        Self::PERFECT
    }
}

impl GyroAxisParams {
    /// A perfect gyro: no bias, no scale error, no noise, 25 °C reference.
    pub const PERFECT: Self = Self {
        bias_rps: 0.0,
        bias_walk_rps_per_sqrt_s: 0.0,
        scale_error_pos: 0.0,
        scale_error_neg: 0.0,
        noise_density_rps_per_sqrt_hz: 0.0,
        temp_coeff_rps_per_k: 0.0,
        ref_temp_c: 25.0,
    };
}

impl Validate for GyroAxisParams {
    /// Every parameter finite, noise terms non-negative, scale errors ≥ [`MIN_SCALE_ERROR`].
    fn validate(&self) -> Result<()> {
        check_finite("gyro bias_rps", self.bias_rps)?;
        check_finite("gyro temp_coeff_rps_per_k", self.temp_coeff_rps_per_k)?;
        check_finite("gyro ref_temp_c", self.ref_temp_c)?;
        check_range(
            "gyro bias_walk_rps_per_sqrt_s",
            self.bias_walk_rps_per_sqrt_s,
            0.0,
            f64::MAX,
        )?;
        check_range(
            "gyro noise_density_rps_per_sqrt_hz",
            self.noise_density_rps_per_sqrt_hz,
            0.0,
            f64::MAX,
        )?;
        check_range(
            "gyro scale_error_pos",
            self.scale_error_pos,
            MIN_SCALE_ERROR,
            f64::MAX,
        )?;
        check_range(
            "gyro scale_error_neg",
            self.scale_error_neg,
            MIN_SCALE_ERROR,
            f64::MAX,
        )?;
        Ok(())
    }
}

/// Coefficients derived from [`GyroAxisParams`] once, at construction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GyroAxisCoefficients {
    /// Gain for positive rates, `1 + scale_error_pos` (> 0).
    pub gain_pos: f64,
    /// Gain for negative rates, `1 + scale_error_neg` (> 0).
    pub gain_neg: f64,
}

/// The time-varying part of the model.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GyroAxisState {
    /// Current value of the bias random walk (added to the constant bias), rad/s.
    pub bias_walk_rps: f64,
}

/// The true state a gyro axis senses: its angular rate and the sensor temperature.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RateTruth {
    /// True angular rate about the axis, rad/s (for yaw: positive = right turn).
    pub rate_rps: f64,
    /// Sensor temperature, °C.
    pub temp_c: f64,
}

impl RateTruth {
    /// Checks that the rate and the temperature are finite.
    pub fn check_finite(&self) -> Result<()> {
        check_finite("true rate rate_rps", self.rate_rps)?;
        check_finite("gyro temperature temp_c", self.temp_c).map(drop)
    }

    /// A rate at the model's reference temperature (so the temperature term is zero).
    pub fn at_reference(rate_rps: f64, params: &GyroAxisParams) -> Self {
        Self {
            rate_rps,
            temp_c: params.ref_temp_c,
        }
    }
}

/// Forward model of one gyro axis (a yaw gyro, or one axis of [`crate::Gyro3Model`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GyroAxisModel {
    params: GyroAxisParams,
    coeffs: GyroAxisCoefficients,
    state: GyroAxisState,
}

impl GyroAxisModel {
    /// A model with these parameters (validated first) and the random walk at zero.
    pub fn new(params: GyroAxisParams) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            coeffs: GyroAxisCoefficients {
                gain_pos: 1.0 + params.scale_error_pos,
                gain_neg: 1.0 + params.scale_error_neg,
            },
            state: GyroAxisState::default(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &GyroAxisParams {
        &self.params
    }

    /// The derived coefficients.
    pub fn coefficients(&self) -> &GyroAxisCoefficients {
        &self.coeffs
    }

    /// The time-varying state.
    pub fn state(&self) -> &GyroAxisState {
        &self.state
    }

    /// Sets the random walk back to zero.
    pub fn reset_state(&mut self) {
        self.state = GyroAxisState::default();
    }

    /// The deterministic bias at temperature `temp_c` (constant part plus temperature term,
    /// without the random walk), rad/s.
    pub fn bias_rps(&self, temp_c: f64) -> f64 {
        self.params.bias_rps + self.params.temp_coeff_rps_per_k * (temp_c - self.params.ref_temp_c)
    }

    /// The model's true inverse at temperature `temp_c`: zero = deterministic bias, gains =
    /// `1 + scale_error`. Applied to [`SensorModel::ideal`] it returns the true rate.
    pub fn true_calibration(&self, temp_c: f64) -> Result<GyroCalibration> {
        check_finite("gyro temperature temp_c", temp_c)?;
        GyroCalibration::asymmetric(
            self.bias_rps(temp_c),
            self.coeffs.gain_pos,
            self.coeffs.gain_neg,
        )
    }

    /// Like [`Self::true_calibration`] but with the current random-walk bias included: the
    /// inverse of the noise-free part of [`SensorModel::sample`] right now.
    pub fn current_calibration(&self, temp_c: f64) -> Result<GyroCalibration> {
        let mut cal = self.true_calibration(temp_c)?;
        cal.zero_rps += self.state.bias_walk_rps;
        Ok(cal)
    }

    fn deterministic(&self, truth: &RateTruth) -> f64 {
        let gain = if truth.rate_rps >= 0.0 {
            self.coeffs.gain_pos
        } else {
            self.coeffs.gain_neg
        };
        gain * truth.rate_rps + self.bias_rps(truth.temp_c)
    }
}

impl SensorModel for GyroAxisModel {
    type Truth = RateTruth;
    type Reading = f64;

    /// Bias (with its temperature term) and scale error; no random walk, no noise. A typed
    /// error for a non-finite truth or a reading too large to represent.
    fn ideal(&self, truth: &RateTruth) -> Result<f64> {
        truth.check_finite()?;
        check_finite("gyro reading (inputs too large)", self.deterministic(truth))
    }

    /// Every error: advances the random walk by `dt_s` and adds white noise. A typed error
    /// (and the state unchanged) if the truth is not finite, `dt_s` is not a positive finite
    /// number or the reading would overflow.
    fn sample(&mut self, truth: &RateTruth, dt_s: f64, noise: &mut dyn NoiseSource) -> Result<f64> {
        truth.check_finite()?;
        let dt_s = check_dt(dt_s)?;
        // Random walk: the bias increment over dt has variance σ_b²·dt.
        let walk = self.state.bias_walk_rps
            + noise.normal(self.params.bias_walk_rps_per_sqrt_s * dt_s.sqrt());
        // White rate noise sampled at 1/dt: σ = N/√dt (density times √bandwidth).
        let white = noise.normal(self.params.noise_density_rps_per_sqrt_hz / dt_s.sqrt());
        let reading = check_finite(
            "gyro reading (inputs too large)",
            self.deterministic(truth) + walk + white,
        )?;
        self.state.bias_walk_rps = walk;
        Ok(reading)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::{Calibration, Error, SplitMix64, ZeroNoise};

    fn params() -> impl Strategy<Value = GyroAxisParams> {
        (
            -0.5f64..0.5,
            -0.3f64..0.3,
            -0.3f64..0.3,
            -1e-3f64..1e-3,
            -20.0f64..40.0,
        )
            .prop_map(|(b, sp, sn, kt, tr)| GyroAxisParams {
                bias_rps: b,
                scale_error_pos: sp,
                scale_error_neg: sn,
                temp_coeff_rps_per_k: kt,
                ref_temp_c: tr,
                ..GyroAxisParams::PERFECT
            })
    }

    proptest! {
        #[test]
        fn ideal_then_true_inverse_is_identity(
            p in params(), rate in -20.0f64..20.0, temp in -40.0f64..85.0,
        ) {
            let m = GyroAxisModel::new(p).unwrap();
            let truth = RateTruth { rate_rps: rate, temp_c: temp };
            let back = m.true_calibration(temp).unwrap().apply(&m.ideal(&truth).unwrap()).unwrap();
            prop_assert!((back - rate).abs() <= 1e-12 * (1.0 + rate.abs()), "{back} vs {rate}");
        }

        #[test]
        fn left_and_right_scale_errors_act_on_their_own_side(
            p in params(), rate in 0.01f64..20.0,
        ) {
            let m = GyroAxisModel::new(p).unwrap();
            let b = m.bias_rps(p.ref_temp_c);
            let right = m.ideal(&RateTruth::at_reference(rate, &p)).unwrap() - b;
            let left = m.ideal(&RateTruth::at_reference(-rate, &p)).unwrap() - b;
            prop_assert!((right - (1.0 + p.scale_error_pos) * rate).abs() < 1e-12 * (1.0 + rate));
            prop_assert!((left + (1.0 + p.scale_error_neg) * rate).abs() < 1e-12 * (1.0 + rate));
        }

        #[test]
        fn temperature_shifts_the_bias_linearly(p in params(), dt_c in -60.0f64..60.0) {
            let m = GyroAxisModel::new(p).unwrap();
            let r0 = m.ideal(&RateTruth { rate_rps: 0.0, temp_c: p.ref_temp_c }).unwrap();
            let r1 = m.ideal(&RateTruth { rate_rps: 0.0, temp_c: p.ref_temp_c + dt_c }).unwrap();
            prop_assert!((r1 - r0 - p.temp_coeff_rps_per_k * dt_c).abs() < 1e-12);
        }

        #[test]
        fn sample_never_panics_and_rejects_bad_input(
            rate in proptest::num::f64::ANY,
            temp in proptest::num::f64::ANY,
            dt in proptest::num::f64::ANY,
        ) {
            let mut m = GyroAxisModel::new(GyroAxisParams {
                bias_walk_rps_per_sqrt_s: 1e-3,
                noise_density_rps_per_sqrt_hz: 1e-3,
                ..GyroAxisParams::PERFECT
            }).unwrap();
            let mut n = SplitMix64::new(1);
            let truth = RateTruth { rate_rps: rate, temp_c: temp };
            let ok = rate.is_finite() && temp.is_finite() && dt.is_finite() && dt > 0.0;
            let before = *m.state();
            let r = m.sample(&truth, dt, &mut n);
            prop_assert_eq!(r.is_ok(), ok);
            if !ok {
                prop_assert_eq!(*m.state(), before);
                let non_finite = matches!(r, Err(Error::NonFinite { .. }));
                let bad_dt = matches!(r, Err(Error::InvalidDt { .. }));
                prop_assert!(non_finite || bad_dt, "{r:?}");
            }
            let ideal_ok = rate.is_finite() && temp.is_finite();
            prop_assert_eq!(m.ideal(&truth).is_ok(), ideal_ok);
        }

        #[test]
        fn invalid_params_are_rejected(s in -10.0f64..-0.9991, n in -1.0f64..-1e-9) {
            let bad_scale = GyroAxisParams { scale_error_neg: s, ..GyroAxisParams::PERFECT };
            let is_range_error = matches!(
                GyroAxisModel::new(bad_scale),
                Err(Error::OutOfRange { .. })
            );
            prop_assert!(is_range_error);
            let bad_noise = GyroAxisParams { noise_density_rps_per_sqrt_hz: n, ..GyroAxisParams::PERFECT };
            prop_assert!(GyroAxisModel::new(bad_noise).is_err());
            let nan = GyroAxisParams { bias_rps: f64::NAN, ..GyroAxisParams::PERFECT };
            let is_non_finite = matches!(GyroAxisModel::new(nan), Err(Error::NonFinite { .. }));
            prop_assert!(is_non_finite);
        }
    }

    #[test]
    fn zero_noise_sample_equals_ideal() {
        let p = GyroAxisParams {
            bias_rps: 0.02,
            scale_error_pos: 0.01,
            scale_error_neg: -0.02,
            bias_walk_rps_per_sqrt_s: 1e-3,
            noise_density_rps_per_sqrt_hz: 1e-2,
            ..GyroAxisParams::PERFECT
        };
        let mut m = GyroAxisModel::new(p).unwrap();
        for &w in &[-1.0, 0.0, 0.3] {
            let t = RateTruth::at_reference(w, &p);
            assert_eq!(
                m.sample(&t, 0.01, &mut ZeroNoise).unwrap(),
                m.ideal(&t).unwrap()
            );
        }
    }

    /// The white noise has standard deviation N/√dt and the random walk's variance grows as
    /// σ_b²·t. 3 % and 10 % are about four standard errors of the estimates at these sizes.
    #[test]
    fn noise_and_random_walk_have_the_stated_size() {
        let dt = 0.01;
        let density = 0.005;
        let p = GyroAxisParams {
            noise_density_rps_per_sqrt_hz: density,
            ..GyroAxisParams::PERFECT
        };
        let mut m = GyroAxisModel::new(p).unwrap();
        let mut rng = SplitMix64::new(3);
        let n = 40_000;
        let truth = RateTruth::at_reference(0.0, &p);
        let var: f64 = (0..n)
            .map(|_| m.sample(&truth, dt, &mut rng).unwrap().powi(2))
            .sum::<f64>()
            / n as f64;
        let want = density / dt.sqrt();
        assert!(
            (var.sqrt() / want - 1.0).abs() < 0.03,
            "σ {} vs {want}",
            var.sqrt()
        );

        // Random walk: many independent walks of length T; variance of the end value.
        let sigma_b = 1e-3;
        let steps = 100;
        let walks = 4000;
        let pw = GyroAxisParams {
            bias_walk_rps_per_sqrt_s: sigma_b,
            ..GyroAxisParams::PERFECT
        };
        let mut s2 = 0.0;
        for _ in 0..walks {
            let mut mw = GyroAxisModel::new(pw).unwrap();
            for _ in 0..steps {
                mw.sample(&truth, dt, &mut rng).unwrap();
            }
            s2 += mw.state().bias_walk_rps.powi(2);
        }
        let var_end = s2 / walks as f64;
        let want_var = sigma_b * sigma_b * dt * steps as f64;
        assert!(
            (var_end / want_var - 1.0).abs() < 0.1,
            "{var_end} vs {want_var}"
        );
    }
}
