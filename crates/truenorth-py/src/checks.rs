//! A recording checked against its physics before an estimator is trusted with it
//! (`truenorth.check_imu`): the units of the gyro and accelerometer columns and the gyro's
//! axes against the accelerometer's and magnetometer's, the checks the `truenorth` command
//! refuses by (`truenorth::checks`).

use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use truenorth::checks::{
    AccUnit, Finding, FindingKind, Fix, GyroUnit, StuckReadings, StuckRun, check_inertial,
};

use crate::convert::arg_err;
use crate::orientation::{imu_arrays, imu_sample};

/// What contradicts the declared units of an IMU recording, or the gyro's axes: `t_s` (N,
/// s), `gyr` and `acc` (N×3, in `gyro_unit` — `"rad/s"` or `"deg/s"` — and `acc_unit` —
/// `"m/s2"`, `"g"` or `"mg"`), `mag` (N×3, any unit; a row of NaN is no reading). Returns a
/// list of findings, empty when nothing contradicts them, each a dict: `kind` (`"units"`
/// or `"axes"`), `seen` (the evidence, in words and figures), `fix` (a dict: `gyro_unit` or
/// `acc_unit` the data are in, or `gyro_axes`, the mapping that reads the gyro along the
/// other sensors' axes, `x=-y,y=x,z=z`: body axis = column as given; `mag_axes` and
/// `mag_axes_rotation` for a mirrored or turned magnetometer; `advice` where no unit fits)
/// and `row`. Readings no live sensor gives (an axis clipped at its range or frozen, a
/// magnetometer reading exactly zero: `truenorth::checks::stuck_readings`) come after, one
/// a sensor, with `kind` `"faults"`, `fix` `{"advice": ...}` and `row` the index of the run's
/// first reading.
#[pyfunction]
#[pyo3(signature = (t_s, gyr, acc, mag=None, gyro_unit="rad/s", acc_unit="m/s2"))]
#[allow(clippy::too_many_arguments)]
pub fn check_imu<'py>(
    py: Python<'py>,
    t_s: PyReadonlyArray1<'py, f64>,
    gyr: PyReadonlyArray2<'py, f64>,
    acc: PyReadonlyArray2<'py, f64>,
    mag: Option<PyReadonlyArray2<'py, f64>>,
    gyro_unit: &str,
    acc_unit: &str,
) -> PyResult<Bound<'py, PyList>> {
    let gyro = GyroUnit::from_name(gyro_unit)
        .ok_or_else(|| arg_err(format!("gyro_unit `{gyro_unit}`: use rad/s or deg/s")))?;
    let accel = AccUnit::from_name(acc_unit)
        .ok_or_else(|| arg_err(format!("acc_unit `{acc_unit}`: use m/s2, g or mg")))?;
    let (t, g, a, m) = imu_arrays(&t_s, &gyr, &acc, mag.as_ref())?;
    let n = t.len();
    let (to_rps, to_mps2) = (gyro.to_rad_per_s(), accel.to_mps2());
    let findings = py.detach(|| {
        let row3 = |v: &numpy::ndarray::ArrayView2<f64>, k: usize, s: f64| {
            [s * v[(k, 0)], s * v[(k, 1)], s * v[(k, 2)]]
        };
        let samples: Vec<_> = (0..n)
            .map(|k| {
                imu_sample(
                    t[k],
                    row3(&g, k, to_rps),
                    row3(&a, k, to_mps2),
                    m.as_ref().map(|m| row3(m, k, 1.0)),
                )
            })
            .collect();
        let mut gyro_watch = StuckReadings::<3>::new();
        let mut mag_watch = StuckReadings::<3>::magnetometer();
        let (mut gyro_run, mut mag_run) = (None, None);
        for (k, s) in samples.iter().enumerate() {
            if let Some(v) = s.gyr_rps.as_xyz() {
                let run = gyro_watch.push(k, s.t_s, &v.into());
                gyro_run = gyro_run.or(run);
            }
            if let Some(v) = s.mag.as_xyz() {
                let run = mag_watch.push(k, s.t_s, &v.into());
                mag_run = mag_run.or(run);
            }
        }
        let gyro_run = gyro_run.or_else(|| gyro_watch.finish());
        let mag_run = mag_run.or_else(|| mag_watch.finish());
        (
            check_inertial(&samples, gyro, accel),
            [("gyro (rad/s)", gyro_run), ("magnetometer", mag_run)],
        )
    });
    let (findings, faults) = findings;
    let out = PyList::empty(py);
    for f in &findings {
        out.append(finding(py, f)?)?;
    }
    for (sensor, run) in &faults {
        if let Some(run) = run {
            out.append(fault(py, sensor, run)?)?;
        }
    }
    Ok(out)
}

/// A run no live sensor gives, as a finding's dictionary.
fn fault<'py>(py: Python<'py>, sensor: &str, run: &StuckRun) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("kind", "faults")?;
    d.set_item("seen", format!("{sensor}: {run}"))?;
    let fix = PyDict::new(py);
    fix.set_item("advice", run.advice())?;
    d.set_item("fix", fix)?;
    d.set_item("row", run.from_row)?;
    Ok(d)
}

/// One finding as a dictionary.
fn finding<'py>(py: Python<'py>, f: &Finding) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(
        "kind",
        match f.kind {
            FindingKind::Units => "units",
            FindingKind::Axes => "axes",
        },
    )?;
    d.set_item("seen", &f.seen)?;
    let fix = PyDict::new(py);
    match &f.fix {
        Fix::GyroUnit(u) => fix.set_item("gyro_unit", u.name())?,
        Fix::AccUnit(u) => fix.set_item("acc_unit", u.name())?,
        Fix::MagUnit { likely, also, .. } => {
            fix.set_item("mag_unit", likely.name())?;
            let also: Vec<&str> = also.iter().map(|u| u.name()).collect();
            fix.set_item("mag_unit_also", also)?;
        }
        Fix::GyroAxes(p) => fix.set_item("gyro_axes", p.to_string())?,
        Fix::GyroZSign => fix.set_item("gyro_axes", "x=x,y=y,z=-z")?,
        Fix::MagAxes { mirror, rotation } => {
            fix.set_item("mag_axes", mirror.to_string())?;
            fix.set_item("mag_axes_rotation", rotation.to_string())?;
        }
        Fix::Advice(a) => fix.set_item("advice", a)?,
    }
    d.set_item("fix", fix)?;
    d.set_item("row", f.row)?;
    Ok(d)
}
