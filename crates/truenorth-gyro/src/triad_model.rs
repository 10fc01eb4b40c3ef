//! A three-axis gyro: three independent [`GyroAxisModel`]s on the body axes (x forward,
//! y right, z down). Cross-axis misalignment is not modelled.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use truenorth_core::{NoiseSource, Result, SensorModel, check_dt, check_finite, check_finite3};

use crate::{Gyro3Calibration, GyroAxisModel, GyroAxisParams, RateTruth};

/// The true state a three-axis gyro senses.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rate3Truth {
    /// True body angular rate (x, y, z), rad/s.
    pub rate_rps: Vector3<f64>,
    /// Sensor temperature, °C.
    pub temp_c: f64,
}

/// Forward model of a three-axis gyro.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gyro3Model {
    axes: [GyroAxisModel; 3],
}

impl Gyro3Model {
    /// A model with the given parameters for the x, y and z axes.
    pub fn new(params: [GyroAxisParams; 3]) -> Result<Self> {
        let [x, y, z] = params;
        Ok(Self {
            axes: [
                GyroAxisModel::new(x)?,
                GyroAxisModel::new(y)?,
                GyroAxisModel::new(z)?,
            ],
        })
    }

    /// The same parameters on all three axes.
    pub fn uniform(params: GyroAxisParams) -> Result<Self> {
        Self::new([params; 3])
    }

    /// The per-axis models, x, y, z.
    pub fn axes(&self) -> &[GyroAxisModel; 3] {
        &self.axes
    }

    /// Sets every random walk back to zero.
    pub fn reset_state(&mut self) {
        for a in &mut self.axes {
            a.reset_state();
        }
    }

    /// The model's true inverse at temperature `temp_c` (see
    /// [`GyroAxisModel::true_calibration`]).
    pub fn true_calibration(&self, temp_c: f64) -> Result<Gyro3Calibration> {
        let [x, y, z] = &self.axes;
        Ok(Gyro3Calibration {
            axes: [
                x.true_calibration(temp_c)?,
                y.true_calibration(temp_c)?,
                z.true_calibration(temp_c)?,
            ],
        })
    }

    /// [`SensorModel::sample`] with validation; on error no axis state changes.
    pub fn try_sample(
        &mut self,
        truth: &Rate3Truth,
        dt_s: f64,
        noise: &mut dyn NoiseSource,
    ) -> Result<Vector3<f64>> {
        // Validate everything first so that a bad z does not leave x and y advanced.
        check_finite3("true rate rate_rps", &truth.rate_rps)?;
        check_finite("gyro temperature temp_c", truth.temp_c)?;
        check_dt(dt_s)?;
        let mut out = Vector3::zeros();
        for (i, axis) in self.axes.iter_mut().enumerate() {
            let t = RateTruth {
                rate_rps: truth.rate_rps[i],
                temp_c: truth.temp_c,
            };
            out[i] = axis.try_sample(&t, dt_s, noise)?;
        }
        Ok(out)
    }
}

impl SensorModel for Gyro3Model {
    type Truth = Rate3Truth;
    type Reading = Vector3<f64>;

    fn ideal(&self, truth: &Rate3Truth) -> Vector3<f64> {
        let [x, y, z] = &self.axes;
        let at = |rate_rps| RateTruth {
            rate_rps,
            temp_c: truth.temp_c,
        };
        Vector3::new(
            x.ideal(&at(truth.rate_rps.x)),
            y.ideal(&at(truth.rate_rps.y)),
            z.ideal(&at(truth.rate_rps.z)),
        )
    }

    /// Every error; NaN components for invalid input (see [`Gyro3Model::try_sample`]).
    fn sample(
        &mut self,
        truth: &Rate3Truth,
        dt_s: f64,
        noise: &mut dyn NoiseSource,
    ) -> Vector3<f64> {
        self.try_sample(truth, dt_s, noise)
            .unwrap_or_else(|_| Vector3::repeat(f64::NAN))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::{Calibration, SplitMix64};

    fn axis() -> impl Strategy<Value = GyroAxisParams> {
        (-0.5f64..0.5, -0.3f64..0.3, -0.3f64..0.3, -1e-3f64..1e-3).prop_map(|(b, sp, sn, kt)| {
            GyroAxisParams {
                bias_rps: b,
                scale_error_pos: sp,
                scale_error_neg: sn,
                temp_coeff_rps_per_k: kt,
                ..GyroAxisParams::PERFECT
            }
        })
    }

    proptest! {
        #[test]
        fn ideal_then_true_inverse_is_identity(
            px in axis(), py in axis(), pz in axis(),
            w in proptest::array::uniform3(-20.0f64..20.0), temp in -40.0f64..85.0,
        ) {
            let m = Gyro3Model::new([px, py, pz]).unwrap();
            let truth = Rate3Truth { rate_rps: Vector3::from(w), temp_c: temp };
            let back = m.true_calibration(temp).unwrap().apply(&m.ideal(&truth));
            prop_assert!((back - truth.rate_rps).amax() < 1e-12 * (1.0 + truth.rate_rps.amax()));
        }

        #[test]
        fn bad_input_changes_no_axis(
            bad in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
            axis in 0usize..3,
        ) {
            let mut m = Gyro3Model::uniform(GyroAxisParams {
                bias_walk_rps_per_sqrt_s: 0.1, ..GyroAxisParams::PERFECT
            }).unwrap();
            let before = m;
            let mut rate = Vector3::new(0.1, 0.2, 0.3);
            rate[axis] = bad;
            let truth = Rate3Truth { rate_rps: rate, temp_c: 25.0 };
            prop_assert!(m.try_sample(&truth, 0.01, &mut SplitMix64::new(5)).is_err());
            prop_assert_eq!(m, before);
            prop_assert!(m.sample(&truth, 0.01, &mut SplitMix64::new(5)).x.is_nan());
        }
    }
}
