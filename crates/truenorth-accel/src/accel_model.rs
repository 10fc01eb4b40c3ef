//! Forward model of a three-axis accelerometer: per-axis bias and scale error, white noise,
//! sensing gravity plus the vehicle's own acceleration.
//!
//! `reading = diag(1 + s)·f_b + b + n`, with `f_b` the specific force
//! ([`crate::specific_force_body_mps2`]) and `n` white noise of density N (per sample
//! `N/√dt`). Parameters and derived coefficients are kept apart (VQF style, Laidig & Seel
//! 2023); the model has no time-varying state.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{
    NoiseSource, Result, STANDARD_GRAVITY_MPS2, SensorModel, Validate, check_dt, check_finite3,
    check_positive, check_range,
};

use crate::specific_force::specific_force_unchecked;
use crate::{AccelCalibration, AccelTruth};

/// Smallest accepted scale error per axis (a gain of 0.001; ≤ 0 could not be inverted).
pub const MIN_SCALE_ERROR: f64 = -0.999;

/// The accelerometer's true error parameters.
///
/// A forward model's parameters are called `*Params` (not `*Config`): they describe the
/// sensor's actual errors, which a calibration estimates, rather than options a user picks.
/// They are validated like every config ([`Validate`]) and [`AccelModel::new`] refuses
/// invalid ones. `Default` is a perfect sensor under standard gravity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AccelParams {
    /// Bias per axis (x, y, z), m/s².
    pub bias_mps2: Vector3<f64>,
    /// Relative scale error per axis; gain `1 + s`.
    pub scale_error: Vector3<f64>,
    /// White-noise density, m/s²/√Hz (velocity random walk); per sample `this / √dt`.
    pub noise_density_mps2_per_sqrt_hz: f64,
    /// Local gravity, m/s² (default: standard gravity).
    pub gravity_mps2: f64,
}

impl Default for AccelParams {
    fn default() -> Self {
        Self {
            bias_mps2: Vector3::zeros(),
            scale_error: Vector3::zeros(),
            noise_density_mps2_per_sqrt_hz: 0.0,
            gravity_mps2: STANDARD_GRAVITY_MPS2,
        }
    }
}

impl Validate for AccelParams {
    /// Every parameter finite, scale errors ≥ [`MIN_SCALE_ERROR`], noise ≥ 0, gravity > 0.
    fn validate(&self) -> Result<()> {
        check_finite3("accel bias_mps2", &self.bias_mps2)?;
        for &s in self.scale_error.iter() {
            check_range("accel scale_error", s, MIN_SCALE_ERROR, f64::MAX)?;
        }
        check_range(
            "accel noise_density_mps2_per_sqrt_hz",
            self.noise_density_mps2_per_sqrt_hz,
            0.0,
            f64::MAX,
        )?;
        check_positive("gravity_mps2", self.gravity_mps2)?;
        Ok(())
    }
}

/// Quantities derived from [`AccelParams`] once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccelCoefficients {
    /// Per-axis gain, `1 + scale_error` (> 0).
    pub gain: Vector3<f64>,
}

/// Forward model of a three-axis accelerometer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccelModel {
    params: AccelParams,
    coeffs: AccelCoefficients,
}

impl AccelModel {
    /// A model with these parameters (validated first).
    pub fn new(params: AccelParams) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            coeffs: AccelCoefficients {
                gain: params.scale_error.add_scalar(1.0),
            },
        })
    }

    /// The parameters.
    pub fn params(&self) -> &AccelParams {
        &self.params
    }

    /// The derived coefficients.
    pub fn coefficients(&self) -> &AccelCoefficients {
        &self.coeffs
    }

    /// The model's true inverse: its bias and gains. Applied to [`SensorModel::ideal`] it
    /// returns the true specific force.
    pub fn true_calibration(&self) -> AccelCalibration {
        AccelCalibration {
            bias_mps2: self.params.bias_mps2,
            gain: self.coeffs.gain,
        }
    }

    fn deterministic(&self, truth: &AccelTruth) -> Vector3<f64> {
        specific_force_unchecked(truth, self.params.gravity_mps2).component_mul(&self.coeffs.gain)
            + self.params.bias_mps2
    }
}

impl SensorModel for AccelModel {
    type Truth = AccelTruth;
    type Reading = Vector3<f64>;

    /// Gravity plus acceleration, with bias and scale; no noise. A typed error for a
    /// non-finite truth or a reading too large to represent.
    fn ideal(&self, truth: &AccelTruth) -> Result<Vector3<f64>> {
        truth.validate()?;
        let reading = self.deterministic(truth);
        check_finite3("accelerometer reading (inputs too large)", &reading)?;
        Ok(reading)
    }

    /// Every error: [`SensorModel::ideal`] plus white noise of `N/√dt` per axis. A typed
    /// error for a non-finite truth, a `dt_s` that is not positive and finite, or a reading
    /// too large to represent. The model has no time-varying state.
    fn sample(
        &mut self,
        truth: &AccelTruth,
        dt_s: f64,
        noise: &mut dyn NoiseSource,
    ) -> Result<Vector3<f64>> {
        truth.validate()?;
        let dt_s = check_dt(dt_s)?;
        let sigma = self.params.noise_density_mps2_per_sqrt_hz / dt_s.sqrt();
        let n = Vector3::new(
            noise.normal(sigma),
            noise.normal(sigma),
            noise.normal(sigma),
        );
        let reading = self.deterministic(truth) + n;
        check_finite3("accelerometer reading (inputs too large)", &reading)?;
        Ok(reading)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::specific_force_body_mps2;
    use crate::static_tilt;
    use core::f64::consts::PI;
    use proptest::prelude::*;
    use truenorth_core::{Calibration, Error, EulerZyx, SplitMix64, ZeroNoise, angle_diff};

    fn params() -> impl Strategy<Value = AccelParams> {
        (
            proptest::array::uniform3(-1.0f64..1.0),
            proptest::array::uniform3(-0.1f64..0.1),
            9.78f64..9.83,
        )
            .prop_map(|(b, s, g)| AccelParams {
                bias_mps2: Vector3::from(b),
                scale_error: Vector3::from(s),
                gravity_mps2: g,
                ..AccelParams::default()
            })
    }

    fn euler() -> impl Strategy<Value = EulerZyx> {
        (-PI..PI, -1.55f64..1.55, -PI..PI).prop_map(|(y, p, r)| EulerZyx {
            yaw_rad: y,
            pitch_rad: p,
            roll_rad: r,
        })
    }

    proptest! {
        /// truth → ideal → true inverse gives the true specific force.
        #[test]
        fn ideal_then_true_inverse_gives_the_specific_force(
            p in params(), e in euler(), a in proptest::array::uniform3(-20.0f64..20.0),
        ) {
            let m = AccelModel::new(p).unwrap();
            let truth = AccelTruth { attitude: e.to_quaternion(), accel_ned_mps2: Vector3::from(a) };
            let back = m.true_calibration().apply(&m.ideal(&truth).unwrap()).unwrap();
            let want = specific_force_body_mps2(&truth, p.gravity_mps2).unwrap();
            prop_assert!((back - want).amax() < 1e-12 * (1.0 + want.amax()));
            // And the specific force maps back to the NED acceleration.
            let a_back = truth.attitude.transform_vector(&back) + crate::gravity_ned_mps2(p.gravity_mps2);
            prop_assert!((a_back - truth.accel_ned_mps2).amax() < 1e-9);
        }

        /// At rest, through the model and its inverse, static tilt gives the true attitude's
        /// pitch and roll (any yaw, upside down included).
        #[test]
        fn at_rest_round_trip_gives_the_tilt(p in params(), e in euler()) {
            let m = AccelModel::new(p).unwrap();
            let f = m.true_calibration().apply(&m.ideal(&AccelTruth::at_rest(e.to_quaternion())).unwrap()).unwrap();
            let t = static_tilt(&f).unwrap();
            prop_assert!((t.pitch_rad - e.pitch_rad).abs() < 1e-9);
            prop_assert!(angle_diff(t.roll_rad, e.roll_rad).abs() < 1e-9);
        }

        /// A wrong calibration does not pass: the bias shows up in the tilt.
        #[test]
        fn uncalibrated_bias_tilts_the_answer(b in 0.2f64..1.0, e in euler()) {
            let m = AccelModel::new(AccelParams { bias_mps2: Vector3::new(b, 0.0, 0.0), ..AccelParams::default() }).unwrap();
            let raw = m.ideal(&AccelTruth::at_rest(e.to_quaternion())).unwrap();
            let t = static_tilt(&raw).unwrap();
            prop_assert!((t.pitch_rad - e.pitch_rad).abs() > 1e-4);
        }

        #[test]
        fn sample_never_panics_and_rejects_bad_input(
            x in proptest::num::f64::ANY, w in proptest::num::f64::ANY, dt in proptest::num::f64::ANY,
        ) {
            let mut m = AccelModel::new(AccelParams { noise_density_mps2_per_sqrt_hz: 1e-3, ..AccelParams::default() }).unwrap();
            let q = nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(w, 0.0, 0.0, 0.0));
            let truth = AccelTruth { attitude: q, accel_ned_mps2: Vector3::new(x, 0.0, 0.0) };
            let ok = x.is_finite() && w.is_finite() && dt.is_finite() && dt > 0.0;
            let r = m.sample(&truth, dt, &mut SplitMix64::new(2));
            if !ok {
                let typed = matches!(r, Err(Error::NonFinite { .. } | Error::InvalidDt { .. }));
                prop_assert!(typed, "{r:?}");
            }
            if let Ok(v) = r { prop_assert!(v.iter().all(|c| c.is_finite())); }
            match m.ideal(&truth) {
                Ok(v) => prop_assert!(v.iter().all(|c| c.is_finite())),
                Err(e) => prop_assert!(matches!(e, Error::NonFinite { .. }), "{e:?}"),
            }
            if !(x.is_finite() && w.is_finite()) {
                prop_assert!(m.ideal(&truth).is_err());
            }
        }
    }

    #[test]
    fn zero_noise_sample_is_ideal_and_noise_has_the_stated_size() {
        let dt = 0.01;
        let density = 0.002;
        let mut m = AccelModel::new(AccelParams {
            noise_density_mps2_per_sqrt_hz: density,
            ..AccelParams::default()
        })
        .unwrap();
        let truth = AccelTruth::at_rest(nalgebra::UnitQuaternion::identity());
        assert_eq!(
            m.sample(&truth, dt, &mut ZeroNoise).unwrap(),
            m.ideal(&truth).unwrap()
        );
        let mut rng = SplitMix64::new(11);
        let n = 20_000;
        let mut s2 = 0.0;
        for _ in 0..n {
            let e = m.sample(&truth, dt, &mut rng).unwrap() - m.ideal(&truth).unwrap();
            s2 += e.norm_squared();
        }
        let sigma = (s2 / (3 * n) as f64).sqrt();
        let want = density / dt.sqrt();
        // 60 000 draws: the standard error of σ is 0.3 %; 2 % is far outside chance.
        assert!((sigma / want - 1.0).abs() < 0.02, "{sigma} vs {want}");
    }

    #[test]
    fn invalid_params_are_rejected() {
        let ok = AccelParams::default();
        for bad in [
            AccelParams {
                scale_error: Vector3::new(0.0, -1.0, 0.0),
                ..ok
            },
            AccelParams {
                gravity_mps2: 0.0,
                ..ok
            },
            AccelParams {
                noise_density_mps2_per_sqrt_hz: -1.0,
                ..ok
            },
            AccelParams {
                bias_mps2: Vector3::new(f64::NAN, 0.0, 0.0),
                ..ok
            },
        ] {
            assert!(AccelModel::new(bad).is_err(), "{bad:?}");
        }
        assert!(AccelCalibration::new(Vector3::zeros(), Vector3::new(1.0, 0.0, 1.0)).is_err());
    }
}
