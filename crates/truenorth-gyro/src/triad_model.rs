//! A three-axis gyro: three independent [`GyroAxisModel`]s on the body axes (x forward,
//! y right, z down). Cross-axis misalignment is not modelled.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use truenorth_core::{
    NoiseSource, Result, SensorModel, Validate, check_dt, check_finite, check_finite3,
};

use crate::{Gyro3Calibration, GyroAxisModel, GyroAxisParams, RateTruth};

/// The true state a three-axis gyro senses.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rate3Truth {
    /// True body angular rate (x, y, z), rad/s.
    pub rate_rps: Vector3<f64>,
    /// Sensor temperature, °C.
    pub temp_c: f64,
}

impl Rate3Truth {
    /// Checks that every rate component and the temperature are finite.
    pub fn check_finite(&self) -> Result<()> {
        check_finite3("true rate rate_rps", &self.rate_rps)?;
        check_finite("gyro temperature temp_c", self.temp_c).map(drop)
    }

    fn axis(&self, i: usize) -> RateTruth {
        RateTruth {
            rate_rps: self.rate_rps[i],
            temp_c: self.temp_c,
        }
    }
}

/// The true error parameters of a three-axis gyro: one [`GyroAxisParams`] per body axis.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Gyro3Params {
    /// Parameters of the x, y and z axes.
    pub axes: [GyroAxisParams; 3],
}

impl Gyro3Params {
    /// The same parameters on all three axes.
    pub const fn uniform(params: GyroAxisParams) -> Self {
        Self { axes: [params; 3] }
    }
}

impl Validate for Gyro3Params {
    /// Every axis valid (see [`GyroAxisParams`]).
    fn validate(&self) -> Result<()> {
        self.axes.iter().try_for_each(Validate::validate)
    }
}

/// Forward model of a three-axis gyro.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gyro3Model {
    axes: [GyroAxisModel; 3],
}

impl Gyro3Model {
    /// A model with the given parameters for the x, y and z axes (validated first).
    pub fn new(params: Gyro3Params) -> Result<Self> {
        params.validate()?;
        let [x, y, z] = params.axes;
        Ok(Self {
            axes: [
                GyroAxisModel::new(x)?,
                GyroAxisModel::new(y)?,
                GyroAxisModel::new(z)?,
            ],
        })
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
}

impl SensorModel for Gyro3Model {
    type Truth = Rate3Truth;
    type Reading = Vector3<f64>;

    /// Each axis's [`SensorModel::ideal`]; a typed error naming the first bad component.
    fn ideal(&self, truth: &Rate3Truth) -> Result<Vector3<f64>> {
        truth.check_finite()?;
        let [x, y, z] = &self.axes;
        Ok(Vector3::new(
            x.ideal(&truth.axis(0))?,
            y.ideal(&truth.axis(1))?,
            z.ideal(&truth.axis(2))?,
        ))
    }

    /// Every error on every axis. On error no axis state changes: the axes are advanced on a
    /// copy that replaces the model only when all three succeeded.
    fn sample(
        &mut self,
        truth: &Rate3Truth,
        dt_s: f64,
        noise: &mut dyn NoiseSource,
    ) -> Result<Vector3<f64>> {
        truth.check_finite()?;
        check_dt(dt_s)?;
        let mut axes = self.axes;
        let mut out = Vector3::zeros();
        for (i, axis) in axes.iter_mut().enumerate() {
            out[i] = axis.sample(&truth.axis(i), dt_s, noise)?;
        }
        self.axes = axes;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::{Calibration, Error, SplitMix64};

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
            let m = Gyro3Model::new(Gyro3Params { axes: [px, py, pz] }).unwrap();
            let truth = Rate3Truth { rate_rps: Vector3::from(w), temp_c: temp };
            let back = m.true_calibration(temp).unwrap().apply(&m.ideal(&truth).unwrap()).unwrap();
            prop_assert!((back - truth.rate_rps).amax() < 1e-12 * (1.0 + truth.rate_rps.amax()));
        }

        #[test]
        fn bad_input_changes_no_axis(
            bad in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
            axis in 0usize..3,
        ) {
            let mut m = Gyro3Model::new(Gyro3Params::uniform(GyroAxisParams {
                bias_walk_rps_per_sqrt_s: 0.1, ..GyroAxisParams::PERFECT
            })).unwrap();
            let before = m;
            let mut rate = Vector3::new(0.1, 0.2, 0.3);
            rate[axis] = bad;
            let truth = Rate3Truth { rate_rps: rate, temp_c: 25.0 };
            let r = m.sample(&truth, 0.01, &mut SplitMix64::new(5));
            let non_finite = matches!(r, Err(Error::NonFinite { .. }));
            prop_assert!(non_finite, "{r:?}");
            prop_assert_eq!(m, before);
            let non_finite = matches!(m.ideal(&truth), Err(Error::NonFinite { .. }));
            prop_assert!(non_finite);
        }
    }
}
