//! The orientation estimators (quaternion filter, Euler detector): one sample at a time,
//! or whole arrays with the loop in Rust, giving what `truenorth orientation` writes.

use numpy::ndarray::{ArrayView1, ArrayView2};
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use truenorth::core::{
    AttitudeEstimate, Axes, EulerZyx, ImuSample, OrientationEstimator as CoreEstimator, ned_to_enu,
    rad_to_deg,
};
use truenorth::fusion::{EulerDetector as CoreEuler, QuaternionFilter as CoreQuaternion};
use truenorth::nalgebra::{UnitQuaternion, Vector3};

use crate::convert::{
    arg_err, array1, array2, bools, config_from, lib_err, row_err, rows, same_rows,
};

/// One attitude estimate.
#[pyclass(module = "truenorth", frozen, get_all)]
#[derive(Debug, Clone)]
pub struct Attitude {
    /// Time of the sample, s.
    pub t_s: f64,
    /// Hamilton quaternion, scalar first `(qw, qx, qy, qz)`, body → NED on magnetic north.
    pub quaternion: (f64, f64, f64, f64),
    /// Yaw, degrees clockwise from north (Z-Y-X angles from NED).
    pub yaw_deg: f64,
    /// Pitch, degrees, nose up.
    pub pitch_deg: f64,
    /// Roll, degrees, right side down.
    pub roll_deg: f64,
    /// Estimated gyro bias, rad/s.
    pub gyro_bias_rps: (f64, f64, f64),
    /// 1-σ of the attitude error about north, east and down, degrees (quaternion filter).
    pub sigma_deg: Option<(f64, f64, f64)>,
    /// The sensor was judged at rest.
    pub at_rest: bool,
    /// The magnetometer corrected the heading.
    pub mag_used: bool,
    /// The magnetic field was judged disturbed.
    pub mag_disturbed: bool,
    /// A hard-iron offset learned online is being subtracted.
    pub mag_calibrating: bool,
    /// The time since the previous sample was longer than the gyro can bridge.
    pub gap: bool,
}

impl From<&AttitudeEstimate> for Attitude {
    fn from(e: &AttitudeEstimate) -> Self {
        let q = e.attitude;
        let angles = EulerZyx::from_quaternion(&q);
        let b = e.gyro_bias_rps;
        Self {
            t_s: e.t_s,
            quaternion: (q.w, q.i, q.j, q.k),
            yaw_deg: rad_to_deg(angles.yaw_rad),
            pitch_deg: rad_to_deg(angles.pitch_rad),
            roll_deg: rad_to_deg(angles.roll_rad),
            gyro_bias_rps: (b.x, b.y, b.z),
            sigma_deg: e
                .sigma_rad
                .map(|s| (rad_to_deg(s.x), rad_to_deg(s.y), rad_to_deg(s.z))),
            at_rest: e.status.at_rest,
            mag_used: e.status.mag_used,
            mag_disturbed: e.status.mag_disturbed,
            mag_calibrating: e.status.mag_calibrating,
            gap: e.status.gap,
        }
    }
}

#[pymethods]
impl Attitude {
    fn __repr__(&self) -> String {
        format!(
            "Attitude(t_s={}, yaw_deg={:.3}, pitch_deg={:.3}, roll_deg={:.3})",
            self.t_s, self.yaw_deg, self.pitch_deg, self.roll_deg
        )
    }
}

/// The arrays of an IMU recording, checked: `gyr`, `acc` and `mag` (if given) N×3, as many
/// rows as `t_s`.
pub(crate) fn imu_arrays<'a>(
    t_s: &'a PyReadonlyArray1<'_, f64>,
    gyr: &'a PyReadonlyArray2<'_, f64>,
    acc: &'a PyReadonlyArray2<'_, f64>,
    mag: Option<&'a PyReadonlyArray2<'_, f64>>,
) -> PyResult<ImuArrays<'a>> {
    let t = t_s.as_array();
    let g = rows(gyr, "gyr", &[3])?;
    let a = rows(acc, "acc", &[3])?;
    let n = t.len();
    same_rows("gyr", g.nrows(), n)?;
    same_rows("acc", a.nrows(), n)?;
    let m = match mag {
        Some(m) => {
            let m = rows(m, "mag", &[3])?;
            same_rows("mag", m.nrows(), n)?;
            Some(m)
        }
        None => None,
    };
    Ok((t, g, a, m))
}

/// `t_s`, `gyr`, `acc` and `mag` of an IMU recording as checked views.
pub(crate) type ImuArrays<'a> = (
    ArrayView1<'a, f64>,
    ArrayView2<'a, f64>,
    ArrayView2<'a, f64>,
    Option<ArrayView2<'a, f64>>,
);

/// An IMU sample from one row; a magnetometer row of three NaN is no reading.
pub(crate) fn imu_sample(t_s: f64, g: [f64; 3], a: [f64; 3], m: Option<[f64; 3]>) -> ImuSample {
    ImuSample {
        t_s,
        gyr_rps: Axes::xyz(Vector3::from(g)),
        acc_mps2: Axes::xyz(Vector3::from(a)),
        mag: match m {
            Some(m) if m.iter().all(|v| v.is_nan()) => Axes::NONE,
            Some(m) => Axes::xyz(Vector3::from(m)),
            None => Axes::NONE,
        },
    }
}

/// The output frame of the quaternion.
fn frame_rotation(frame: &str) -> PyResult<UnitQuaternion<f64>> {
    match frame {
        "ned" => Ok(UnitQuaternion::identity()),
        "enu" => Ok(ned_to_enu()),
        other => Err(arg_err(format!(
            "unknown frame `{other}`: `ned` (north, east, down) or `enu` (east, north, up)"
        ))),
    }
}

/// What [`OrientationEstimator::update_array`] collects, row-major.
#[derive(Default)]
struct Columns {
    quaternion: Vec<f64>,
    euler_deg: Vec<f64>,
    bias: Vec<f64>,
    sigma_deg: Vec<f64>,
    flags: [Vec<bool>; 5],
}

impl Columns {
    fn with_capacity(n: usize) -> Self {
        Self {
            quaternion: Vec::with_capacity(4 * n),
            euler_deg: Vec::with_capacity(3 * n),
            bias: Vec::with_capacity(3 * n),
            sigma_deg: Vec::with_capacity(3 * n),
            flags: std::array::from_fn(|_| Vec::with_capacity(n)),
        }
    }

    fn push(&mut self, to_frame: &UnitQuaternion<f64>, e: &AttitudeEstimate) {
        let q = to_frame * e.attitude;
        self.quaternion.extend([q.w, q.i, q.j, q.k]);
        let angles = EulerZyx::from_quaternion(&e.attitude);
        self.euler_deg.extend([
            rad_to_deg(angles.yaw_rad),
            rad_to_deg(angles.pitch_rad),
            rad_to_deg(angles.roll_rad),
        ]);
        self.bias.extend(e.gyro_bias_rps.iter());
        match e.sigma_rad {
            Some(s) => self.sigma_deg.extend(s.iter().map(|v| rad_to_deg(*v))),
            None => self.sigma_deg.extend([f64::NAN; 3]),
        }
        let s = e.status;
        for (v, f) in self.flags.iter_mut().zip([
            s.at_rest,
            s.mag_used,
            s.mag_disturbed,
            s.mag_calibrating,
            s.gap,
        ]) {
            v.push(f);
        }
    }
}

/// An orientation estimator (the base class of [`QuaternionFilter`] and [`EulerDetector`]):
/// IMU samples in (`t_s` s, gyro rad/s, specific force m/s², magnetometer any unit,
/// calibrated; body axes x forward, y right, z down), attitude out (body → NED on magnetic
/// north).
#[pyclass(module = "truenorth", subclass)]
pub struct OrientationEstimator {
    inner: Box<dyn CoreEstimator + Send + Sync>,
}

#[pymethods]
impl OrientationEstimator {
    /// Feeds one sample: `gyr` (3, rad/s), `acc` (3, m/s²), `mag` (3, or `None` for no
    /// reading). Returns the estimate after it.
    #[pyo3(signature = (t_s, gyr, acc, mag=None))]
    fn update(
        &mut self,
        t_s: f64,
        gyr: [f64; 3],
        acc: [f64; 3],
        mag: Option<[f64; 3]>,
    ) -> PyResult<Attitude> {
        let e = self
            .inner
            .update(&imu_sample(t_s, gyr, acc, mag))
            .map_err(lib_err)?;
        Ok(Attitude::from(&e))
    }

    /// Runs every row (the loop in Rust, without the GIL): `t_s` (N, s, increasing), `gyr`
    /// and `acc` (N×3), `mag` (N×3; a row of NaN is no reading; `None`: no magnetometer).
    /// Returns a dict of arrays, the columns of `truenorth orientation --status`:
    /// `t_s` (N), `quaternion` (N×4, `qw,qx,qy,qz`, into `frame`: `"ned"` or `"enu"`),
    /// `euler_deg` (N×3, yaw, pitch, roll from NED), `gyro_bias_rps` (N×3), `sigma_deg`
    /// (N×3, NaN for a method without σ), and the flags `at_rest`, `mag_used`,
    /// `mag_disturbed`, `mag_calibrating`, `gap` (N, bool). The estimator goes on from
    /// where it was; a bad row raises `TruenorthError` naming it.
    #[pyo3(signature = (t_s, gyr, acc, mag=None, frame="ned"))]
    fn update_array<'py>(
        &mut self,
        py: Python<'py>,
        t_s: PyReadonlyArray1<'py, f64>,
        gyr: PyReadonlyArray2<'py, f64>,
        acc: PyReadonlyArray2<'py, f64>,
        mag: Option<PyReadonlyArray2<'py, f64>>,
        frame: &str,
    ) -> PyResult<Bound<'py, PyDict>> {
        let to_frame = frame_rotation(frame)?;
        let (t, g, a, m) = imu_arrays(&t_s, &gyr, &acc, mag.as_ref())?;
        let n = t.len();
        let inner = &mut self.inner;
        let cols = py.detach(|| {
            let mut cols = Columns::with_capacity(n);
            let row3 =
                |v: &numpy::ndarray::ArrayView2<f64>, k: usize| [v[(k, 0)], v[(k, 1)], v[(k, 2)]];
            for k in 0..n {
                let s = imu_sample(
                    t[k],
                    row3(&g, k),
                    row3(&a, k),
                    m.as_ref().map(|m| row3(m, k)),
                );
                let e = inner.update(&s).map_err(|e| (k, e))?;
                cols.push(&to_frame, &e);
            }
            Ok::<_, (usize, truenorth::Error)>(cols)
        });
        let cols = cols.map_err(|(k, e)| row_err(k, e))?;
        let d = PyDict::new(py);
        d.set_item("t_s", array1(py, t.to_vec()))?;
        d.set_item("quaternion", array2(py, cols.quaternion, 4)?)?;
        d.set_item("euler_deg", array2(py, cols.euler_deg, 3)?)?;
        d.set_item("gyro_bias_rps", array2(py, cols.bias, 3)?)?;
        d.set_item("sigma_deg", array2(py, cols.sigma_deg, 3)?)?;
        let names = [
            "at_rest",
            "mag_used",
            "mag_disturbed",
            "mag_calibrating",
            "gap",
        ];
        for (name, v) in names.into_iter().zip(cols.flags) {
            d.set_item(name, bools(py, v))?;
        }
        Ok(d)
    }

    /// The current estimate.
    fn estimate(&self) -> Attitude {
        Attitude::from(&self.inner.estimate())
    }

    /// Back to the state before the first sample (the configuration stays).
    fn reset(&mut self) {
        self.inner.reset();
    }
}

/// The quaternion filter: gyro strapdown, inclination from the low-passed specific force,
/// heading from the magnetometer with disturbance rejection and online hard-iron
/// re-estimation, gyro bias at rest and in motion. `config`: the library's
/// `QuaternionFilterConfig` as a dictionary (missing fields take their defaults), e.g.
/// `{"use_mag": False}` or `{"gyro_timing": "instantaneous"}`.
#[pyclass(module = "truenorth", extends = OrientationEstimator)]
pub struct QuaternionFilter;

#[pymethods]
impl QuaternionFilter {
    #[new]
    #[pyo3(signature = (config=None))]
    fn new(config: Option<&Bound<'_, PyAny>>) -> PyResult<(Self, OrientationEstimator)> {
        let f = CoreQuaternion::new(config_from(config)?).map_err(lib_err)?;
        Ok((Self, OrientationEstimator { inner: Box::new(f) }))
    }
}

/// The Euler orientation angle detector (WO 00/36376): Euler-rate integration, static tilt
/// and tilt-compensated yaw, correction definer. `config`: the library's
/// `EulerDetectorConfig` as a dictionary.
#[pyclass(module = "truenorth", extends = OrientationEstimator)]
pub struct EulerDetector;

#[pymethods]
impl EulerDetector {
    #[new]
    #[pyo3(signature = (config=None))]
    fn new(config: Option<&Bound<'_, PyAny>>) -> PyResult<(Self, OrientationEstimator)> {
        let f = CoreEuler::new(config_from(config)?).map_err(lib_err)?;
        Ok((Self, OrientationEstimator { inner: Box::new(f) }))
    }
}
