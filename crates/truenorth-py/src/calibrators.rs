//! Every compass calibration method by its CLI name, behind one Python class: samples
//! pushed one at a time or as arrays, `solve()` (and `estimate()` for the online and seed
//! methods) giving a [`Calibration`] with its quality and verdict.

use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use truenorth::calib::{
    BinnedEllipseCalibrator, BinnedEllipseConfig, EllipseCalibrator, EllipseConfig,
    EllipsoidCalibrator, EllipsoidConfig, MagAccelCalibration, MagAccelCalibrator, MagAccelConfig,
    MagAccelQuality, MagAccelSample, MeritCircleCalibrator, MeritCircleConfig,
    OnlineEllipseCalibrator, OnlineEllipseConfig, OnlineEllipsoidCalibrator, OnlineEllipsoidConfig,
    TurnCompassCalibrator, TurnConfig,
};
use truenorth::compass::{CompassCalibration2d, CompassCalibration3d};
use truenorth::core::{
    Calibrator as CoreCalibrator, CompassQuality, Mag2Sample, Mag3Sample, OnlineCalibrator,
    Progress, Pushed, Solution,
};
use truenorth::nalgebra::{Vector2, Vector3};

use crate::calibration::{Calibration, Params};
use crate::convert::{arg_err, config_from, lib_err, row_err, rows, same_rows, times, to_py};

/// The method names, as the CLI's `--method`.
pub const METHODS: [&str; 8] = [
    "ellipse",
    "ellipsoid",
    "ellipsoid-accel",
    "online-ellipse",
    "online-ellipsoid",
    "binned-ellipse",
    "merit-circle",
    "turn",
];

/// A sample built from one row: `t_s`, the magnetometer's columns and, for the joint
/// method, the accelerometer's.
pub trait FromRow: Sized {
    /// Magnetometer columns.
    const MAG_COLS: usize;
    /// Whether the method needs the accelerometer.
    const NEEDS_ACC: bool = false;
    /// The sample at `t_s`.
    fn from_row(t_s: f64, mag: &[f64], acc: Option<&[f64]>) -> Self;
}

impl FromRow for Mag2Sample {
    const MAG_COLS: usize = 2;
    fn from_row(t_s: f64, mag: &[f64], _: Option<&[f64]>) -> Self {
        Self {
            t_s,
            mag: Vector2::new(mag[0], mag[1]),
        }
    }
}

impl FromRow for Mag3Sample {
    const MAG_COLS: usize = 3;
    fn from_row(t_s: f64, mag: &[f64], _: Option<&[f64]>) -> Self {
        Self {
            t_s,
            mag: Vector3::new(mag[0], mag[1], mag[2]),
        }
    }
}

impl FromRow for MagAccelSample {
    const MAG_COLS: usize = 3;
    const NEEDS_ACC: bool = true;
    fn from_row(t_s: f64, mag: &[f64], acc: Option<&[f64]>) -> Self {
        let a = acc.unwrap_or(&[f64::NAN; 3]);
        Self {
            t_s,
            mag: Vector3::new(mag[0], mag[1], mag[2]),
            acc: Vector3::new(a[0], a[1], a[2]),
        }
    }
}

/// A solution that becomes a Python [`Calibration`].
pub trait IntoCalibration {
    /// The calibration, named after `method`.
    fn into_calibration(self, method: &str) -> Calibration;
}

impl IntoCalibration for Solution<CompassCalibration2d, CompassQuality> {
    fn into_calibration(self, method: &str) -> Calibration {
        Calibration {
            method: method.into(),
            params: Params::TwoD(self.params),
            quality: self.quality,
        }
    }
}

impl IntoCalibration for Solution<CompassCalibration3d, CompassQuality> {
    fn into_calibration(self, method: &str) -> Calibration {
        Calibration {
            method: method.into(),
            params: Params::ThreeD(self.params),
            quality: self.quality,
        }
    }
}

impl IntoCalibration for Solution<MagAccelCalibration, MagAccelQuality> {
    fn into_calibration(self, method: &str) -> Calibration {
        Calibration {
            method: method.into(),
            params: Params::Joint(Box::new((self.params, self.quality))),
            quality: self.quality.mag,
        }
    }
}

/// Any calibrator, fed rows.
trait AnyCalibrator: Send + Sync {
    fn mag_cols(&self) -> usize;
    fn needs_acc(&self) -> bool;
    fn push(&mut self, t_s: f64, mag: &[f64], acc: Option<&[f64]>) -> truenorth::Result<Pushed>;
    fn progress(&self) -> Progress;
    fn solve(&self, method: &str) -> truenorth::Result<Calibration>;
    fn estimate(&self, method: &str) -> Option<Calibration>;
    fn reset(&mut self);
}

/// A batch calibrator (no running estimate).
struct Batch<C>(C);
/// A calibrator with a running estimate.
struct Online<C>(C);

macro_rules! any_calibrator {
    ($wrapper:ident) => {
        impl<C> AnyCalibrator for $wrapper<C>
        where
            C: CoreCalibrator + Send + Sync,
            C::Sample: FromRow,
            Solution<C::Params, C::Quality>: IntoCalibration,
            $wrapper<C>: Estimate,
        {
            fn mag_cols(&self) -> usize {
                C::Sample::MAG_COLS
            }
            fn needs_acc(&self) -> bool {
                C::Sample::NEEDS_ACC
            }
            fn push(
                &mut self,
                t_s: f64,
                mag: &[f64],
                acc: Option<&[f64]>,
            ) -> truenorth::Result<Pushed> {
                self.0.push(&C::Sample::from_row(t_s, mag, acc))
            }
            fn progress(&self) -> Progress {
                self.0.progress()
            }
            fn solve(&self, method: &str) -> truenorth::Result<Calibration> {
                Ok(self.0.solve()?.into_calibration(method))
            }
            fn estimate(&self, method: &str) -> Option<Calibration> {
                Estimate::current(self, method)
            }
            fn reset(&mut self) {
                self.0.reset()
            }
        }
    };
}

/// The running estimate of a calibrator, if it keeps one.
trait Estimate {
    fn current(&self, method: &str) -> Option<Calibration>;
}

impl<C> Estimate for Batch<C> {
    fn current(&self, _: &str) -> Option<Calibration> {
        None
    }
}

impl<C> Estimate for Online<C>
where
    C: OnlineCalibrator,
    Solution<C::Params, C::Quality>: IntoCalibration,
{
    fn current(&self, method: &str) -> Option<Calibration> {
        self.0.estimate().map(|s| s.into_calibration(method))
    }
}

any_calibrator!(Batch);
any_calibrator!(Online);

/// The method's calibrator from its configuration dictionary.
fn build(method: &str, config: Option<&Bound<'_, PyAny>>) -> PyResult<Box<dyn AnyCalibrator>> {
    Ok(match method {
        "ellipse" => Box::new(Batch(
            EllipseCalibrator::new(config_from::<EllipseConfig>(config)?).map_err(lib_err)?,
        )),
        "ellipsoid" => Box::new(Batch(
            EllipsoidCalibrator::new(config_from::<EllipsoidConfig>(config)?).map_err(lib_err)?,
        )),
        "ellipsoid-accel" => Box::new(Batch(
            MagAccelCalibrator::new(config_from::<MagAccelConfig>(config)?).map_err(lib_err)?,
        )),
        "online-ellipse" => Box::new(Online(
            OnlineEllipseCalibrator::new(config_from::<OnlineEllipseConfig>(config)?)
                .map_err(lib_err)?,
        )),
        "online-ellipsoid" => Box::new(Online(
            OnlineEllipsoidCalibrator::new(config_from::<OnlineEllipsoidConfig>(config)?)
                .map_err(lib_err)?,
        )),
        "binned-ellipse" => Box::new(Online(
            BinnedEllipseCalibrator::new(config_from::<BinnedEllipseConfig>(config)?)
                .map_err(lib_err)?,
        )),
        "merit-circle" => Box::new(Online(
            MeritCircleCalibrator::new(config_from::<MeritCircleConfig>(config)?)
                .map_err(lib_err)?,
        )),
        "turn" => Box::new(Batch(
            TurnCompassCalibrator::new(config_from::<TurnConfig>(config)?).map_err(lib_err)?,
        )),
        other => {
            return Err(arg_err(format!(
                "unknown calibration method `{other}`; one of: {}",
                METHODS.join(", ")
            )));
        }
    })
}

/// A compass calibrator, chosen by the CLI's method name: `ellipse`, `ellipsoid`,
/// `ellipsoid-accel`, `online-ellipse`, `online-ellipsoid`, `binned-ellipse`,
/// `merit-circle` or `turn` (the compass half). `config` is the method's configuration as
/// a dictionary (the library's field names and units; missing fields take their defaults).
#[pyclass(module = "truenorth")]
pub struct Calibrator {
    method: String,
    inner: Box<dyn AnyCalibrator>,
}

impl Calibrator {
    /// Pushes every row; the count of samples used.
    fn push_rows(
        &mut self,
        mag: &PyReadonlyArray2<'_, f64>,
        t_s: Option<&PyReadonlyArray1<'_, f64>>,
        acc: Option<&PyReadonlyArray2<'_, f64>>,
    ) -> PyResult<usize> {
        let m = rows(mag, "mag", &[self.inner.mag_cols()])?;
        let t = times(t_s, m.nrows())?;
        let a = match acc {
            Some(a) => {
                let a = rows(a, "acc", &[3])?;
                same_rows("acc", a.nrows(), m.nrows())?;
                Some(a)
            }
            None if self.inner.needs_acc() => {
                return Err(arg_err(format!(
                    "method `{}` needs `acc` (N×3 accelerometer readings)",
                    self.method
                )));
            }
            None => None,
        };
        let mut used = 0;
        let (mut mrow, mut arow) = ([0.0; 3], [0.0; 3]);
        for k in 0..m.nrows() {
            for (c, v) in mrow.iter_mut().enumerate().take(m.ncols()) {
                *v = m[(k, c)];
            }
            if let Some(a) = &a {
                for (c, v) in arow.iter_mut().enumerate() {
                    *v = a[(k, c)];
                }
            }
            let pushed = self
                .inner
                .push(t[k], &mrow[..m.ncols()], a.as_ref().map(|_| &arow[..]))
                .map_err(|e| row_err(k, e))?;
            used += usize::from(pushed != Pushed::Ignored);
        }
        Ok(used)
    }
}

#[pymethods]
impl Calibrator {
    #[new]
    #[pyo3(signature = (method, config=None))]
    fn new(method: &str, config: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        Ok(Self {
            method: method.to_string(),
            inner: build(method, config)?,
        })
    }

    /// The method's name.
    #[getter]
    fn method(&self) -> &str {
        &self.method
    }

    /// Feeds one sample: `mag` a sequence of 2 or 3 values (the method's), `acc` three
    /// for `ellipsoid-accel`. Returns `"ignored"`, `"accepted"` or `"new_estimate"`.
    #[pyo3(signature = (t_s, mag, acc=None))]
    fn push(&mut self, t_s: f64, mag: Vec<f64>, acc: Option<Vec<f64>>) -> PyResult<&'static str> {
        if mag.len() != self.inner.mag_cols() {
            return Err(arg_err(format!(
                "method `{}` takes {} magnetometer values per sample, got {}",
                self.method,
                self.inner.mag_cols(),
                mag.len()
            )));
        }
        if self.inner.needs_acc() && acc.as_ref().is_none_or(|a| a.len() != 3) {
            return Err(arg_err(format!(
                "method `{}` needs `acc` (three accelerometer values)",
                self.method
            )));
        }
        Ok(
            match self
                .inner
                .push(t_s, &mag, acc.as_deref())
                .map_err(lib_err)?
            {
                Pushed::Ignored => "ignored",
                Pushed::Accepted => "accepted",
                Pushed::NewEstimate => "new_estimate",
            },
        )
    }

    /// Feeds every row of `mag` (N×2 or N×3, the method's) with times `t_s` (N, seconds;
    /// default one second apart, as the CLI without a `t_s` column) and, for
    /// `ellipsoid-accel`, `acc` (N×3). Returns how many samples were used. A bad row raises
    /// `TruenorthError` naming it (rows before it stay pushed).
    #[pyo3(signature = (mag, t_s=None, acc=None))]
    fn push_array(
        &mut self,
        mag: PyReadonlyArray2<'_, f64>,
        t_s: Option<PyReadonlyArray1<'_, f64>>,
        acc: Option<PyReadonlyArray2<'_, f64>>,
    ) -> PyResult<usize> {
        self.push_rows(&mag, t_s.as_ref(), acc.as_ref())
    }

    /// How far the calibrator has got: `{"samples", "coverage", "ready"}`.
    fn progress<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.inner.progress())
    }

    /// Solves from everything pushed; raises `TruenorthError` with the reason when the data
    /// cannot support a calibration.
    fn solve(&self) -> PyResult<Calibration> {
        self.inner.solve(&self.method).map_err(lib_err)
    }

    /// The running estimate of an online or seed method, or `None` (none yet, or a batch
    /// method).
    fn estimate(&self) -> Option<Calibration> {
        self.inner.estimate(&self.method)
    }

    /// Forgets every sample (the configuration stays).
    fn reset(&mut self) {
        self.inner.reset();
    }

    fn __repr__(&self) -> String {
        let p = self.inner.progress();
        format!(
            "Calibrator({:?}, samples={}, coverage={:.3}, ready={})",
            self.method, p.samples, p.coverage, p.ready
        )
    }
}

/// Calibrates in one call, as `truenorth calibrate --method METHOD` on the same readings:
/// `mag` N×2 or N×3, `t_s` (N, seconds; default one second apart), `acc` N×3 for
/// `ellipsoid-accel`, `config` the method's configuration. Raises `TruenorthError` with
/// the library's reason when the data cannot support a calibration; a `poor` verdict is
/// returned (check `calibration.verdict.grade`), not refused.
#[pyfunction]
#[pyo3(signature = (method, mag, t_s=None, acc=None, config=None))]
pub fn calibrate(
    method: &str,
    mag: PyReadonlyArray2<'_, f64>,
    t_s: Option<PyReadonlyArray1<'_, f64>>,
    acc: Option<PyReadonlyArray2<'_, f64>>,
    config: Option<&Bound<'_, PyAny>>,
) -> PyResult<Calibration> {
    let mut c = Calibrator::new(method, config)?;
    c.push_rows(&mag, t_s.as_ref(), acc.as_ref())?;
    c.solve()
}
