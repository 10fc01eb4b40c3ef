//! Accelerometer calibration with bias, per-axis scale and cross-axis sensitivity (the three
//! axes not quite orthogonal, or coupled): `f = matrix · (raw − bias)`, raw reading in any
//! unit, specific force in m/s² — the [`InertialCalibration`] model with unit gains and the
//! scale folded into the matrix, under the names the joint calibration files carry.
//!
//! A triad whose axes are not orthogonal reads `raw = K f + b` with `K` any invertible
//! matrix; the calibration is its inverse. A tumble at rest determines `K⁻¹` only up to a
//! rotation (`|f| = g` in every orientation), so a calibrator must choose the rotation:
//! the fits of this workspace take the symmetric matrix (the one closest to the sensor's
//! own axes, by the polar decomposition) unless other information fixes the body axes.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_core::{Calibration, Error, InertialCalibration, Result, Validate, check_finite3};

/// The largest condition number (largest over smallest singular value) of an accepted
/// matrix: 10, the largest axis ratio the ellipsoid fits accept. A real triad's scale
/// errors are a few per cent and its cross-axis terms smaller.
pub const MAX_TRIAD_CONDITION: f64 = 10.0;

/// `f = matrix · (raw − bias)`: bias in the raw unit, `matrix` from the raw unit to m/s².
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AccelTriadCalibration {
    /// Bias, raw unit.
    pub bias: Vector3<f64>,
    /// Raw unit → m/s², with scale and cross-axis correction (and, when a calibrator
    /// aligned the body axes, the rotation onto them).
    pub matrix: Matrix3<f64>,
}

impl Default for AccelTriadCalibration {
    /// No correction, raw readings already in m/s².
    fn default() -> Self {
        Self {
            bias: Vector3::zeros(),
            matrix: Matrix3::identity(),
        }
    }
}

impl AccelTriadCalibration {
    /// A checked calibration (see [`Validate`]).
    pub fn new(bias: Vector3<f64>, matrix: Matrix3<f64>) -> Result<Self> {
        let cal = Self { bias, matrix };
        cal.validate()?;
        Ok(cal)
    }

    /// The specific force of a raw reading, m/s², without checks (see
    /// [`Calibration::apply`]).
    #[inline]
    pub fn correct(&self, raw: &Vector3<f64>) -> Vector3<f64> {
        InertialCalibration::from(*self).correct(raw)
    }
}

impl From<AccelTriadCalibration> for InertialCalibration {
    /// Offset the bias, unit gains, the matrix as the misalignment.
    fn from(c: AccelTriadCalibration) -> Self {
        Self {
            offset: c.bias,
            gain: Vector3::repeat(1.0),
            misalignment: Some(c.matrix),
        }
    }
}

impl Validate for AccelTriadCalibration {
    /// Finite; the matrix orientation-preserving (a negative determinant mirrors every
    /// tilt) and no worse conditioned than [`MAX_TRIAD_CONDITION`].
    fn validate(&self) -> Result<()> {
        check_finite3("accelerometer bias", &self.bias)?;
        for c in self.matrix.column_iter() {
            check_finite3("accelerometer matrix column", &c.into_owned())?;
        }
        // A NaN fails every check instead of slipping through one.
        let determinant = self.matrix.determinant();
        if determinant.is_nan() || determinant <= 0.0 {
            return Err(Error::Degenerate {
                reason: "the accelerometer matrix is singular or mirrors the axes (determinant not positive); recalibrate",
            });
        }
        let sv = self.matrix.singular_values();
        let condition = sv.max() / sv.min();
        if condition.is_nan() || condition > MAX_TRIAD_CONDITION {
            return Err(Error::OutOfRange {
                what: "condition number of the accelerometer matrix",
                value: condition,
                min: 1.0,
                max: MAX_TRIAD_CONDITION,
            });
        }
        Ok(())
    }
}

impl Calibration for AccelTriadCalibration {
    type Raw = Vector3<f64>;
    type Physical = Vector3<f64>;

    /// `matrix · (raw − bias)`, or a typed error (non-finite reading, invalid calibration,
    /// a result too large to represent).
    fn apply(&self, raw: &Vector3<f64>) -> Result<Vector3<f64>> {
        check_finite3("raw accelerometer reading", raw)?;
        self.validate()?;
        let f = self.correct(raw);
        check_finite3("calibrated specific force (reading too large)", &f)?;
        Ok(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// `apply` inverts `raw = K f + b` for any well-conditioned `K`.
        #[test]
        fn apply_inverts_a_cross_coupled_triad(
            k in proptest::array::uniform9(-0.05f64..0.05),
            s in proptest::array::uniform3(0.9f64..1.1),
            b in proptest::array::uniform3(-0.5f64..0.5),
            f in proptest::array::uniform3(-20.0f64..20.0),
        ) {
            let kk = Matrix3::from_diagonal(&Vector3::from(s)) + Matrix3::from_row_slice(&k);
            let cal = AccelTriadCalibration::new(Vector3::from(b), kk.try_inverse().unwrap()).unwrap();
            let f = Vector3::from(f);
            let raw = kk * f + cal.bias;
            prop_assert!((cal.apply(&raw).unwrap() - f).amax() < 1e-9 * (1.0 + f.amax()));
        }

        /// No panic on any input; non-finite parameters or readings are typed errors.
        #[test]
        fn typed_errors_on_any_input(x in proptest::num::f64::ANY, m in proptest::num::f64::ANY) {
            let mut cal = AccelTriadCalibration::default();
            cal.matrix[(1, 2)] = m;
            let r = cal.apply(&Vector3::new(x, 0.0, -9.8));
            if !(x.is_finite() && m.is_finite()) {
                prop_assert!(r.is_err());
            }
        }
    }

    #[test]
    fn mirrors_and_singular_matrices_are_refused() {
        let mirror = AccelTriadCalibration {
            matrix: Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0)),
            ..AccelTriadCalibration::default()
        };
        assert!(mirror.validate().is_err());
        let flat = AccelTriadCalibration {
            matrix: Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 1e-6)),
            ..AccelTriadCalibration::default()
        };
        assert!(matches!(flat.validate(), Err(Error::OutOfRange { .. })));
        assert!(AccelTriadCalibration::default().validate().is_ok());
    }
}
