//! Quasi-static detection: is the accelerometer sensing gravity alone, so that its static tilt
//! can be trusted? The seed's test with three accelerometers (WO 00/36376):
//! `| |a| − g |` below a threshold.
//!
//! The test is necessary, not sufficient: an acceleration that happens to keep |a − g| = g
//! (e.g. a level turn combined with a vertical acceleration) passes it. The seed pairs it
//! with tests on the change of the static angles; those live in the estimator.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use truenorth_core::{Result, STANDARD_GRAVITY_MPS2, Validate, check_finite3, check_positive};

/// Settings of a [`QuasiStaticDetector`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct QuasiStaticConfig {
    /// Local gravity, m/s² (> 0). Default: standard gravity.
    pub gravity_mps2: f64,
    /// Largest accepted `| |f| − g |`, m/s² (> 0). Default 0.2 m/s² (≈ 0.02 g): a few times
    /// a consumer MEMS accelerometer's noise per sample plus its residual scale error near
    /// 1 g.
    pub threshold_mps2: f64,
}

impl Default for QuasiStaticConfig {
    fn default() -> Self {
        Self {
            gravity_mps2: STANDARD_GRAVITY_MPS2,
            threshold_mps2: 0.2,
        }
    }
}

impl Validate for QuasiStaticConfig {
    /// Gravity and threshold positive and finite.
    fn validate(&self) -> Result<()> {
        check_positive("gravity_mps2", self.gravity_mps2)?;
        check_positive("quasi-static threshold_mps2", self.threshold_mps2)?;
        Ok(())
    }
}

/// Decides whether a specific-force reading is (close to) gravity alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuasiStaticDetector {
    config: QuasiStaticConfig,
}

impl Default for QuasiStaticDetector {
    /// The detector of [`QuasiStaticConfig::default`].
    fn default() -> Self {
        Self {
            config: QuasiStaticConfig::default(),
        }
    }
}

impl QuasiStaticDetector {
    /// A detector with a validated `config`.
    pub fn new(config: QuasiStaticConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self { config })
    }

    /// The settings in use.
    pub fn config(&self) -> &QuasiStaticConfig {
        &self.config
    }

    /// `| |f| − g |`, m/s², for a calibrated specific-force reading; a typed error if a
    /// component is not finite.
    pub fn deviation_mps2(&self, f_b_mps2: &Vector3<f64>) -> Result<f64> {
        check_finite3("specific force", f_b_mps2)?;
        // Scaled norm: huge finite readings must not overflow to inf.
        let scale = f_b_mps2.amax();
        let norm = if scale > 0.0 {
            scale * (f_b_mps2 / scale).norm()
        } else {
            0.0
        };
        Ok((norm - self.config.gravity_mps2).abs())
    }

    /// Whether the reading is within the threshold of gravity.
    pub fn is_quasi_static(&self, f_b_mps2: &Vector3<f64>) -> Result<bool> {
        Ok(self.deviation_mps2(f_b_mps2)? <= self.config.threshold_mps2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AccelTruth, specific_force_body_mps2};
    use core::f64::consts::PI;
    use proptest::prelude::*;
    use truenorth_core::EulerZyx;

    fn attitude(y: f64, p: f64, r: f64) -> nalgebra::UnitQuaternion<f64> {
        EulerZyx {
            yaw_rad: y,
            pitch_rad: p,
            roll_rad: r,
        }
        .to_quaternion()
    }

    proptest! {
        #[test]
        fn at_rest_is_quasi_static_in_any_attitude(y in -PI..PI, p in -1.57f64..1.57, r in -PI..PI) {
            let d = QuasiStaticDetector::default();
            let f = specific_force_body_mps2(&AccelTruth::at_rest(attitude(y, p, r)), d.config().gravity_mps2).unwrap();
            prop_assert!(d.deviation_mps2(&f).unwrap() < 1e-12);
            prop_assert!(d.is_quasi_static(&f).unwrap());
        }

        /// A horizontal acceleration of magnitude m gives |f| = √(m² + g²): detected as
        /// moving exactly when √(m² + g²) − g exceeds the threshold.
        #[test]
        fn horizontal_acceleration_is_detected(
            m in 0.0f64..20.0, dir in -PI..PI, y in -PI..PI, p in -1.5f64..1.5, r in -PI..PI,
        ) {
            let d = QuasiStaticDetector::default();
            let truth = AccelTruth {
                attitude: attitude(y, p, r),
                accel_ned_mps2: Vector3::new(m * dir.cos(), m * dir.sin(), 0.0),
            };
            let c = *d.config();
            let f = specific_force_body_mps2(&truth, c.gravity_mps2).unwrap();
            let dev = (m * m + c.gravity_mps2 * c.gravity_mps2).sqrt() - c.gravity_mps2;
            prop_assume!((dev - c.threshold_mps2).abs() > 1e-9);
            prop_assert_eq!(d.is_quasi_static(&f).unwrap(), dev <= c.threshold_mps2);
        }

        #[test]
        fn no_panic_on_any_input(
            x in proptest::num::f64::ANY, g in proptest::num::f64::ANY, t in proptest::num::f64::ANY,
        ) {
            let f = Vector3::new(x, 1.0, -9.8);
            let r = QuasiStaticDetector::default().is_quasi_static(&f);
            prop_assert_eq!(r.is_ok(), x.is_finite());
            if r.is_err() {
                let non_finite = matches!(r, Err(truenorth_core::Error::NonFinite { .. }));
                prop_assert!(non_finite);
            }
            let config = QuasiStaticConfig { gravity_mps2: g, threshold_mps2: t };
            let valid = g.is_finite() && g > 0.0 && t.is_finite() && t > 0.0;
            prop_assert_eq!(QuasiStaticDetector::new(config).is_ok(), valid);
        }
    }
}
