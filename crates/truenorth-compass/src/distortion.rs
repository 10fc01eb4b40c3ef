//! The soft-iron distortion of a sensor model, checked and inverted once when the model is
//! made, so that producing a reading never meets a matrix it cannot undo.

use nalgebra::{Const, DimMin, SMatrix};
use truenorth_core::{Error, Result, check_finite};

/// The inverse of a `D × D` soft-iron distortion matrix, refusing a non-finite entry and a
/// singular or nearly singular matrix, which no calibration could undo.
///
/// "Nearly" is relative to the matrix's size: `|det| ≤ 10⁻¹² · ‖M‖_F^D`, so that the test
/// is the same for a distortion in any unit (the determinant scales as the `D`-th power of
/// the entries).
pub(crate) fn invert_distortion<const D: usize>(
    soft_iron: &SMatrix<f64, D, D>,
) -> Result<SMatrix<f64, D, D>>
where
    Const<D>: DimMin<Const<D>, Output = Const<D>>,
{
    for &x in soft_iron.iter() {
        check_finite("soft-iron matrix entry", x)?;
    }
    const SINGULAR: Error = Error::Degenerate {
        reason: "the soft-iron distortion matrix is singular; no calibration can undo it",
    };
    let size = soft_iron.norm();
    let limit = (0..D).fold(1e-12, |l, _| l * size);
    if size == 0.0 || soft_iron.determinant().abs() <= limit {
        return Err(SINGULAR);
    }
    soft_iron.try_inverse().ok_or(SINGULAR)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3};
    use proptest::prelude::*;

    proptest! {
        /// Scaling a distortion by any unit factor never changes whether it is accepted.
        #[test]
        fn the_singularity_test_does_not_depend_on_the_unit(
            e in proptest::array::uniform9(-2.0f64..2.0),
            scale_exp in -6i32..6,
        ) {
            let m = Matrix3::from_row_slice(&e);
            let k = 10f64.powi(scale_exp);
            prop_assert_eq!(invert_distortion(&m).is_ok(), invert_distortion(&(m * k)).is_ok());
        }
    }

    #[test]
    fn singular_and_non_finite_distortions_are_refused() {
        assert!(invert_distortion(&Matrix2::new(1.0, 2.0, 2.0, 4.0)).is_err());
        assert!(invert_distortion(&Matrix2::<f64>::zeros()).is_err());
        assert!(invert_distortion(&Matrix2::new(f64::NAN, 0.0, 0.0, 1.0)).is_err());
        let m = Matrix3::new(2.0, 0.1, 0.0, 0.0, 1.0, 0.0, 0.3, 0.0, 0.5);
        let inv = invert_distortion(&m).unwrap();
        assert!((inv * m - Matrix3::identity()).norm() < 1e-12);
    }
}
