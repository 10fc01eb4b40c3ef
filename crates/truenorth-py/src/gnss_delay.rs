//! How late a drive's satellite fixes are stamped (`truenorth.check_gnss_delay`): their
//! course's turns against the gyro's (`truenorth::checks::CourseLagCheck`), the check
//! `truenorth drive` warns by.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use truenorth::checks::CourseLagCheck;

use crate::convert::arg_err;

/// How long after the epoch they describe the fixes are stamped, from rows `t_s` (N, s):
/// `gyr_z` (N, the yaw rate in any unit and sign: the check fits the gyro's scale and bias),
/// `lat_deg`, `lon_deg` (N, NaN on rows without a fix) and optionally `speed_mps`,
/// `course_deg` (N, the fixes' speed and course over ground; without them the chords between
/// fixes stand for the course). `None` until the turns tell (30 pairs of courses 0.5–2 s
/// apart, at 3 m/s or more); else a dict: `lag_s`, `sigma_s`, `pairs`, `misfit` (the residual
/// per pair over the noise modelled, about 1 or less when the fit holds) and
/// `excess_at_assumed`, how much worse the delay `assumed_s` fits (default 0.1 s, `drive`'s
/// assumption; beyond 25 it is refuted at 5σ).
#[pyfunction]
#[pyo3(signature = (t_s, gyr_z, lat_deg, lon_deg, speed_mps=None, course_deg=None, assumed_s=0.1))]
#[allow(clippy::too_many_arguments)]
pub fn check_gnss_delay<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    gyr_z: PyReadonlyArray1<'py, f64>,
    lat_deg: PyReadonlyArray1<'py, f64>,
    lon_deg: PyReadonlyArray1<'py, f64>,
    speed_mps: Option<PyReadonlyArray1<'py, f64>>,
    course_deg: Option<PyReadonlyArray1<'py, f64>>,
    assumed_s: f64,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let (t, g, lat, lon) = (
        t_s.as_array(),
        gyr_z.as_array(),
        lat_deg.as_array(),
        lon_deg.as_array(),
    );
    let n = t.len();
    let velocity = match (&speed_mps, &course_deg) {
        (Some(s), Some(c)) => Some((s.as_array(), c.as_array())),
        (None, None) => None,
        _ => {
            return Err(arg_err(
                "give speed_mps and course_deg together, or neither",
            ));
        }
    };
    let lengths_differ = [g.len(), lat.len(), lon.len()]
        .into_iter()
        .chain(velocity.iter().flat_map(|(s, c)| [s.len(), c.len()]))
        .any(|len| len != n);
    if lengths_differ {
        return Err(arg_err(format!(
            "every array must have the {n} rows of t_s"
        )));
    }
    let (found, excess) = py.detach(|| {
        let mut check = Box::new(CourseLagCheck::new());
        for k in 0..n {
            let v = velocity
                .as_ref()
                .map(|(speed, course)| (speed[k], course[k]));
            check.push_columns(t[k], g[k], lat[k], lon[k], v);
        }
        (check.lag(), check.excess_at(assumed_s))
    });
    let Some(f) = found else {
        return Ok(None);
    };
    let d = PyDict::new(py);
    d.set_item("lag_s", f.lag_s)?;
    d.set_item("sigma_s", f.sigma_s)?;
    d.set_item("pairs", f.pairs)?;
    d.set_item("misfit", f.misfit)?;
    d.set_item("excess_at_assumed", excess)?;
    Ok(Some(d))
}
