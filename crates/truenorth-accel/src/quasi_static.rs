//! Quasi-static detection: is the accelerometer sensing gravity alone, so that its static tilt
//! can be trusted? The seed's test with three accelerometers (WO 00/36376, METHODS §E.5(7)):
//! `| |a| − g |` below a threshold.
//!
//! The test is necessary, not sufficient: an acceleration that happens to keep |a − g| = g
//! (e.g. a level turn combined with a vertical acceleration) passes it. The seed pairs it
//! with tests on the change of the static angles; those live in the estimator.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
#[allow(unused_imports)]
use truenorth_core::Float as _;
use truenorth_core::{Error, Result, STANDARD_GRAVITY_MPS2, check_finite, check_finite3};

/// Decides whether a specific-force reading is (close to) gravity alone.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct QuasiStaticDetector {
    /// Local gravity, m/s².
    pub gravity_mps2: f64,
    /// Largest accepted `| |f| − g |`, m/s².
    pub threshold_mps2: f64,
}

impl Default for QuasiStaticDetector {
    /// Standard gravity and a 0.2 m/s² (≈ 0.02 g) threshold: a few times a consumer MEMS
    /// accelerometer's noise per sample plus its residual scale error near 1 g.
    fn default() -> Self {
        Self {
            gravity_mps2: STANDARD_GRAVITY_MPS2,
            threshold_mps2: 0.2,
        }
    }
}

impl QuasiStaticDetector {
    /// A detector with positive finite gravity and threshold.
    pub fn new(gravity_mps2: f64, threshold_mps2: f64) -> Result<Self> {
        let d = Self {
            gravity_mps2,
            threshold_mps2,
        };
        d.validate()?;
        Ok(d)
    }

    /// Checks gravity and threshold (useful after loading from disk).
    pub fn validate(&self) -> Result<()> {
        for (what, v) in [
            ("gravity_mps2", self.gravity_mps2),
            ("quasi-static threshold_mps2", self.threshold_mps2),
        ] {
            check_finite(what, v)?;
            if v <= 0.0 {
                return Err(Error::OutOfRange {
                    what,
                    value: v,
                    min: f64::MIN_POSITIVE,
                    max: f64::MAX,
                });
            }
        }
        Ok(())
    }

    /// `| |f| − g |`, m/s², for a calibrated specific-force reading.
    pub fn deviation_mps2(&self, f_b_mps2: &Vector3<f64>) -> Result<f64> {
        check_finite3("specific force", f_b_mps2)?;
        self.validate()?;
        // Scaled norm: huge finite readings must not overflow to inf.
        let scale = f_b_mps2.amax();
        let norm = if scale > 0.0 {
            scale * (f_b_mps2 / scale).norm()
        } else {
            0.0
        };
        Ok((norm - self.gravity_mps2).abs())
    }

    /// Whether the reading is within the threshold of gravity.
    pub fn is_quasi_static(&self, f_b_mps2: &Vector3<f64>) -> Result<bool> {
        Ok(self.deviation_mps2(f_b_mps2)? <= self.threshold_mps2)
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
            let f = specific_force_body_mps2(&AccelTruth::at_rest(attitude(y, p, r)), d.gravity_mps2);
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
            let f = specific_force_body_mps2(&truth, d.gravity_mps2);
            let dev = (m * m + d.gravity_mps2 * d.gravity_mps2).sqrt() - d.gravity_mps2;
            prop_assume!((dev - d.threshold_mps2).abs() > 1e-9);
            prop_assert_eq!(d.is_quasi_static(&f).unwrap(), dev <= d.threshold_mps2);
        }

        #[test]
        fn no_panic_on_any_input(
            x in proptest::num::f64::ANY, g in proptest::num::f64::ANY, t in proptest::num::f64::ANY,
        ) {
            let f = Vector3::new(x, 1.0, -9.8);
            prop_assert_eq!(QuasiStaticDetector::default().is_quasi_static(&f).is_ok(), x.is_finite());
            let d = QuasiStaticDetector { gravity_mps2: g, threshold_mps2: t };
            let valid = g.is_finite() && g > 0.0 && t.is_finite() && t > 0.0;
            prop_assert_eq!(d.deviation_mps2(&Vector3::new(0.0, 0.0, -9.8)).is_ok(), valid);
            prop_assert_eq!(QuasiStaticDetector::new(g, t).is_ok(), valid);
        }
    }
}
