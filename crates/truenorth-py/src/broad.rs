//! BROAD's accuracy metric (Laidig, Caruso, Cereatti & Seel, *Data* 6(7):72, 2021) over
//! arrays.

use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use truenorth::fusion::orientation::broad_rmse as core_broad_rmse;
use truenorth::nalgebra::{Quaternion, UnitQuaternion};

use crate::convert::{arg_err, rows, same_rows};

/// How far from unit norm an estimate may be and still be taken as it is: an estimator's
/// own output is unit to rounding, and renormalising it would move the metric in its last
/// digits away from the Rust caller's (`truenorth eval broad`).
const UNIT_NORM_TOLERANCE: f64 = 1e-9;

/// Unit quaternions from N×4 rows `qw,qx,qy,qz`; a row with a NaN (or all zero) is `None`.
/// With `keep_unit`, a row already of unit norm is taken as it is, others are normalised.
fn quaternions(
    q: numpy::ndarray::ArrayView2<f64>,
    keep_unit: bool,
) -> Vec<Option<UnitQuaternion<f64>>> {
    q.rows()
        .into_iter()
        .map(|r| {
            let q = Quaternion::new(r[0], r[1], r[2], r[3]);
            let norm = q.norm();
            (q.coords.iter().all(|v| v.is_finite()) && norm > 0.0).then(|| {
                if keep_unit && (norm - 1.0).abs() < UNIT_NORM_TOLERANCE {
                    UnitQuaternion::new_unchecked(q)
                } else {
                    UnitQuaternion::from_quaternion(q)
                }
            })
        })
        .collect()
}

/// BROAD's metric: the RMSE (degrees) of the total, heading and inclination error angles
/// between `estimate` and `reference` (both N×4 `qw,qx,qy,qz`, body → one common frame;
/// NaN rows of the reference are invalid; an estimate of unit norm is used as given,
/// others are normalised) over the samples where `movement` (N, bool) is
/// true and the reference valid. Returns `{"total_deg", "heading_deg", "inclination_deg"}`,
/// or `None` when no sample is scored.
#[pyfunction]
pub fn broad_rmse<'py>(
    py: Python<'py>,
    estimate: PyReadonlyArray2<'py, f64>,
    reference: PyReadonlyArray2<'py, f64>,
    movement: PyReadonlyArray1<'py, bool>,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let e = rows(&estimate, "estimate", &[4])?;
    let r = rows(&reference, "reference", &[4])?;
    let m = movement.as_array();
    same_rows("reference", r.nrows(), e.nrows())?;
    same_rows("movement", m.len(), e.nrows())?;
    let est: Option<Vec<UnitQuaternion<f64>>> = quaternions(e, true).into_iter().collect();
    let est = est
        .ok_or_else(|| arg_err("`estimate` has a row that is not a finite, non-zero quaternion"))?;
    let reference = quaternions(r, false);
    let movement = m.to_vec();
    let Some(rmse) = core_broad_rmse(&est, &reference, &movement) else {
        return Ok(None);
    };
    let d = PyDict::new(py);
    d.set_item("total_deg", rmse.total_deg)?;
    d.set_item("heading_deg", rmse.heading_deg)?;
    d.set_item("inclination_deg", rmse.inclination_deg)?;
    Ok(Some(d))
}
