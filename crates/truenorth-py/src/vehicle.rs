//! The fused vehicle estimator over arrays (and one sample at a time): wheels, yaw gyro and
//! compass in, position and heading out, as `truenorth drive --single-pass` computes them.

use numpy::PyReadonlyArray1;
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use truenorth::core::{
    GnssFix, HeadingEstimator, NavEstimate, VehicleSample, rad_to_deg, wrap_two_pi,
};
use truenorth::fusion::{SensorPriors, VehicleEstimator as CoreVehicle};
use truenorth::nalgebra::Vector2;
use truenorth::odometer::OdometerWheels;

use crate::convert::{array1, bools, config_from, lib_err, row_err, rows, same_rows, to_py};

/// A row's readings, each optional.
struct Readings {
    wheels: Option<(f64, f64)>,
    gyr_z: Option<f64>,
    mag: Option<(f64, f64)>,
    dist_m: Option<f64>,
    /// A satellite fix: latitude, longitude (degrees), its 1σ accuracy (m), speed over
    /// ground (m/s) and course over ground (degrees clockwise from true north), each NaN
    /// when the receiver gives none.
    gnss: Option<[f64; 5]>,
}

/// A fix given as 3 values (latitude, longitude, σ) or 5 (and speed, course over ground),
/// NaN for what the receiver does not give.
fn fix_values(values: &[f64]) -> PyResult<[f64; 5]> {
    match *values {
        [lat, lon, sigma] => Ok([lat, lon, sigma, f64::NAN, f64::NAN]),
        [lat, lon, sigma, speed, course] => Ok([lat, lon, sigma, speed, course]),
        _ => Err(crate::convert::arg_err(format!(
            "`gnss` is (lat_deg, lon_deg, sigma_m) or (lat_deg, lon_deg, sigma_m, speed_mps, course_deg), got {} values",
            values.len()
        ))),
    }
}

/// The row at `t_s` with whichever readings are finite.
fn vehicle_sample(t_s: f64, r: Readings) -> VehicleSample {
    let Readings {
        wheels,
        gyr_z,
        mag,
        dist_m,
        gnss,
    } = r;
    let mut s = VehicleSample::at(t_s);
    if let Some([lat, lon, sigma, speed, course]) =
        gnss.filter(|[lat, lon, ..]| !(lat.is_nan() && lon.is_nan()))
    {
        let mut fix = GnssFix::at(lat, lon);
        fix.sigma_m = Some(sigma).filter(|s| !s.is_nan());
        if !(speed.is_nan() || course.is_nan()) {
            fix.speed_mps = Some(speed);
            fix.course_deg = Some(course);
        }
        s = s.with_gnss(fix);
    }
    if let Some(d) = dist_m.filter(|d| !d.is_nan()) {
        s = s.with_distance(d);
    }
    if let Some((l, r)) = wheels.filter(|(l, r)| !(l.is_nan() && r.is_nan())) {
        s = s.with_wheels(l, r);
    }
    if let Some(g) = gyr_z.filter(|g| !g.is_nan()) {
        s = s.with_gyro(g);
    }
    if let Some((x, y)) = mag.filter(|(x, y)| !(x.is_nan() && y.is_nan())) {
        s = s.with_mag(Vector2::new(x, y));
    }
    s
}

/// The estimate of `nav` as `(north_m, east_m, heading_deg)` of the drive output: the
/// position NaN while no wheel has given it, the heading in [0, 360), from true north on rows
/// the satellite fixes referred (as `drive` writes them).
fn contract_row(e: &NavEstimate, nav: &CoreVehicle) -> [f64; 3] {
    let (n, east) = if e.status.position_known {
        (e.north_m, e.east_m)
    } else {
        (f64::NAN, f64::NAN)
    };
    let declination = nav
        .gnss_declination_rad()
        .filter(|_| e.status.gnss_frame)
        .unwrap_or(0.0);
    [
        n,
        east,
        rad_to_deg(wrap_two_pi(e.heading.rad() + declination)),
    ]
}

/// The fused vehicle estimator: cumulative wheel distances (m) or the vehicle's one
/// cumulative distance (`dist_m`, a CAN speed integrated: the distance, nothing about
/// turning), raw yaw rate (rad/s, positive turning right), raw horizontal magnetometer (any
/// unit), satellite fixes (latitude, longitude in degrees and their 1σ in metres), each
/// optional per row; every sensor calibrated online. With fixes, `north_m`, `east_m` are in
/// the tangent plane at the first fix and the heading from true north, on the rows they
/// refer (`gnss_frame`). `config`: the library's `VehicleConfig` as a dictionary,
/// e.g. `{"wheels": {"rear": {"track_m": 1.6}}}` (missing fields take their defaults).
#[pyclass(module = "truenorth")]
pub struct VehicleEstimator {
    inner: CoreVehicle,
}

#[pymethods]
impl VehicleEstimator {
    #[new]
    #[pyo3(signature = (config=None))]
    fn new(config: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        Ok(Self {
            inner: CoreVehicle::new(config_from(config)?).map_err(lib_err)?,
        })
    }

    /// Feeds one row; any reading may be `None` (`gnss`: `(lat_deg, lon_deg, sigma_m)` or
    /// `(lat_deg, lon_deg, sigma_m, speed_mps, course_deg)`, a value NaN when the receiver
    /// gives none). Returns `{"t_s", "north_m", "east_m",
    /// "heading_deg", "gnss_frame"}` after it.
    #[pyo3(signature = (t_s, dist_l_m=None, dist_r_m=None, gyr_z=None, mag=None, dist_m=None, gnss=None))]
    #[allow(clippy::too_many_arguments)]
    fn update<'py>(
        &mut self,
        py: Python<'py>,
        t_s: f64,
        dist_l_m: Option<f64>,
        dist_r_m: Option<f64>,
        gyr_z: Option<f64>,
        mag: Option<(f64, f64)>,
        dist_m: Option<f64>,
        gnss: Option<Vec<f64>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let readings = Readings {
            wheels: dist_l_m.zip(dist_r_m),
            gyr_z,
            mag,
            dist_m,
            gnss: gnss.as_deref().map(fix_values).transpose()?,
        };
        let e = self
            .inner
            .update(&vehicle_sample(t_s, readings))
            .map_err(lib_err)?;
        let [n, east, h] = contract_row(&e, &self.inner);
        let d = PyDict::new(py);
        d.set_item("t_s", e.t_s)?;
        d.set_item("north_m", n)?;
        d.set_item("east_m", east)?;
        d.set_item("heading_deg", h)?;
        d.set_item("gnss_frame", e.status.gnss_frame)?;
        Ok(d)
    }

    /// Runs every row (the loop in Rust, without the GIL): `t_s` (N, s), and any of
    /// `dist_l_m`, `dist_r_m` (N, cumulative), `gyr_z` (N, rad/s), `mag` (N×2), `dist_m` (N,
    /// the vehicle's one cumulative distance, where there are no wheels), NaN where a row
    /// has no reading. Returns a dict of arrays: `t_s`, `north_m`, `east_m` (NaN before
    /// the wheels give a position), `heading_deg` ([0, 360), magnetic north, or true north
    /// where `gnss_frame`), `heading_sigma_deg`, `speed_mps`, `distance_m`, `gap` (bool),
    /// `gnss_frame` (bool: the row is on the fixes' tangent plane and true north). `gnss`:
    /// N×3, latitude, longitude (degrees) and 1σ (m, NaN if not given), NaN where a row has
    /// no fix.
    #[pyo3(signature = (t_s, dist_l_m=None, dist_r_m=None, gyr_z=None, mag=None, dist_m=None, gnss=None))]
    #[allow(clippy::too_many_arguments)]
    fn update_array<'py>(
        &mut self,
        py: Python<'py>,
        t_s: PyReadonlyArray1<'py, f64>,
        dist_l_m: Option<PyReadonlyArray1<'py, f64>>,
        dist_r_m: Option<PyReadonlyArray1<'py, f64>>,
        gyr_z: Option<PyReadonlyArray1<'py, f64>>,
        mag: Option<PyReadonlyArray2<'py, f64>>,
        dist_m: Option<PyReadonlyArray1<'py, f64>>,
        gnss: Option<PyReadonlyArray2<'py, f64>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let t = t_s.as_array();
        let n = t.len();
        let col =
            |a: &Option<PyReadonlyArray1<'py, f64>>, name: &str| -> PyResult<Option<Vec<f64>>> {
                match a {
                    Some(a) => {
                        let v = a.as_array();
                        same_rows(name, v.len(), n)?;
                        Ok(Some(v.to_vec()))
                    }
                    None => Ok(None),
                }
            };
        let (l, r, g) = (
            col(&dist_l_m, "dist_l_m")?,
            col(&dist_r_m, "dist_r_m")?,
            col(&gyr_z, "gyr_z")?,
        );
        let single = col(&dist_m, "dist_m")?;
        let m = match &mag {
            Some(m) => {
                let m = rows(m, "mag", &[2])?;
                same_rows("mag", m.nrows(), n)?;
                Some(m)
            }
            None => None,
        };
        let fixes = match &gnss {
            Some(f) => {
                let f = rows(f, "gnss", &[3, 5])?;
                same_rows("gnss", f.nrows(), n)?;
                Some(f)
            }
            None => None,
        };
        let inner = &mut self.inner;
        let out = py.detach(|| {
            let mut out: [Vec<f64>; 6] = std::array::from_fn(|_| Vec::with_capacity(n));
            let mut gap = Vec::with_capacity(n);
            let mut frame = Vec::with_capacity(n);
            for k in 0..n {
                let wheels = match (&l, &r) {
                    (Some(l), Some(r)) => Some((l[k], r[k])),
                    _ => None,
                };
                let s = vehicle_sample(
                    t[k],
                    Readings {
                        wheels,
                        gyr_z: g.as_ref().map(|g| g[k]),
                        mag: m.as_ref().map(|m| (m[(k, 0)], m[(k, 1)])),
                        dist_m: single.as_ref().map(|d| d[k]),
                        gnss: fixes.as_ref().map(|f| {
                            let v = |j: usize| if j < f.ncols() { f[(k, j)] } else { f64::NAN };
                            [v(0), v(1), v(2), v(3), v(4)]
                        }),
                    },
                );
                let e = inner.update(&s).map_err(|e| (k, e))?;
                let [north, east, h] = contract_row(&e, inner);
                for (v, x) in out.iter_mut().zip([
                    north,
                    east,
                    h,
                    rad_to_deg(e.heading_sigma_rad),
                    e.speed_mps,
                    e.distance_m,
                ]) {
                    v.push(x);
                }
                gap.push(e.status.gap);
                frame.push(e.status.gnss_frame);
            }
            Ok::<_, (usize, truenorth::Error)>((out, gap, frame))
        });
        let (out, gap, frame) = out.map_err(|(k, e)| row_err(k, e))?;
        let d = PyDict::new(py);
        d.set_item("t_s", array1(py, t.to_vec()))?;
        let names = [
            "north_m",
            "east_m",
            "heading_deg",
            "heading_sigma_deg",
            "speed_mps",
            "distance_m",
        ];
        for (name, v) in names.into_iter().zip(out) {
            d.set_item(name, array1(py, v))?;
        }
        d.set_item("gap", bools(py, gap))?;
        d.set_item("gnss_frame", bools(py, frame))?;
        Ok(d)
    }

    /// The sensors' priors of a kind of vehicle, as a dictionary for `config["priors"]`:
    /// `wheels` as in the configuration (`{"skid_steer": {"track_m": 0.57}}`); `speeds`: the
    /// wheel distances are integrated wheel speeds from a controller (their quantum and the
    /// controller filter's delay, as `truenorth drive` assumes for speed columns).
    #[staticmethod]
    #[pyo3(signature = (wheels, speeds=false))]
    fn priors<'py>(
        py: Python<'py>,
        wheels: &Bound<'py, PyAny>,
        speeds: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let wheels: OdometerWheels = pythonize::depythonize(wheels)
            .map_err(|e| crate::convert::arg_err(format!("invalid wheels: {e}")))?;
        let priors = if speeds {
            SensorPriors::for_wheel_speeds(&wheels)
        } else {
            SensorPriors::for_wheels(&wheels)
        };
        to_py(py, &priors)
    }

    /// What the estimator has learned about the sensors, as a dictionary (the form a later
    /// drive starts from, as `truenorth drive --calibration-out` writes it).
    fn calibration<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.inner.calibration())
    }

    /// Back to the state before the first sample.
    fn reset(&mut self) {
        self.inner.reset();
    }
}
